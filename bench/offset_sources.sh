#!/usr/bin/env bash
# Which realism error makes `taiga calibrate`'s lidar-IMU time offset miss the truth by more than
# its 1-sigma (issue 20, "honest sigma"): each recording is simulated with a preset, or with the
# preset less one error source (set to its ideal value by an overrides file), calibrated on its
# first STRETCH s, and the offset compared with the truth over that stretch (rig_truth.yaml's
# offset holds at the start; the lidar's clock drift moves it by -drift x t, so the truth is
# taken at the stretch's middle).
#
#   bench/offset_sources.sh [WORK_DIR]   (default /tmp/offset_sources; environment:
#       TAIGA=path/to/taiga, SCENARIO=handheld-loop, DURATION=35, STRETCH=30, BEAMS=64,
#       SEEDS="1 2 3 4", REALISM=typical, SOURCES="all no_scale_axes_gsens ...")
#
# Writes WORK_DIR/results.csv (one row per recording) and prints a Markdown table: per source
# removed, the offset errors (ms) and |error| / 1-sigma per seed.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
taiga=${TAIGA:-$here/../build/bin/taiga}
work=${1:-/tmp/offset_sources}
scenario=${SCENARIO:-handheld-loop}
duration=${DURATION:-35}
stretch=${STRETCH:-30}
beams=${BEAMS:-64}
seeds=${SEEDS:-1 2 3 4}
realism=${REALISM:-typical}
mkdir -p "$work"

# Each entry: the overrides that set one error source of the preset back to ideal.
declare -A sources=(
  [all]=""
  [no_scale_axes_gsens]="imu: {scale_factor_error: 0, misalignment_deg: 0, gyro_g_sensitivity_deg_s_per_g: 0}"
  [no_scale]="imu: {scale_factor_error: 0}"
  [no_axes]="imu: {misalignment_deg: 0}"
  [no_gsens]="imu: {gyro_g_sensitivity_deg_s_per_g: 0}"
  [no_jitter]="imu: {timestamp_jitter_s: 0}"
  [imu_200hz]="imu: {rate_hz: 200}"
  [no_imu_noise]="imu: {noise_density_factor: 1, bias_walk_factor: 1, accel_bias_instability_mps2: 0, gyro_bias_instability_radps: 0}"
  [no_clock_drift]="rig: {lidar_clock_drift_ppm: 0}"
  [no_extrinsic_error]="rig: {extrinsic_rotation_error_deg: 0, extrinsic_translation_error_m: 0}"
  [no_lidar_errors]="lidar: {dropout_probability: 0.01, range_noise_at_limit_m: 0, packet_loss_probability: 0}"
  [no_wind]="forest: {wind_sway_m: 0}"
)
order=${SOURCES:-all no_scale_axes_gsens no_jitter no_imu_noise no_clock_drift no_extrinsic_error no_lidar_errors no_wind}

csv=$work/results.csv
[[ -f $csv ]] || echo "scenario,realism,source,seed,offset_error_ms,offset_sigma_ms,ratio,rotation_error_deg,exit" > "$csv"
for source in $order; do
  for seed in $seeds; do
    key="$scenario,$realism,$source,$seed,"
    grep -q "^$key" "$csv" && continue
    rec=$work/$realism-$source-$seed
    args=(--scenario "$scenario" --realism "$realism" --duration "$duration" --seed "$seed" --beams "$beams")
    if [[ -n ${sources[$source]} ]]; then
      echo "${sources[$source]}" > "$work/$source.yaml"
      args+=(--overrides "$work/$source.yaml")
    fi
    [[ -f $rec/groundtruth.tum ]] || "$taiga" simulate "${args[@]}" --out "$rec" > /dev/null
    code=0
    "$taiga" calibrate "$rec/recording.bag" --config "$rec/rig.yaml" --duration "$stretch" \
      --out "$rec/calibrate" --no-plots > "$rec/calibrate.log" 2>&1 || code=$?
    row=$(/usr/bin/python3 - "$rec" "$stretch" <<'PY'
import json, sys
import numpy as np, yaml
from scipy.spatial.transform import Rotation
rec, stretch = sys.argv[1], float(sys.argv[2])
c = json.load(open(f"{rec}/calibrate/calibration.json"))
truth = yaml.safe_load(open(f"{rec}/rig_truth.yaml"))["rig"]
drift_ppm = yaml.safe_load(open(f"{rec}/scenario.yaml"))["rig"].get("lidar_clock_drift_ppm", 0.0)
true_s = truth["lidar_time_offset_s"] - 1e-6 * drift_ppm * stretch / 2
error_ms = 1e3 * (c["time_offset"]["estimated_s"] - true_s)
sigma_ms = 1e3 * c["time_offset"]["sigma_s"]
R_est = Rotation.from_quat(c["rotation"]["estimated_quaternion_xyzw"])
R_true = Rotation.from_quat(truth["T_body_lidar"]["quaternion_xyzw"])
print(f"{error_ms:.3f},{sigma_ms:.3f},{abs(error_ms) / sigma_ms:.2f},"
      f"{np.degrees((R_true.inv() * R_est).magnitude()):.3f}")
PY
    ) || row="nan,nan,nan,nan"
    echo "$key$row,$code" >> "$csv"
    rm -f "$rec/recording.bag"
  done
done

/usr/bin/python3 - "$csv" "$scenario" "$realism" <<'PY'
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["scenario"] == sys.argv[2] and r["realism"] == sys.argv[3]]
print(f"| {sys.argv[3]}, source set to ideal | offset error per seed (ms) | 1-sigma (ms) | error / sigma | RMS error (ms) |")
print("|---|---|---|---|---:|")
for source in dict.fromkeys(r["source"] for r in rows):
    sel = [r for r in rows if r["source"] == source]
    errors = [float(r["offset_error_ms"]) for r in sel]
    rms = (sum(e * e for e in errors) / len(errors)) ** 0.5
    print(f"| {source} | {', '.join(f'{e:+.2f}' for e in errors)} | "
          f"{', '.join(r['offset_sigma_ms'] for r in sel)} | {', '.join(r['ratio'] for r in sel)} | {rms:.2f} |")
PY
