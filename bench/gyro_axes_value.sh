#!/usr/bin/env bash
# What the gyro's scale and axis errors (rig.gyro_axes, docs/calibration.md) cost, per simulated
# recording (bench/BENCHMARK.md, "Session 52"):
#   calibrate  `taiga calibrate` on the first 30 s with rig.yaml (the user's rig) and with rig.yaml
#              given rig_truth.yaml's gyro_axes: offset error and |error| / 1-sigma, rotation
#              error against rig_truth.yaml's T_body_lidar
#   run        `taiga run` with rig_truth.yaml and with rig_truth.yaml less its gyro_axes: APE of
#              the odometry and of the loop-closed trajectory (SE(3) alignment)
#
#   bench/gyro_axes_value.sh [WORK_DIR]   (default /tmp/gyro_axes_value; environment:
#       TAIGA=path/to/taiga, SCENARIO=handheld-loop, REALISM=harsh, DURATION=35, BEAMS=64,
#       SEEDS="1 2 3 4")
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
taiga=${TAIGA:-$here/../build/bin/taiga}
work=${1:-/tmp/gyro_axes_value}
scenario=${SCENARIO:-handheld-loop}
realism=${REALISM:-harsh}
duration=${DURATION:-35}
beams=${BEAMS:-64}
seeds=${SEEDS:-1 2 3 4}
mkdir -p "$work"

# Writes DIR/NAME.yaml: FROM.yaml with the rig.gyro_axes rows of AXES.yaml (or the identity).
with_axes() {
  /usr/bin/python3 - "$@" <<'PY'
import sys, yaml
rec, source, axes_from, name = sys.argv[1:5]
rows = yaml.safe_load(open(f"{rec}/{axes_from}.yaml"))["rig"]["gyro_axes"] if axes_from != "identity" \
    else {"x": [1, 0, 0], "y": [0, 1, 0], "z": [0, 0, 1]}
config = yaml.safe_load(open(f"{rec}/{source}.yaml"))
config["rig"]["gyro_axes"] = rows
yaml.safe_dump(config, open(f"{rec}/{name}.yaml", "w"))
PY
}

ape() { "$taiga" eval --est "$1" --ref "$2" | awk '/^APE translation \(m\)/ {printf "%.2f", 100 * $5}'; }

echo "| seed | calibrate, rig.yaml: offset ms (err/sigma), rotation deg | with true gyro_axes | run APE cm, true rig: odometry / loop-closed | true rig less gyro_axes |"
echo "|---|---|---|---|---|"
for seed in $seeds; do
  rec=$work/$scenario-$realism-$seed
  [[ -f $rec/groundtruth.tum ]] ||
    "$taiga" simulate --scenario "$scenario" --realism "$realism" --duration "$duration" \
      --seed "$seed" --beams "$beams" --out "$rec" > /dev/null
  with_axes "$rec" rig rig_truth rig_true_axes
  with_axes "$rec" rig_truth identity rig_truth_no_axes
  row="| $seed"
  for cfg in rig rig_true_axes; do
    cal=$rec/calibrate_$cfg
    [[ -f $cal/calibration.json ]] ||
      "$taiga" calibrate "$rec/recording.bag" --config "$rec/$cfg.yaml" --duration 30 \
        --out "$cal" --no-plots > "$cal.log" 2>&1 || true
    row+=" | $(/usr/bin/python3 - "$rec" "$cal" <<'PY'
import json, sys
import numpy as np, yaml
from scipy.spatial.transform import Rotation
rec, cal = sys.argv[1:3]
c = json.load(open(f"{cal}/calibration.json"))
truth = yaml.safe_load(open(f"{rec}/rig_truth.yaml"))["rig"]
drift_ppm = yaml.safe_load(open(f"{rec}/scenario.yaml"))["rig"].get("lidar_clock_drift_ppm", 0.0)
true_s = truth["lidar_time_offset_s"] - 1e-6 * drift_ppm * 30.0 / 2  # the stretch's middle
error_ms = 1e3 * (c["time_offset"]["estimated_s"] - true_s)
ratio = abs(error_ms) / (1e3 * c["time_offset"]["sigma_s"])
R_est = Rotation.from_quat(c["rotation"]["estimated_quaternion_xyzw"])
R_true = Rotation.from_quat(truth["T_body_lidar"]["quaternion_xyzw"])
print(f"{error_ms:+.2f} ({ratio:.1f}), {np.degrees((R_true.inv() * R_est).magnitude()):.2f}")
PY
)"
  done
  for cfg in rig_truth rig_truth_no_axes; do
    run=$rec/run_$cfg
    [[ -f $run/summary.json ]] ||
      "$taiga" run "$rec/recording.bag" --config "$rec/$cfg.yaml" --out "$run" > "$run.log" 2>&1 || true
    row+=" | $(ape "$run/trajectory_odometry.tum" "$rec/groundtruth.tum") / $(ape "$run/trajectory.tum" "$rec/groundtruth.tum")"
  done
  echo "$row |"
done
