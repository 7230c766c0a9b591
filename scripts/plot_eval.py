#!/usr/bin/python3
"""Plots for `taiga eval --plots DIR`, `taiga compare --plots DIR` and `taiga calibrate`.

Usage: /usr/bin/python3 plot_eval.py DATA.json OUT_DIR LISTING

DATA.json is written by taiga (src/eval/report_json.cpp, src/eval/compare.cpp). The PNGs go to
OUT_DIR and their paths, one per line, to LISTING. Exit codes: 0 done, 2 bad arguments or data,
3 matplotlib missing (taiga turns that into an install hint).
"""
import json
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")  # files only, no display needed
    import matplotlib.pyplot as plt
except ImportError as error:
    sys.stderr.write(f"plot_eval.py: cannot import matplotlib ({error})\n")
    sys.exit(3)

DPI = 120


def save(fig, out_dir, name, written):
    path = os.path.join(out_dir, name)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    written.append(path)


def xy(series):
    return [p[0] for p in series["xyz"]], [p[1] for p in series["xyz"]]


def top_view(ax, reference, estimates, ref_label):
    rx, ry = xy(reference)
    ax.plot(rx, ry, color="black", linestyle="--", linewidth=1.2, label=f"reference ({ref_label})")
    for label, series in estimates:
        ex, ey = xy(series)
        ax.plot(ex, ey, linewidth=1.2, label=label)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")


def relative_times(series):
    t = series["t_s"]
    return [v - t[0] for v in t] if t else []


def plot_timing(timing, out_dir, written, title):
    t0 = timing["t_s"][0] if timing["t_s"] else 0.0
    t = [v - t0 for v in timing["t_s"]]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    stages = timing["stages"]
    if stages:
        ax1.stackplot(t, [s["ms"] for s in stages], labels=[s["name"] for s in stages], alpha=0.7)
    ax1.plot(t, timing["total_ms"], color="black", linewidth=0.8, label="total_ms")
    ax1.axhline(timing["period_ms"], color="red", linestyle="--", linewidth=1,
                label=f"sensor period {timing['period_ms']:g} ms")
    ax1.set_xlabel("time since the first scan (s)")
    ax1.set_ylabel("processing time per scan (ms)")
    ax1.set_title(title)
    ax1.grid(True, alpha=0.3)
    ax1.legend(fontsize="small", loc="upper left")
    ax2.hist(timing["total_ms"], bins=50, color="tab:blue", edgecolor="white")
    ax2.axvline(timing["period_ms"], color="red", linestyle="--", linewidth=1)
    ax2.set_xlabel("total processing time per scan (ms)")
    ax2.set_ylabel("scans")
    ax2.set_title("distribution")
    ax2.grid(True, alpha=0.3)
    save(fig, out_dir, "timing.png", written)


def plot_eval(data, out_dir, written):
    ref, est = data["reference"], data["estimate"]
    fig, ax = plt.subplots(figsize=(8, 7))
    top_view(ax, ref, [(f"estimate ({data['est_label']}, {data['alignment']} aligned)", est)],
             data["ref_label"])
    ax.set_title("trajectory, top view")
    save(fig, out_dir, "trajectory_top.png", written)

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(10, 7))
    ape = data["ape_m"]
    ax1.plot(relative_times(ref), ape, linewidth=1)
    ax1.set_xlabel("time since the first associated pose (s)")
    ax1.set_ylabel("APE translation (m)")
    ax1.set_title(f"absolute position error ({data['alignment']} alignment)")
    ax1.grid(True, alpha=0.3)
    ax2.plot(ref["path_m"], ape, linewidth=1, color="tab:orange")
    ax2.set_xlabel("distance along the reference path (m)")
    ax2.set_ylabel("APE translation (m)")
    ax2.grid(True, alpha=0.3)
    save(fig, out_dir, "ape.png", written)

    if "timing" in data:
        plot_timing(data["timing"], out_dir, written, "processing time per scan")
    if "trees" in data:
        plot_trees(data["trees"], ref, out_dir, written)


