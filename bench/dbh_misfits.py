#!/usr/bin/python3
"""Where a tree list's DBH error comes from: RMSE and bias by distance from the path, and every
matched stem off by more than 4 cm with its fit's attributes (trees.csv).

  taiga eval ... --trees RUN/trees/trees.csv --ref-trees SIM/trees.csv --json > eval.json
  bench/dbh_misfits.py eval.json RUN/trees/trees.csv
"""
import csv
import json
import math
import sys


def rmse_bias(errors):
    n = len(errors)
    return math.sqrt(sum(e * e for e in errors) / n), sum(errors) / n


def main(eval_json, trees_csv):
    trees = json.load(open(eval_json))["trees"]
    stems = {int(r["id"]): r for r in csv.DictReader(open(trees_csv))}
    matches = trees["matches"]
    print(f"recall {trees['recall']:.3f} commission {trees['commission']:.3f}")
    for limit_m in (5, 10, 12, 15):
        errors = [m["est_dbh_m"] - m["ref_dbh_m"] for m in matches
                  if m["path_distance_m"] < limit_m]
        if errors:
            rmse, bias = rmse_bias(errors)
            print(f"within {limit_m:2d} m: {len(errors):3d} stems, DBH RMSE {100 * rmse:.2f} cm,"
                  f" bias {100 * bias:+.2f} cm")
    misfits = [m for m in matches if abs(m["est_dbh_m"] - m["ref_dbh_m"]) > 0.04]
    for m in sorted(misfits, key=lambda m: m["path_distance_m"]):
        s = stems[m["est_id"]]
        print(f"ref {m['ref_id']:4d} est {m['est_id']:4d}: DBH {100 * m['ref_dbh_m']:5.1f} ->"
              f" {100 * m['est_dbh_m']:5.1f} cm, {m['path_distance_m']:4.1f} m from the path,"
              f" {s['points']:>4} points, rms {100 * float(s['fit_rms_m']):3.1f} cm,"
              f" arc {s['arc_deg']:>3} deg, {s['slices']:>2} slices,"
              f" sigma {100 * float(s['dbh_sigma_m']):4.1f} cm, {s['quality']},"
              f" at ({float(s['x_bh_m']):.2f}, {float(s['y_bh_m']):.2f})")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
