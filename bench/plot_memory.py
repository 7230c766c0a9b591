#!/usr/bin/python3
"""Plots a memory curve written by bench/memory_curve.sh (CSV time_s,rss_mb[,hwm_mb]).

Usage: bench/plot_memory.py CURVE.csv OUT.png [--title TEXT] [--limit-mb MB]
                            [--summary RUN/summary.json]

Draws resident memory against wall time, the running peak (VmHWM) when present, and an optional
limit line (e.g. issue 7's 3 GB). With --summary it also marks the recording time covered, so the
x axis can be read against the run's real-time factor.
"""
import argparse
import csv
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_curve(path):
    times_s, rss_mb, hwm_mb = [], [], []
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames is None or "time_s" not in reader.fieldnames \
                or "rss_mb" not in reader.fieldnames:
            sys.exit(f"{path}: expected a header with time_s and rss_mb, got {reader.fieldnames}")
        for line, row in enumerate(reader, start=2):
            try:
                times_s.append(float(row["time_s"]))
                rss_mb.append(float(row["rss_mb"]))
                if row.get("hwm_mb"):
                    hwm_mb.append(float(row["hwm_mb"]))
            except (TypeError, ValueError):
                sys.exit(f"{path}:{line}: time_s/rss_mb/hwm_mb are not numbers: {row}")
    if not times_s:
        sys.exit(f"{path}: no samples")
    if hwm_mb and len(hwm_mb) != len(times_s):
        sys.exit(f"{path}: hwm_mb present on some rows only")
    return times_s, rss_mb, hwm_mb


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("curve")
    parser.add_argument("out")
    parser.add_argument("--title", default="taiga run: resident memory")
    parser.add_argument("--limit-mb", type=float, default=None)
    parser.add_argument("--summary", default=None, help="RUN/summary.json for a caption")
    args = parser.parse_args()

    times_s, rss_mb, hwm_mb = read_curve(args.curve)
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(times_s, rss_mb, lw=1.2, label="resident (VmRSS)")
    if hwm_mb:
        ax.plot(times_s, hwm_mb, lw=1.0, ls="--", label="peak so far (VmHWM)")
    if args.limit_mb is not None:
        ax.axhline(args.limit_mb, color="tab:red", lw=1.0, label=f"limit {args.limit_mb:.0f} MB")
    peak = max(hwm_mb) if hwm_mb else max(rss_mb)
    caption = f"peak {peak:.0f} MB, {len(times_s)} samples"
    if args.summary:
        with open(args.summary) as f:
            summary = json.load(f)
        parts = []
        for key, fmt in (("realtime_factor", "RTF {:.2f}"), ("wall_time_s", "wall {:.0f} s"),
                         ("duration_s", "data {:.0f} s")):
            if key in summary and isinstance(summary[key], (int, float)):
                parts.append(fmt.format(summary[key]))
        if parts:
            caption += ", " + ", ".join(parts)
    ax.set_title(f"{args.title}\n{caption}", fontsize=10)
    ax.set_xlabel("wall time since start [s]")
    ax.set_ylabel("memory [MB]")
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"{args.out}: peak {peak:.1f} MB")


if __name__ == "__main__":
    main()
