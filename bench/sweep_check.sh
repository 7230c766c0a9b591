#!/usr/bin/env bash
# recording.deskewed: auto (docs/recordings.md, "Per-point times, and clouds deskewed upstream"):
# simulated recordings without per-point times, deskewed upstream (`point_layout: deskewed`) or
# raw sweeps (`untimed`), run with the rig.yaml a user would write and recording.deskewed set to
# auto (the sweep check decides), false (times made up from the azimuth: the behaviour before
# the check) and true (every point at the stamp). One binary, so the three differ only in how the
# points' times are taken.
#
#   bench/sweep_check.sh [WORK_DIR]   (default /tmp/sweep_check; environment: TAIGA=path/to/taiga,
#       SCENARIOS="mixed harvester", REALISM="typical harsh", SEEDS="41 42", LAYOUTS="deskewed
#       untimed", MODES="auto false true", BEAMS=64, DURATION=60)
#
# One row per run is appended to WORK_DIR/sweep_check.csv; rows already in it are skipped.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
taiga=${TAIGA:-$here/../build/bin/taiga}
work=${1:-/tmp/sweep_check}
mkdir -p "$work"
csv=$work/sweep_check.csv
[[ -f $csv ]] || echo "scenario,layout,realism,seed,mode,exit_code,verdict,seam_ratio,scans_used,ate_m,ate_odometry_m,health" > "$csv"

ate() {  # est ref -> loop-closed or odometry ATE RMSE, m (nan when it cannot be scored)
  "$taiga" eval --json --est "$1" --ref "$2" 2>/dev/null |
    python3 -c 'import json,sys
try: print(json.load(sys.stdin)["ape"]["translation_m"]["rmse"])
except Exception: print("nan")'
}

for scenario in ${SCENARIOS:-mixed harvester}; do
  for layout in ${LAYOUTS:-deskewed untimed}; do
    for realism in ${REALISM:-typical harsh}; do
      for seed in ${SEEDS:-41 42}; do
        sim=$work/sim_${scenario}_${layout}_${realism}_$seed
        if [[ ! -f $sim/recording.bag ]]; then
          printf 'output: {point_layout: %s}\n' "$layout" > "$work/$layout.yaml"
          "$taiga" simulate --scenario "$scenario" --realism "$realism" --seed "$seed" \
            --duration "${DURATION:-60}" --beams "${BEAMS:-64}" --overrides "$work/$layout.yaml" \
            --out "$sim" > "$sim.log" 2>&1
        fi
        for mode in ${MODES:-auto false true}; do
          key="$scenario,$layout,$realism,$seed,$mode"
          if cut -d, -f1-5 "$csv" | grep -qxF "$key"; then continue; fi
          run=$work/run_${scenario}_${layout}_${realism}_${seed}_$mode
          rm -rf "$run"
          sed "s/^  deskewed: .*/  deskewed: $mode/" "$sim/rig.yaml" > "$sim/rig_$mode.yaml"
          code=0
          "$taiga" run "$sim/recording.bag" --config "$sim/rig_$mode.yaml" --out "$run" \
            > "$run.log" 2>&1 || code=$?
          read -r verdict ratio used health < <(python3 -c '
import json, sys
try:
    s = json.load(open(sys.argv[1]))
    c = s.get("sweep_check") or {}
    print(c.get("verdict", "-"), c.get("seam_ratio", "nan"), c.get("scans_used", 0),
          s["health"]["verdict"])
except Exception:
    print("- nan 0 failed")' "$run/summary.json")
          echo "$key,$code,$verdict,$ratio,$used,$(ate "$run/trajectory.tum" "$sim/groundtruth.tum"),$(ate "$run/trajectory_odometry.tum" "$sim/groundtruth.tum"),$health" >> "$csv"
          tail -1 "$csv"
        done
      done
    done
  done
done
