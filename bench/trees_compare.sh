#!/usr/bin/env bash
# `taiga trees` of two binaries on the same runs (made by bench/trees_table.sh), and the fit
# across the surface alone (the new binary on the run's map.las, which has no sensor positions).
#   TAIGA_OLD=... TAIGA_NEW=... bench/trees_compare.sh DIR/CASE:RADIUS ...
# CASE is a trees_table.sh case directory (scenario_seed_realism); RADIUS as there (15 handheld,
# 12 harvester). Prints one Markdown row per case and variant.
set -euo pipefail
old=${TAIGA_OLD:?binary before the change}
new=${TAIGA_NEW:-build/bin/taiga}
echo "| case | taiga trees | reference | detected % | commission % | DBH RMSE cm | DBH bias cm | position RMSE cm |"
echo "|---|---|---|---|---|---|---|---|"
for c in "$@"; do
  dir=${c%:*} radius=${c##*:}
  for variant in old new across; do
    case $variant in
      old) bin=$old input=$dir/run ;;
      new) bin=$new input=$dir/run ;;
      across) bin=$new input=$dir/run/map.las ;;
    esac
    out=$dir/compare_$variant
    "$bin" trees "$input" --out "$out" >/dev/null
    "$new" eval --est "$dir/run/trajectory.tum" --ref "$dir/groundtruth.tum" --trees "$out/trees.csv" \
      --ref-trees "$dir/trees.csv" --trees-radius "$radius" --json >"$out/eval.json"
    python3 - "$out/eval.json" "$(basename "$dir")" "$variant" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["trees"]
print(f"| {sys.argv[2]} | {sys.argv[3]} | {t['reference']} | {100*t['recall']:.1f} | "
      f"{100*t['commission']:.1f} | {100*t['dbh_rmse_m']:.2f} | {100*t['dbh_bias_m']:+.2f} | "
      f"{100*t['position_rmse_m']:.2f} |")
PY
  done
done
