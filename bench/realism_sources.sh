#!/usr/bin/env bash
# Which of the `typical` realism errors costs how much accuracy: each error source of the preset
# on its own (the others ideal), `taiga run` with the rig.yaml a user would write, ATE against the
# truth. Issue 18 asks the closing note to name the sources that break the accuracy goal, each
# measured on its own.
#
#   bench/realism_sources.sh [WORK_DIR]   (default /tmp/realism_sources; environment:
#       TAIGA=path/to/taiga, SCENARIO=handheld-loop, DURATION=15, BEAMS=64, SEEDS="1 2 3")
#
# Prints one Markdown row per source: ATE RMSE (cm) per seed, their median, and the end-point
# drift (% of path).
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
taiga=${TAIGA:-$here/../build/bin/taiga}
work=${1:-/tmp/realism_sources}
scenario=${SCENARIO:-handheld-loop}
duration=${DURATION:-15}
beams=${BEAMS:-64}
seeds=${SEEDS:-1 2 3}
mkdir -p "$work"

# The values of the typical preset (src/sim/realism.cpp), one source at a time.
declare -A sources=(
  [ideal]=""
  [imu_noise_2x]="imu: {noise_density_factor: 2, bias_walk_factor: 2}"
  [imu_bias_instability]="imu: {accel_bias_instability_mps2: 5.0e-4, gyro_bias_instability_radps: 5.0e-5}"
  [imu_scale_axes_gsens]="imu: {scale_factor_error: 0.005, misalignment_deg: 0.3, gyro_g_sensitivity_deg_s_per_g: 0.03}"
  [imu_clip_jitter]="imu: {accel_range_g: 4, gyro_range_deg_s: 500, timestamp_jitter_s: 2.0e-4}"
  [extrinsic_rotation_2deg]="rig: {extrinsic_rotation_error_deg: 2}"
  [extrinsic_translation_3cm]="rig: {extrinsic_translation_error_m: 0.03}"
  [time_offset_10ms]="rig: {lidar_time_offset_s: 0.010}"
  [clock_drift_10ppm]="rig: {lidar_clock_drift_ppm: 10}"
  [lidar_noise_loss]="lidar: {dropout_probability: 0.02, range_noise_at_limit_m: 0.03, packet_loss_probability: 0.001}"
  [wind_5cm]="forest: {wind_sway_m: 0.05}"
  [typical]="PRESET"
)
order="ideal imu_noise_2x imu_bias_instability imu_scale_axes_gsens imu_clip_jitter extrinsic_rotation_2deg extrinsic_translation_3cm time_offset_10ms clock_drift_10ppm lidar_noise_loss wind_5cm typical"

echo "| error source ($scenario, ${duration} s, $beams beams) | ATE RMSE per seed (cm) | median (cm) | drift median (% of path) |"
echo "|---|---|---:|---:|"
for source in $order; do
  ates=() drifts=()
  for seed in $seeds; do
    dir=$work/$source-$seed
    args=(--scenario "$scenario" --duration "$duration" --seed "$seed" --beams "$beams")
    if [[ ${sources[$source]} == PRESET ]]; then
      args+=(--realism typical)
    elif [[ -n ${sources[$source]} ]]; then
      echo "${sources[$source]}" > "$work/$source.yaml"
      args+=(--overrides "$work/$source.yaml")
    fi
    [[ -f $dir/rec/groundtruth.tum ]] || "$taiga" simulate "${args[@]}" --out "$dir/rec" > /dev/null
    [[ -f $dir/run/trajectory.tum ]] || "$taiga" run "$dir/rec/recording.bag" --config "$dir/rec/rig.yaml" --out "$dir/run" > /dev/null 2>&1 || true
    read -r ate drift < <("$taiga" eval --json --est "$dir/run/trajectory.tum" --ref "$dir/rec/groundtruth.tum" 2>/dev/null |
      python3 -c 'import json, sys; d = json.load(sys.stdin); print(100 * d["ape"]["translation_m"]["rmse"], d["drift"]["drift_percent"])' || echo "nan nan")
    ates+=("$ate") drifts+=("$drift")
    rm -f "$dir/rec/recording.bag"; rm -rf "$dir/run/keyframes" "$dir/run/map.las"
  done
  python3 - "$source" "${#ates[@]}" "${ates[@]}" "${drifts[@]}" <<'PY'
import statistics, sys
name, n = sys.argv[1], int(sys.argv[2])
ates, drifts = [float(x) for x in sys.argv[3:3 + n]], [float(x) for x in sys.argv[3 + n:]]
print(f"| {name} | {', '.join(f'{a:.1f}' for a in ates)} | {statistics.median(ates):.1f} | {statistics.median(drifts):.2f} |")
PY
done
