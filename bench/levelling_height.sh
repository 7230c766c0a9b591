#!/usr/bin/env bash
# The start's levelling seen at the end of a walk: for two taiga binaries on the same simulated
# recordings, the odometry's end-point error per axis (first poses aligned in position and
# heading, `taiga eval`'s "End-point drift, heading aligned"), its largest axis in % of the path
# (issue 25 asks <= 0.1 % in every axis) and the loop-closed trajectory's ATE (SE(3)).
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
printf '%-34s %-10s %9s %9s %9s %10s %9s\n' case binary "dx (m)" "dy (m)" "dz (m)" "max axis %" "ATE (cm)"
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
    evaluation=$("$new" eval --est "$run/trajectory_odometry.tum" --ref "$sim/groundtruth.tum")
    read -r dx dy dz < <(sed -n 's/.*heading aligned (m) *dx \([-0-9.]*\), dy \([-0-9.]*\), dz \([-0-9.]*\);.*/\1 \2 \3/p' <<<"$evaluation")
    path=$(sed -n 's/.*reference path \([0-9.]*\) m.*/\1/p' <<<"$evaluation")
    worst=$(awk -v a="$dx" -v b="$dy" -v c="$dz" -v p="$path" 'function abs(v) {return v < 0 ? -v : v}
      BEGIN {m = abs(a); if (abs(b) > m) m = abs(b); if (abs(c) > m) m = abs(c); printf "%.2f", 100 * m / p}')
    ate=$("$new" eval --est "$run/trajectory.tum" --ref "$sim/groundtruth.tum" |
      awk '/^APE translation \(m\)/ {printf "%.1f", $5 * 100}')
    printf '%-34s %-10s %9.3f %9.3f %9.3f %10s %9s\n' "$c" "$label" "$dx" "$dy" "$dz" "$worst" "$ate"
  done
done
