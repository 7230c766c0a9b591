#!/usr/bin/env bash
# The lidar factor's heading sigma and the gyro noise density the run uses, side by side
# (docs/odometry.md, "The lidar factor's covariance"; BENCHMARK.md "Session 55"): simulate each
# case, run it with rig.yaml (the rig a user writes: calibration.at_start on) in four variants,
# and print loop-closed and odometry ATE and the keyframes' heading wander.
#   bench/heading_sigma.sh [OUT_DIR]   (TAIGA=path/to/taiga, CASES="scenario:realism:seed ...",
#                                       VARIANTS="name:heading_sigma_rad:apply_gyro_noise ...")
# Default variants: old = heading 0.003 rad, the gyro density as configured (before session 55);
# new = 0.001 rad and the measured density (calibration.apply_gyro_noise).
set -euo pipefail
taiga=${TAIGA:-build/bin/taiga}
out=${1:-/tmp/taiga_heading_sigma}
here=$(cd "$(dirname "$0")" && pwd)
cases=${CASES:-"handheld-loop:typical:12 handheld-loop:typical:13 handheld-loop:typical:14 handheld-loop:typical:15 handheld-loop:ideal:12 handheld-loop:harsh:12 harvester:typical:5"}
mkdir -p "$out"
echo "| scenario | realism | seed | variant | ATE cm | odometry ATE cm | heading wander std deg |"
echo "|---|---|---|---|---|---|---|"
ate() {
  "$taiga" eval --est "$1" --ref "$2" --json |
    python3 -c "import json,sys; print('%.2f' % (100*json.load(sys.stdin)['ape']['translation_m']['rmse']))"
}
for c in $cases; do
  IFS=: read -r scenario realism seed <<<"$c"
  rec="$out/${scenario}_${realism}_${seed}"
  [ -f "$rec/recording.bag" ] || "$taiga" simulate --scenario "$scenario" --realism "$realism" \
    --duration 60 --seed "$seed" --beams 64 --out "$rec" >/dev/null 2>&1
  for variant in ${VARIANTS:-old:0.003:false new:0.001:true}; do
    IFS=: read -r name sigma apply <<<"$variant"
    /usr/bin/python3 - "$rec/rig.yaml" "$rec/$name.yaml" "$sigma" "$apply" <<'PY'
import sys, yaml
config = yaml.safe_load(open(sys.argv[1]))
config["odometry"]["lidar_heading_sigma_rad"] = float(sys.argv[3])
config["calibration"]["apply_gyro_noise"] = sys.argv[4] == "true"
yaml.safe_dump(config, open(sys.argv[2], "w"))
PY
    run="$rec/run_$name"
    [ -f "$run/trajectory.tum" ] || "$taiga" run "$rec/recording.bag" --config "$rec/$name.yaml" \
      --out "$run" >"$run.log" 2>&1
    wander=$("$here/keyframe_heading_error.py" "$rec" "$run" | sed 's/.*std \([0-9.]*\).*/\1/')
    echo "| $scenario | $realism | $seed | $name | $(ate "$run/trajectory.tum" "$rec/groundtruth.tum") |" \
      "$(ate "$run/trajectory_odometry.tum" "$rec/groundtruth.tum") | $wander |"
  done
done