def plot_trees(trees, reference, out_dir, written):
    """The tree map (`taiga eval --trees`): matched stems coloured by their DBH error, missed
    reference trees and false stems, over the reference path."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(15, 6.5), gridspec_kw={"width_ratios": [3, 2]})
    rx, ry = xy(reference)
    ax1.plot(rx, ry, color="black", linewidth=1, label="reference path")
    matched = trees["matches"]
    if matched:
        errors_cm = [100 * (m["est_dbh_m"] - m["ref_dbh_m"]) for m in matched]
        bound = max(2.0, max(abs(e) for e in errors_cm))
        points = ax1.scatter([m["ref_xy_m"][0] for m in matched], [m["ref_xy_m"][1] for m in matched],
                             s=[3000 * m["ref_dbh_m"] ** 2 + 8 for m in matched], c=errors_cm,
                             cmap="coolwarm", vmin=-bound, vmax=bound, edgecolors="black",
                             linewidths=0.3, label=f"found ({len(matched)})")
        fig.colorbar(points, ax=ax1, label="DBH error (cm), est - ref")
    for key, marker, colour, label in (("missed_xy_m", "x", "red", "missed reference tree"),
                                       ("false_xy_m", "+", "purple", "false stem")):
        if trees[key]:
            ax1.scatter([p[0] for p in trees[key]], [p[1] for p in trees[key]], marker=marker,
                        s=60, color=colour, label=f"{label} ({len(trees[key])})")
    ax1.set_xlabel("x (m)")
    ax1.set_ylabel("y (m)")
    ax1.set_aspect("equal", adjustable="datalim")
    ax1.grid(True, alpha=0.3)
    ax1.legend(fontsize="small", loc="upper right")
    ax1.set_title(f"trees within {trees['max_path_distance_m']:g} m of the path, DBH >= "
                  f"{100 * trees['min_dbh_m']:g} cm: {100 * trees['recall']:.1f} % found, "
                  f"{100 * trees['commission']:.1f} % false")
    if matched:
        ax2.scatter([100 * m["ref_dbh_m"] for m in matched], [100 * m["est_dbh_m"] for m in matched],
                    s=12, c=[m["path_distance_m"] for m in matched], cmap="viridis")
        lo = min(100 * m["ref_dbh_m"] for m in matched)
        hi = max(100 * m["ref_dbh_m"] for m in matched)
        ax2.plot([lo, hi], [lo, hi], color="black", linewidth=0.8)
    ax2.set_xlabel("reference DBH (cm)")
    ax2.set_ylabel("estimated DBH (cm), colour: distance from the path")
    ax2.set_title(f"DBH RMSE {100 * trees['dbh_rmse_m']:.2f} cm, bias {100 * trees['dbh_bias_m']:+.2f} cm")
    ax2.set_aspect("equal", adjustable="datalim")
    ax2.grid(True, alpha=0.3)
    save(fig, out_dir, "trees.png", written)


def plot_compare(data, out_dir, written):
    runs = data["runs"]
    fig, ax = plt.subplots(figsize=(8, 7))
    top_view(ax, data["reference"], [(run["name"], run["estimate"]) for run in runs],
             data["ref_label"])
    ax.set_title(f"runs, top view ({data['alignment']} aligned)")
    save(fig, out_dir, "compare_top.png", written)

    fig, ax = plt.subplots(figsize=(10, 4.5))
    for run in runs:
        ax.plot(relative_times(run["estimate"]), run["ape_m"], linewidth=1, label=run["name"])
    ax.set_xlabel("time since the first associated pose (s)")
    ax.set_ylabel("APE translation (m)")
    ax.set_title("absolute position error per run")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    save(fig, out_dir, "compare_ape.png", written)


def plot_calibration(data, out_dir, written):
    """The profile cost of the lidar-IMU time offset (docs/calibration.md)."""
    curve = data["cost_curve"]
    offsets_ms = [1e3 * t for t in curve["offset_s"]]
    rms_deg_s = [57.29577951308232 * r for r in curve["rms_radps"]]
    estimate_ms = 1e3 * data["time_offset"]["estimated_s"]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(offsets_ms, rms_deg_s, color="tab:blue", linewidth=1.2)
    ax.axvline(estimate_ms, color="tab:red", linestyle="--", linewidth=1.0,
               label=f"estimate {estimate_ms:.2f} ms")
    ax.set_xlabel("lidar time offset (s added to lidar times), ms")
    ax.set_ylabel("gyro vs registration, RMS deg/s")
    ax.set_title("Time offset: profile cost (rotation and gyro bias fitted at each offset)")
    ax.grid(True, alpha=0.3)
    ax.legend()
    save(fig, out_dir, "offset_cost.png", written)


def main(argv):
    if len(argv) != 4:
        sys.stderr.write(__doc__)
        return 2
    data_path, out_dir, listing = argv[1], argv[2], argv[3]
    try:
        with open(data_path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError) as error:
        sys.stderr.write(f"plot_eval.py: {data_path}: {error}\n")
        return 2
    os.makedirs(out_dir, exist_ok=True)
    written = []
    kind = data.get("kind")
    if kind == "eval":
        plot_eval(data, out_dir, written)
    elif kind == "compare":
        plot_compare(data, out_dir, written)
    elif kind == "calibration":
        plot_calibration(data, out_dir, written)
    else:
        sys.stderr.write(f"plot_eval.py: {data_path}: unknown kind {kind!r}\n")
        return 2
    with open(listing, "w", encoding="utf-8") as f:
        f.write("".join(path + "\n" for path in written))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
