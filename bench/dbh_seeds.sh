#!/usr/bin/env bash
# DBH accuracy of `typical` handheld walks by distance from the path, one row per seed (issue 22;
# BENCHMARK.md, "Session 58"): simulate (handheld-loop, typical, 60 s, 64 beams), `taiga run` with
# the rig.yaml as written, `taiga trees`, `taiga eval --trees --trees-radius 15`.
#   bench/dbh_seeds.sh [OUT_DIR]   (TAIGA=path/to/taiga, SEEDS="12 13 ...", TAG=name of the trees run)
# Recordings and runs are kept in OUT_DIR and reused; each TAG gets its own trees/eval, so two
# binaries can be compared on the same maps (TAIGA=old TAG=old, then TAIGA=new TAG=new).
set -euo pipefail
taiga=${TAIGA:-build/bin/taiga}
out=${1:-/tmp/taiga_dbh_seeds}
tag=${TAG:-trees}
mkdir -p "$out"
echo "| seed | recall % | commission % | DBH RMSE within 10 m cm (bias) | within 15 m cm (bias) | median abs error cm | errors > 4 cm | within 2 sigma % |"
echo "|---|---:|---:|---|---|---:|---:|---:|"
for seed in ${SEEDS:-12 13 14 15 16}; do
  rec="$out/$seed"
  [ -f "$rec/sim/recording.bag" ] || "$taiga" simulate --scenario handheld-loop --realism typical \
    --duration 60 --seed "$seed" --beams 64 --out "$rec/sim" >/dev/null 2>&1
  [ -f "$rec/run/map.las" ] || "$taiga" run "$rec/sim/recording.bag" --config "$rec/sim/rig.yaml" \
    --out "$rec/run" >"$rec/run.log" 2>&1
  "$taiga" trees "$rec/run" --out "$rec/$tag" >"$rec/$tag.log" 2>&1
  "$taiga" eval --est "$rec/run/trajectory.tum" --ref "$rec/sim/groundtruth.tum" \
    --trees "$rec/$tag/trees.csv" --ref-trees "$rec/sim/trees.csv" --trees-radius 15 \
    --json >"$rec/$tag/eval.json" 2>/dev/null
  python3 - "$rec/$tag/eval.json" "$seed" <<'PY'
import json, math, statistics, sys
t = json.load(open(sys.argv[1]))["trees"]
errors = [(m["path_distance_m"], m["est_dbh_m"] - m["ref_dbh_m"]) for m in t["matches"]]
def cell(limit_m):
    e = [v for d, v in errors if d < limit_m]
    return f"{100 * math.sqrt(sum(v * v for v in e) / len(e)):.2f} ({100 * sum(e) / len(e):+.2f})"
median = 100 * statistics.median(abs(v) for _, v in errors)
misfits = sum(abs(v) > 0.04 for _, v in errors)
print(f"| {sys.argv[2]} | {100 * t['recall']:.1f} | {100 * t['commission']:.1f} | {cell(10)} | "
      f"{cell(15)} | {median:.2f} | {misfits} | {100 * t['dbh_within_2_sigma']:.0f} |")
PY
done
