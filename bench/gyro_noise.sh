#!/usr/bin/env bash
# The gyro's noise density measured by `taiga calibrate` against the lidar (docs/calibration.md,
# "IMU noise"), against the simulator's truth: handheld walks per realism and seed, rig.yaml as
# a user would write it (the datasheet's 2.5e-4 rad/s/sqrt(Hz)), rig_truth.yaml the true density.
#
#   bench/gyro_noise.sh [WORK_DIR]   (default /tmp/gyro_noise; environment: TAIGA=path/to/taiga,
#       SCENARIO=handheld-loop, DURATION=40, BEAMS=64, SEEDS="1 2 3",
#       REALISMS="ideal typical harsh", OVERRIDES=file.yaml (one error source alone, say))
#
# Resumes: a recording or calibration already in WORK_DIR is kept. Prints a Markdown table and
# writes WORK_DIR/gyro_noise.csv.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
taiga=${TAIGA:-$here/../build/bin/taiga}
work=${1:-/tmp/gyro_noise}
scenario=${SCENARIO:-handheld-loop}
duration=${DURATION:-40}
beams=${BEAMS:-64}
seeds=${SEEDS:-1 2 3}
realisms=${REALISMS:-ideal typical harsh}
overrides=()
[[ -n ${OVERRIDES:-} ]] && overrides=(--overrides "$OVERRIDES")
mkdir -p "$work"
csv=$work/gyro_noise.csv
echo "realism,seed,true_density,configured_density,measured_density,sigma,verdict" > "$csv"
for realism in $realisms; do
  for seed in $seeds; do
    rec=$work/$realism-$seed
    [[ -f $rec/groundtruth.tum ]] || "$taiga" simulate --scenario "$scenario" --realism "$realism" \
      --duration "$duration" --seed "$seed" --beams "$beams" "${overrides[@]}" --out "$rec" > /dev/null
    [[ -f $rec/cal/calibration.json ]] || "$taiga" calibrate "$rec/recording.bag" \
      --config "$rec/rig.yaml" --out "$rec/cal" --no-plots > "$rec/cal.log" 2>&1 || true
    /usr/bin/python3 - "$rec" "$realism" "$seed" >> "$csv" <<'PY'
import json, re, sys
rec, realism, seed = sys.argv[1:4]
truth = re.search(r"gyro_noise_density: ([0-9.e+-]+)", open(rec + "/rig_truth.yaml").read()).group(1)
try:
    g = json.load(open(rec + "/cal/calibration.json"))["gyro_noise"]
    print(f"{realism},{seed},{float(truth):g},{g['configured_radps_sqrthz']:g},"
          f"{g.get('measured_radps_sqrthz', float('nan')):.3g},"
          f"{g.get('sigma_radps_sqrthz', float('nan')):.2g},{g['verdict']}")
except (OSError, KeyError, ValueError):
    print(f"{realism},{seed},{float(truth):g},nan,nan,nan,failed")
PY
  done
done
/usr/bin/python3 - "$csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("| realism | seed | true density | configured | measured (1-sigma) | measured / true | verdict |")
print("|---|---|---|---|---|---|---|")
for r in rows:
    ratio = float(r["measured_density"]) / float(r["true_density"])
    print(f"| {r['realism']} | {r['seed']} | {r['true_density']} | {r['configured_density']} | "
          f"{r['measured_density']} ({r['sigma']}) | {ratio:.2f} | {r['verdict']} |")
PY
