#!/usr/bin/env bash
# Issue 19's recording as users have it: scans kept at 2 Hz, deskewed upstream without a time
# field, no IMU, the handheld walk's fast turns (60-120 deg at up to 90 deg/s: up to about 45 deg
# between kept scans). `taiga run` with the rig.yaml a user would write plus only the documented
# switch `recording.deskewed: true`; APE against the truth and the health verdict.
#
#   bench/large_motion.sh [WORK_DIR]   (default /tmp/large_motion; environment:
#       TAIGA=path/to/taiga, DURATION=60, SEEDS="1 2 3", HEADS="os0-128 hdl-32e",
#       REALISM=ideal|typical|harsh: the lidar's and the scene's errors; the rig.yaml is the
#       user's either way)
#
# Prints one Markdown row per head and seed.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
taiga=${TAIGA:-$here/../build/bin/taiga}
work=${1:-/tmp/large_motion}
duration=${DURATION:-60}
realism=${REALISM:-ideal}
mkdir -p "$work"

echo "| head | seed | path (m) | largest turn between scans (deg) | APE RMSE (m) | APE max (m) | health | scans degraded / lost | exit |"
echo "|---|---:|---:|---:|---:|---:|---|---|---:|"
for head in ${HEADS:-os0-128 hdl-32e}; do
  case $head in
    os0-128) lidar="" ;;
    hdl-32e) lidar="lidar: {model: hdl-32e, columns: 2048}" ;;
    *) echo "unknown head $head" >&2; exit 2 ;;
  esac
  for seed in ${SEEDS:-1 2 3}; do
    sim=$work/sim_${realism}_${head}_$seed
    run=$work/run_${realism}_${head}_$seed
    overrides=$work/overrides_$head.yaml
    printf '%s\noutput: {point_layout: deskewed, scan_stride: 5, imu: false, gnss: false}\n' \
      "$lidar" > "$overrides"
    [[ -f $sim/groundtruth.tum ]] || "$taiga" simulate --scenario handheld-loop --realism "$realism" --seed "$seed" \
      --duration "$duration" --overrides "$overrides" --out "$sim" > "$sim.log" 2>&1
    sed 's/^  deskewed: .*/  deskewed: true/' "$sim/rig.yaml" > "$sim/rig_deskewed.yaml"
    code=0
    "$taiga" run "$sim/recording.bag" --config "$sim/rig_deskewed.yaml" --out "$run" \
      > "$run.log" 2>&1 || code=$?
    /usr/bin/python3 - "$taiga" "$run" "$sim" "$head" "$seed" "$code" <<'PY'
import json, math, subprocess, sys
taiga, run, sim, head, seed, code = sys.argv[1:]
ev = json.loads(subprocess.run([taiga, "eval", "--json", "--est", f"{run}/trajectory_odometry.tum",
                                "--ref", f"{sim}/groundtruth.tum"], capture_output=True, text=True).stdout)
s = json.load(open(f"{run}/summary.json"))
h = s["health"]
# The largest heading change between consecutive kept scans, from the odometry's own trajectory
# stamps looked up in the truth.
truth = [list(map(float, l.split())) for l in open(f"{sim}/groundtruth.tum") if l.strip() and l[0] != "#"]
est_t = [float(l.split()[0]) for l in open(f"{run}/trajectory_odometry.tum") if l.strip() and l[0] != "#"]
def yaw_at(t):
    import bisect
    i = min(bisect.bisect_left([r[0] for r in truth], t), len(truth) - 1)
    qx, qy, qz, qw = truth[i][4:8]
    return math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
yaws = [yaw_at(t) for t in est_t]
turn = max(abs(math.degrees(math.remainder(b - a, 2 * math.pi))) for a, b in zip(yaws, yaws[1:]))
a = ev["ape"]["translation_m"]
print(f"| {head} | {seed} | {ev['drift']['reference_path_length_m']:.0f} | {turn:.0f} | {a['rmse']:.3f} | {a['max']:.3f} | "
      f"{h['verdict']} | {h['scans_degraded']} / {h['scans_lost']} | {code} |")
PY
  done
done
