#!/usr/bin/env python3
"""Per-stage time of `taiga run` from the runs' timing.csv and scans.csv (issue 26, "profile
first"): for each stage the median, p95, p99 and max over the scans, the median of each run's
value pooled over runs (medians of the per-run figures), and the scans by how many scans came
since the last keyframe (the keyframe spike).

Usage: bench/stage_profile.py RUN_DIR [RUN_DIR...]
  Each RUN_DIR is a `taiga run --out` directory; give several runs of the same recording and
  binary to get medians over runs.
"""
import csv
import statistics
import sys

STAGES = ["read_ms", "deskew_ms", "filter_ms", "registration_ms", "optimization_ms", "map_ms",
          "total_ms"]


def percentile(values, q):
    """Linear interpolation between closest ranks, as taiga's own percentile()."""
    v = sorted(values)
    if not v:
        return float("nan")
    pos = (len(v) - 1) * q / 100.0
    lo = int(pos)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (pos - lo)


def load(run_dir):
    with open(f"{run_dir}/timing.csv") as f:
        timing = list(csv.DictReader(f))
    with open(f"{run_dir}/scans.csv") as f:
        scans = list(csv.DictReader(f))
    if len(timing) != len(scans):
        sys.exit(f"{run_dir}: timing.csv and scans.csv differ in length")
    # The first scan has no registration: it only seeds the map.
    rows = [(t, s) for t, s in zip(timing, scans) if s["lidar_factor"] != "first_scan"]
    return rows


def figures(rows):
    out = {}
    for stage in STAGES:
        v = [float(t[stage]) for t, _ in rows]
        out[stage] = (statistics.median(v), percentile(v, 95), percentile(v, 99), max(v),
                      statistics.fmean(v))
    # The scan that becomes a keyframe pays for the keyframe (map_ms); the second scan after it
    # may wait for the local map's rebuild (registration_ms, LocalMap::kScansOnPreviousMap).
    since = []
    count = None
    for _, s in rows:
        count = 0 if s["keyframe"] == "1" else (None if count is None else count + 1)
        since.append(count)
    for group, label in ((0, "0 (the keyframe)"), (1, "1"), (2, "2"), (3, "3 and later")):
        members = [t for (t, _), n in zip(rows, since)
                   if n is not None and (n == group or (group == 3 and n >= 3))]
        total = [float(t["total_ms"]) for t in members]
        registration = [float(t["registration_ms"]) for t in members]
        out[f"since {label}"] = (
            (len(members), statistics.median(total), max(total), statistics.median(registration),
             max(registration)) if members else (0,) + (float("nan"),) * 4)
    return out


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    per_run = [figures(load(d)) for d in sys.argv[1:]]
    print(f"{len(per_run)} run(s); per stage: median, p95, p99, max, mean over scans (ms), "
          "each the median over runs")
    print(f"| stage | median | p95 | p99 | max | mean |")
    print(f"|---|---|---|---|---|---|")
    for stage in STAGES:
        cols = [statistics.median(r[stage][k] for r in per_run) for k in range(5)]
        print(f"| {stage[:-3]} | " + " | ".join(f"{c:.2f}" for c in cols) + " |")
    print("\nby scans since the last keyframe (each the median over runs):")
    print("| scans since the keyframe | scans | total median | total max | registration median "
          "| registration max |")
    print("|---|---|---|---|---|---|")
    for key in [k for k in per_run[0] if k.startswith("since ")]:
        cols = [statistics.median(r[key][k] for r in per_run) for k in range(5)]
        print(f"| {key[6:]} | {cols[0]:.0f} | " + " | ".join(f"{c:.2f}" for c in cols[1:]) + " |")


if __name__ == "__main__":
    main()
