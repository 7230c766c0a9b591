#!/usr/bin/python3
"""The robustness table (bench/robustness.sh writes robustness.csv): Markdown and a plot.

    /usr/bin/python3 bench/robustness.py WORK_DIR/robustness.csv [PLOT.png]

Per scenario and realism: the ATE (loop-closed, and the odometry alone) of every seed, its
median, the end-point drift, scans whose lidar factor was rejected, and failures (a non-zero
exit, or an ATE above 0.5 m: 10x the goal), and of those the silent ones (exit 0 and the health
monitor's verdict ok, degraded or recovered; rows from before the monitor have no verdict: '-'). Where the ideal run of the same scenario and seed
exists, the ATE is also given as a ratio to it.
"""
import csv
import statistics
import sys
from collections import defaultdict


def main():
    rows = list(csv.DictReader(open(sys.argv[1])))
    cells = defaultdict(list)
    for r in rows:
        cells[(r["scenario"], r["realism"])].append(r)
    ideal_ate = {(r["scenario"], r["seed"]): float(r["ate_m"]) for r in rows if r["realism"] == "ideal"}

    def f(x):
        try:
            return float(x)
        except ValueError:
            return float("nan")

    print("| scenario | realism | seeds | ATE per seed (cm) | median ATE (cm) | ATE / ideal (same seed) | "
          "odometry ATE median (cm) | drift median (% of path) | scans rejected | scans degraded / lost | "
          "failures | silent failures |")
    print("|---|---|---:|---|---:|---|---:|---:|---:|---|---:|---:|")
    order = {"ideal": 0, "typical": 1, "harsh": 2}
    for (scenario, realism), rs in sorted(cells.items(), key=lambda kv: (kv[0][0], order.get(kv[0][1], 9))):
        rs.sort(key=lambda r: int(r["seed"]))
        ates = [100 * f(r["ate_m"]) for r in rs]
        ratios = [f(r["ate_m"]) / ideal_ate[(scenario, r["seed"])] for r in rs
                  if (scenario, r["seed"]) in ideal_ate and realism != "ideal"]
        failed = [r for r in rs if r["exit_code"] != "0" or not f(r["ate_m"]) < 0.5]
        with_health = all(r.get("health") not in (None, "", "nan") for r in rs)
        silent = (str(sum(1 for r in failed if r["exit_code"] == "0" and r["health"] in ("ok", "degraded", "recovered")))
                  if with_health else "-")
        flagged = (f"{sum(int(f(r['scans_degraded'])) for r in rs)} / {sum(int(f(r['scans_lost'])) for r in rs)}"
                   if with_health else "-")
        print(f"| {scenario} | {realism} | {len(rs)} | {', '.join(f'{a:.1f}' for a in ates)} | "
              f"{statistics.median(ates):.1f} | {', '.join(f'{x:.2f}' for x in ratios) or '-'} | "
              f"{100 * statistics.median(f(r['ate_odometry_m']) for r in rs):.1f} | "
              f"{statistics.median(f(r['drift_percent']) for r in rs):.2f} | "
              f"{sum(int(f(r['lidar_factors_rejected'])) for r in rs)} | {flagged} | {len(failed)} | {silent} |")

    if len(sys.argv) > 2:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        keys = sorted(cells, key=lambda k: (k[0], order.get(k[1], 9)))
        fig, ax = plt.subplots(figsize=(1.2 + 1.1 * len(keys), 4))
        colors = {"ideal": "tab:green", "typical": "tab:orange", "harsh": "tab:red"}
        for i, k in enumerate(keys):
            ates = [100 * f(r["ate_m"]) for r in cells[k]]
            ax.scatter([i] * len(ates), ates, color=colors.get(k[1], "gray"), zorder=3)
            ax.hlines(statistics.median(ates), i - 0.3, i + 0.3, color="black")
        ax.set_xticks(range(len(keys)), [f"{s}\n{r}" for s, r in keys], fontsize=8)
        ax.set_ylabel("ATE RMSE (cm), loop-closed")
        ax.set_yscale("log")
        ax.axhline(5, color="gray", linestyle="--", linewidth=0.8)
        ax.set_title("taiga run with the rig.yaml a user would write, per seed")
        ax.grid(axis="y", which="both", alpha=0.3)
        fig.tight_layout()
        fig.savefig(sys.argv[2], dpi=110)


if __name__ == "__main__":
    main()
