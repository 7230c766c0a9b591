#!/usr/bin/env bash
# Self-calibration (issue 20, docs/calibration.md): how close `taiga calibrate` gets to the true
# lidar-IMU time offset and extrinsic rotation, and what it is worth to `taiga run`.
# Per recording (simulated with realism errors, rig.yaml = the rig a user would write):
#   stated     rig.yaml with calibration.at_start: false  (the errors cost this)
#   truth      rig_truth.yaml                             (the floor)
#   at_start   rig.yaml as written (calibration.at_start: true, the default)
# and `taiga calibrate` on the first STRETCH s: its offset and rotation against rig_truth.yaml,
# their 1-sigma, and its wall time.
#
#   bench/self_calibration.sh [WORK_DIR]   (default /tmp/self_calibration; environment:
#       TAIGA=path/to/taiga, SCENARIO=handheld-loop, DURATION=60, BEAMS=64, SEEDS="1 2 3",
#       REALISMS="typical harsh", STRETCH=30)
#
# Writes WORK_DIR/results.csv (one row per recording and rig) and prints a Markdown table.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
taiga=${TAIGA:-$here/../build/bin/taiga}
work=${1:-/tmp/self_calibration}
scenario=${SCENARIO:-handheld-loop}
duration=${DURATION:-60}
beams=${BEAMS:-64}
seeds=${SEEDS:-1 2 3}
realisms=${REALISMS:-typical harsh}
stretch=${STRETCH:-30}
mkdir -p "$work"
csv=$work/results.csv
echo "scenario,realism,seed,rig,ate_cm,offset_error_ms,offset_sigma_ms,rotation_error_deg,rotation_sigma_deg,calibrate_s,exit" > "$csv"

ate_cm() {
  "$taiga" eval --json --est "$1/trajectory.tum" --ref "$2/groundtruth.tum" 2>/dev/null |
    python3 -c 'import json, sys; print(100 * json.load(sys.stdin)["ape"]["translation_m"]["rmse"])' || echo nan
}

for realism in $realisms; do
  for seed in $seeds; do
    rec=$work/$scenario-$realism-$seed
    [[ -f $rec/groundtruth.tum ]] || "$taiga" simulate --scenario "$scenario" --realism "$realism" \
      --duration "$duration" --seed "$seed" --beams "$beams" --out "$rec" > /dev/null
    # taiga calibrate against the truth (kept when done before: the script resumes).
    if [[ ! -f $rec/calibrate.seconds ]]; then
      start=$(date +%s.%N)
      code=0
      "$taiga" calibrate "$rec/recording.bag" --config "$rec/rig.yaml" --duration "$stretch" \
        --out "$rec/calibrate" --no-plots > "$rec/calibrate.log" 2>&1 || code=$?
      echo "$(python3 -c "print($(date +%s.%N) - $start)") $code" > "$rec/calibrate.seconds"
    fi
    read -r seconds code < "$rec/calibrate.seconds"
    errors=$(/usr/bin/python3 "$here/self_calibration_errors.py" "$rec/calibrate/calibration.json" "$rec/rig_truth.yaml" || echo "nan,nan,nan,nan")
    echo "$scenario,$realism,$seed,calibrate,,$errors,$seconds,$code" >> "$csv"
    # taiga run with each rig.
    sed 's/^  at_start: true/  at_start: false/' "$rec/rig.yaml" > "$rec/rig_stated.yaml"
    sed 's/^  at_start: false/  at_start: true/' "$rec/rig.yaml" > "$rec/rig_at_start.yaml"
    for rig in rig_stated rig_truth rig_at_start; do
      run=$rec/run-$rig
      if [[ ! -f $run/trajectory.tum ]]; then
        code=0
        "$taiga" run "$rec/recording.bag" --config "$rec/$rig.yaml" --out "$run" > "$run.log" 2>&1 || code=$?
        echo "$code" > "$run.exit"
      fi
      echo "$scenario,$realism,$seed,$rig,$(ate_cm "$run" "$rec"),,,,,,$(cat "$run.exit")" >> "$csv"
      rm -rf "$run/keyframes" "$run/map.las"
    done
  done
done

/usr/bin/python3 - "$csv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
def num(x):
    try: return float(x)
    except ValueError: return float("nan")
print("| realism | seed | ATE rig.yaml, not calibrated (cm) | ATE rig_truth (cm) | ATE at_start (cm) | at_start / truth | offset error (ms) | 1-sigma (ms) | rotation error (deg) | 1-sigma (deg) | calibrate (s) |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
keys = sorted({(r["realism"], r["seed"]) for r in rows})
for realism, seed in keys:
    sel = {r["rig"]: r for r in rows if r["realism"] == realism and r["seed"] == seed}
    c = sel["calibrate"]
    a, t, s = (num(sel[k]["ate_cm"]) for k in ("rig_stated", "rig_truth", "rig_at_start"))
    print(f"| {realism} | {seed} | {a:.1f} | {t:.1f} | {s:.1f} | {s / t:.2f} | {num(c['offset_error_ms']):+.2f} | "
          f"{num(c['offset_sigma_ms']):.2f} | {num(c['rotation_error_deg']):.3f} | {num(c['rotation_sigma_deg']):.3f} | {num(c['calibrate_s']):.0f} |")
PY
