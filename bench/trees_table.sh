#!/usr/bin/env bash
# The forest inventory's accuracy table (docs/trees.md, BENCHMARK.md "Trees"): simulate, run,
# `taiga trees`, `taiga eval --trees` against the simulator's trees.csv, for scenarios and seeds.
#   bench/trees_table.sh [OUT_DIR]          (TAIGA=path/to/taiga, CASES="scenario:seed:radius ...")
# Prints one Markdown row per case. Uses 64 beams and 60 s (BEAMS, DURATION to change).
set -euo pipefail
taiga=${TAIGA:-build/bin/taiga}
out=${1:-/tmp/taiga_trees_table}
beams=${BEAMS:-64}
duration=${DURATION:-60}
cases=${CASES:-"handheld-loop:12:15 handheld-loop:13:15 harvester:5:12"}
mkdir -p "$out"
echo "| scenario | seed | realism | reference trees | detected % | commission % | DBH RMSE cm | DBH bias cm | position RMSE cm | height RMSE m | taiga trees s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for c in $cases; do
  IFS=: read -r scenario seed radius <<<"$c"
  realism=${REALISM:-ideal}
  rec="$out/${scenario}_${seed}_${realism}"
  [ -f "$rec/recording.bag" ] || "$taiga" simulate --scenario "$scenario" --realism "$realism" \
    --duration "$duration" --seed "$seed" --beams "$beams" --out "$rec" >/dev/null 2>&1
  [ -f "$rec/run/map.las" ] || "$taiga" run "$rec/recording.bag" --config "$rec/rig.yaml" \
    --out "$rec/run" >"$rec/run.log" 2>&1
  start_ns=$(date +%s%N)
  "$taiga" trees "$rec/run" --out "$rec/trees" >/dev/null
  milliseconds=$((($(date +%s%N) - start_ns) / 1000000))
  "$taiga" eval --est "$rec/run/trajectory.tum" --ref "$rec/groundtruth.tum" \
    --trees "$rec/trees/trees.csv" --ref-trees "$rec/trees.csv" --trees-radius "$radius" \
    --json >"$rec/trees/eval.json"
  python3 - "$rec/trees/eval.json" "$scenario" "$seed" "$realism" "$milliseconds" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["trees"]
print(f"| {sys.argv[2]} | {sys.argv[3]} | {sys.argv[4]} | {t['reference']} | {100*t['recall']:.1f} | "
      f"{100*t['commission']:.1f} | {100*t['dbh_rmse_m']:.2f} | {100*t['dbh_bias_m']:+.2f} | "
      f"{100*t['position_rmse_m']:.2f} | {t['height_rmse_m']:.2f} | {float(sys.argv[5])/1000:.1f} |")
PY
done
