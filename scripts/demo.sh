#!/usr/bin/env bash
# Sets everything up on a fresh Debian 12 machine, builds, and runs the main job on the built-in
# default: simulate a one-minute walk through a mixed forest, run the lidar-inertial odometry on
# it, and evaluate the trajectory against the simulator's ground truth (numbers and plots).
# Outputs go to out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
scripts/build.sh

taiga=build/bin/taiga
out=out/demo
mkdir -p "$out"

"$taiga" --version
"$taiga" simulate --scenario mixed --duration 60 --seed 1 --out "$out/recording"
"$taiga" run "$out/recording/recording.bag" --config "$out/recording/rig.yaml" --out "$out/run"
"$taiga" eval --est "$out/run/trajectory.tum" --ref "$out/recording/groundtruth.tum" \
  --timing "$out/run/timing.csv" --plots "$out/plots"
echo
echo "demo: trajectory, map (map.las: open it in CloudCompare), timings and summary in $out/run/,"
echo "      plots in $out/plots/"
