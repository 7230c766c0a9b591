#!/usr/bin/env bash
# The start's levelling seen at the end of a walk: for two taiga binaries on the same simulated
# recordings, the odometry's end-point height error (first poses aligned in position and heading,
# `taiga eval`'s "End-point drift, heading aligned") and the loop-closed trajectory's ATE (SE(3)).
# Without loop closure a tilt left by the levelling becomes a slope in the map that the odometry
# climbs (docs/odometry.md, Height).
#
# Usage: bench/levelling_height.sh REFERENCE_TAIGA NEW_TAIGA OUT_DIR [CASE ...]
#   CASE = scenario:seed:duration_s:realism[:rig file], default: the set of BENCHMARK.md
#   "Session 46" (64 beams; harsh with rig_truth.yaml, whose IMU errors no rig file can state).
set -euo pipefail
if [[ $# -lt 3 ]]; then
  echo "usage: $0 REFERENCE_TAIGA NEW_TAIGA OUT_DIR [CASE ...]" >&2
  exit 2
fi
reference="$1" new="$2" out="$3"
shift 3
cases=("$@")
if [[ ${#cases[@]} -eq 0 ]]; then
  cases=(dense_spruce:2:40:ideal dense_spruce:3:40:ideal mixed:1:60:ideal mixed:7:60:ideal
         dense_spruce:3:40:typical mixed:7:60:typical handheld-loop:12:60:typical
         handheld-loop:3:30:harsh:rig_truth.yaml handheld-loop:4:30:harsh:rig_truth.yaml)
fi
mkdir -p "$out"
printf '%-34s %-10s %12s %10s\n' case binary "end dz (m)" "ATE (cm)"
for c in "${cases[@]}"; do
  IFS=: read -r scenario seed duration realism rig <<<"$c"
  rig=${rig:-rig.yaml}
  sim="$out/sim_${scenario}_${seed}_${realism}"
  [[ -f "$sim/recording.bag" ]] || "$new" simulate --scenario "$scenario" --seed "$seed" \
    --duration "$duration" --realism "$realism" --beams 64 --out "$sim" >/dev/null 2>&1
  for label in reference new; do
    binary="$reference"; [[ "$label" == new ]] && binary="$new"
    run="$out/run_${scenario}_${seed}_${realism}_$label"
    rm -rf "$run"
    "$binary" run "$sim/recording.bag" --config "$sim/$rig" --out "$run" >/dev/null 2>&1
    dz=$("$new" eval --est "$run/trajectory_odometry.tum" --ref "$sim/groundtruth.tum" |
      sed -n 's/.*heading aligned (m).*dz \([-0-9.]*\).*/\1/p')
    ate=$("$new" eval --est "$run/trajectory.tum" --ref "$sim/groundtruth.tum" |
      awk '/^APE translation \(m\)/ {printf "%.1f", $5 * 100}')
    printf '%-34s %-10s %12s %10s\n' "$c" "$label" "$dz" "$ate"
  done
done
