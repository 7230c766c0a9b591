#!/usr/bin/env bash
# The robustness table of issue 18: `taiga run` with the rig.yaml a user would write (nominal
# extrinsics, datasheet IMU noise, no time offset) on simulated recordings of several scenarios,
# realism presets and seeds, scored against the simulator's truth.
#
#   bench/robustness.sh [WORK_DIR]   (default /tmp/robustness; environment: TAIGA=path/to/taiga,
#       SCENARIOS="handheld-loop harvester dense_spruce", REALISM="ideal typical harsh",
#       SEEDS="1 2 3 4 5", DURATION_harvester=..., DURATION_<scenario>=... (default: the
#       scenario's own), BEAMS=64 to simulate fewer lidar rows (default: the full 128),
#       KEEP=1 to keep the recordings, OVERRIDES=file.yaml passed to every `taiga simulate`
#       (a recording kind, docs/simulator.md) with TAG=name, which the csv's scenario column
#       then carries as scenario[name]), RIG=rig_truth.yaml to run with the simulator's true rig
#       instead (default rig.yaml))
#
# One row per run is appended to WORK_DIR/robustness.csv as soon as it is done; cells already in
# it are skipped, so an interrupted table resumes. bench/robustness.py turns it into Markdown and
# a plot. Each recording is deleted after its run unless KEEP=1 (1-5 GB each at full OS0-128).
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
taiga=${TAIGA:-$here/../build/bin/taiga}
work=${1:-/tmp/robustness}
mkdir -p "$work"
csv=$work/robustness.csv
[[ -f $csv ]] || echo "scenario,realism,seed,duration_s,exit_code,scans,lidar_factors_rejected,loop_closures,ate_m,ate_odometry_m,ate_max_m,drift_m,drift_percent,path_m,realtime_factor,health,scans_degraded,scans_lost" > "$csv"

evaluate() {  # est ref -> "rmse max drift drift% path" (or "nan ..." when it cannot be scored)
  "$taiga" eval --json --est "$1" --ref "$2" 2>/dev/null | python3 -c '
import json, sys
try:
    d = json.load(sys.stdin)
    a, dr = d["ape"]["translation_m"], d["drift"]
    print(a["rmse"], a["max"], dr["drift_m"], dr["drift_percent"], dr["reference_path_length_m"])
except Exception:
    print("nan nan nan nan nan")'
}

beam_args=()
[[ -n ${BEAMS:-} ]] && beam_args=(--beams "$BEAMS")
[[ -n ${OVERRIDES:-} ]] && beam_args+=(--overrides "$OVERRIDES")
tag=${TAG:+[$TAG]}

for scenario in ${SCENARIOS:-handheld-loop harvester dense_spruce}; do
  var=DURATION_${scenario//-/_}
  duration_args=()
  [[ -n ${!var:-} ]] && duration_args=(--duration "${!var}")
  for realism in ${REALISM:-ideal typical harsh}; do
    for seed in ${SEEDS:-1 2 3 4 5}; do
      if cut -d, -f1-3 "$csv" | grep -qxF "$scenario$tag,$realism,$seed"; then continue; fi
      sim=$work/sim_${scenario}${TAG:+_$TAG}_${realism}_$seed
      run=$work/run_${scenario}${TAG:+_$TAG}_${realism}_$seed
      rm -rf "$sim" "$run"
      "$taiga" simulate --scenario "$scenario" --realism "$realism" --seed "$seed" \
        "${duration_args[@]}" "${beam_args[@]}" --out "$sim" > "$sim.log" 2>&1
      code=0
      "$taiga" run "$sim/recording.bag" --config "$sim/${RIG:-rig.yaml}" --out "$run" \
        > "$run.log" 2>&1 || code=$?
      read -r ate ate_max drift drift_pct path < <(evaluate "$run/trajectory.tum" "$sim/groundtruth.tum")
      read -r ate_odom _ < <(evaluate "$run/trajectory_odometry.tum" "$sim/groundtruth.tum")
      summary=$(python3 -c '
import json, sys
try:
    s = json.load(open(sys.argv[1]))
    h = s.get("health", {})
    print(s["scans"], s["lidar_factors_rejected"], s["loop_closures"], s["realtime_factor"], s["duration_s"],
          h.get("verdict", "nan"), h.get("scans_degraded", "nan"), h.get("scans_lost", "nan"))
except Exception:
    print("nan nan nan nan nan nan nan nan")' "$run/summary.json")
      read -r scans rejected loops rtf dur health degraded lost <<< "$summary"
      echo "$scenario$tag,$realism,$seed,$dur,$code,$scans,$rejected,$loops,$ate,$ate_odom,$ate_max,$drift,$drift_pct,$path,$rtf,$health,$degraded,$lost" >> "$csv"
      tail -1 "$csv"
      [[ ${KEEP:-0} == 1 ]] || rm -rf "$sim/recording.bag" "$run/keyframes" "$run/map.las"
    done
  done
done
