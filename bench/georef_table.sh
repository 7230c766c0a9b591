#!/usr/bin/env bash
# The georeferencing table of issue 9 (thesis Tables 5-6): on simulated `handheld-loop` and
# `harvester` recordings with canopy-degraded GNSS, `taiga run` without and with GNSS fused in the
# mapping graph, the four post-fit methods of `taiga georef` on the unfused trajectory, and the
# errors of each against the simulator's truth (bench/georef_table.py explains how).
#
#   bench/georef_table.sh [WORK_DIR]   (default /tmp/georef_table; environment: TAIGA=path/to/taiga,
#                                       BEAMS=32, SEED=1, DURATION=180, SCENARIOS="handheld-loop harvester")
#
# Runs one heavy job at a time. Simulations are kept in WORK_DIR and reused; delete WORK_DIR
# afterwards (about 0.5 GB per 180 s simulation at 32 beams, plus the runs' keyframes).
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
taiga=${TAIGA:-$here/../build/bin/taiga}
work=${1:-/tmp/georef_table}
beams=${BEAMS:-32}
seed=${SEED:-1}
duration=${DURATION:-180}
mkdir -p "$work"

echo "| scenario | method | east RMS (m) | north RMS (m) | up RMS (m) | horizontal RMS (m) | mean E / N / U (m) | roll (deg) | pitch (deg) | yaw (deg) | ATE of the run (cm) |"
echo "|---|---|---:|---:|---:|---:|---|---:|---:|---:|---:|"
for scenario in ${SCENARIOS:-handheld-loop harvester}; do
  sim=$work/sim_$scenario
  off=$work/run_${scenario}_off
  on=$work/run_${scenario}_fused
  if [[ ! -f $sim/recording.bag ]]; then
    "$taiga" simulate --scenario "$scenario" --beams "$beams" --seed "$seed" \
      --duration "$duration" --out "$sim" >&2
  fi
  # The fused run: the simulation's rig with mapping.gnss_fusion on.
  # (Simulations written since the option exists list it, off; older ones do not.)
  if grep -q '^  gnss_fusion:' "$sim/rig.yaml"; then
    sed 's/^  gnss_fusion:.*/  gnss_fusion: true/' "$sim/rig.yaml" > "$work/rig_${scenario}_fused.yaml"
  else
    sed 's/^mapping:.*/&\n  gnss_fusion: true/' "$sim/rig.yaml" > "$work/rig_${scenario}_fused.yaml"
  fi
  [[ -f $off/summary.json ]] || "$taiga" run "$sim/recording.bag" --config "$sim/rig.yaml" --out "$off" >&2
  [[ -f $on/summary.json ]] || "$taiga" run "$sim/recording.bag" --config "$work/rig_${scenario}_fused.yaml" --out "$on" >&2
  for run in "$off" "$on"; do
    "$taiga" eval --est "$run/trajectory.tum" --ref "$sim/groundtruth.tum" --json > "$run/eval.json"
  done
  georefs=()
  for method in closed pf3 pf6 robust; do
    "$taiga" georef --traj "$off/trajectory.tum" --gnss "$sim/recording.bag" --config "$sim/rig.yaml" \
      --method "$method" --out "$off/georef_$method" >&2 || { echo "georef $method failed" >&2; continue; }
    georefs+=(--georef "$method=$off/georef_$method/georef.yaml")
  done
  python3 "$here/georef_table.py" --sim "$sim" --label "$scenario" "${georefs[@]}" \
    --traj-off "$off/trajectory.tum" --eval-off "$off/eval.json" \
    --fused "$on/summary.json" --traj-on "$on/trajectory.tum" --eval-on "$on/eval.json"
  # The keyframe scans and maps are what takes the space; the table needs the trajectories.
  rm -rf "$off/keyframes" "$on/keyframes" "$off/map.las" "$on/map.las" "$off"/georef/map_epsg*.las \
    "$on"/georef/map_epsg*.las
done
