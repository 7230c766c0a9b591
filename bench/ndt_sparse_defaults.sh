#!/usr/bin/env bash
# NDT settings for sparse lidars (fewer than 64 beams), side by side on the same simulated
# recordings (BENCHMARK.md, "Session 40"): each case is simulated once, then run with
# each variant of the odometry settings layered on the simulator's rig.yaml.
#   bench/ndt_sparse_defaults.sh [OUT_DIR]
#   TAIGA=path/to/taiga  CASES="scenario:beams:seed ..."  DURATION=60  REALISM=ideal
#   VARIANTS="name:key=value,key=value ..." (name "rig" = the rig.yaml unchanged)
# Prints one Markdown row per case and variant: APE RMSE (cm), verdict, median and p95 ms/scan.
set -euo pipefail
taiga=${TAIGA:-build/bin/taiga}
out=${1:-/tmp/taiga_ndt_sparse}
duration=${DURATION:-60}
realism=${REALISM:-ideal}
cases=${CASES:-"harvester:32:59 harvester:32:51 handheld-loop:32:3 handheld-loop:16:3"}
variants=${VARIANTS:-"rig: d1_1m:ndt_neighbours=direct1,ndt_resolution_m=1.0 d7_1m:ndt_neighbours=direct7,ndt_resolution_m=1.0 d1_05m:ndt_neighbours=direct1,ndt_resolution_m=0.5"}
mkdir -p "$out"
echo "| scenario | beams | seed | variant | APE RMSE cm | verdict | median ms | p95 ms |"
echo "|---|---|---|---|---|---|---|---|"
for c in $cases; do
  IFS=: read -r scenario beams seed <<<"$c"
  rec="$out/${scenario}_${beams}_${seed}_${realism}"
  [ -f "$rec/recording.bag" ] || "$taiga" simulate --scenario "$scenario" --realism "$realism" \
    --duration "$duration" --seed "$seed" --beams "$beams" --out "$rec" >/dev/null 2>&1
  boxes=()
  [ -f "$rec/machine_boxes.csv" ] && boxes=(--moving-boxes "$rec/machine_boxes.csv")
  for v in $variants; do
    name=${v%%:*}
    settings=${v#*:}
    python3 - "$rec/rig.yaml" "$rec/$name.yaml" "$settings" <<'PY'
import sys, yaml
config = yaml.safe_load(open(sys.argv[1]))
for kv in filter(None, sys.argv[3].split(",")):
    key, value = kv.split("=")
    config.setdefault("odometry", {})[key] = yaml.safe_load(value)
yaml.safe_dump(config, open(sys.argv[2], "w"))
PY
    run="$rec/run_$name"
    "$taiga" run "$rec/recording.bag" --config "$rec/$name.yaml" "${boxes[@]}" --out "$run" \
      >"$run.log" 2>&1 || true
    "$taiga" eval --est "$run/trajectory.tum" --ref "$rec/groundtruth.tum" --json >"$run/eval.json"
    python3 - "$run" "$scenario" "$beams" "$seed" "$name" <<'PY'
import json, sys
run, scenario, beams, seed, name = sys.argv[1:]
e = json.load(open(f"{run}/eval.json"))
s = json.load(open(f"{run}/summary.json"))
t = s["time_per_scan_ms"]
print(f"| {scenario} | {beams} | {seed} | {name} | {100*e['ape']['translation_m']['rmse']:.2f} | "
      f"{s['health']['verdict']} | {t['p50']:.1f} | {t['p95']:.1f} |")
PY
  done
done
