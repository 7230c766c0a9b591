#!/usr/bin/env bash
# taiga run --live on a simulated Ouster capture replayed over loopback (issue 24): at each pace,
# whether scans were dropped or packets lost, whether the trajectory equals the run on the
# capture file, the latency from a scan's assembly to its pose inside taiga (summary.json
# "realtime"), and end to end, from the packet's sending to the pose datagram's arrival
# (live.pose_udp, bench/pose_listener.py and bench/pose_latency.py).
#
# Usage: bench/live.sh [OUT_DIR]   (environment: TAIGA, SCENARIO, DURATION, BEAMS, SEED, RATES)
# Example (the issue's figure: a 60 s full OS0-128 capture at 1x, 2x and 5x):
#   bench/live.sh /tmp/live_bench
set -euo pipefail
taiga="${TAIGA:-build/bin/taiga}"
out="${1:-$(mktemp -d)}"
scenario="${SCENARIO:-mixed}" duration="${DURATION:-60}" beams="${BEAMS:-128}" seed="${SEED:-1}"
rates="${RATES:-1 2 5}"
offset=20000  # replay to 27502/27503, so a real sensor's 7502/7503 traffic does not mix in
mkdir -p "$out"
sim="$out/sim"
if [[ ! -f "$sim/capture.pcap" ]]; then
  "$taiga" simulate --scenario "$scenario" --duration "$duration" --beams "$beams" --seed "$seed" \
    --pcap --out "$sim" >/dev/null
fi
"$taiga" run "$sim/capture.pcap" --config "$sim/rig.yaml" --out "$out/file" >/dev/null 2>&1
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for rate in $rates; do
  config="$out/live_$rate.yaml"
  python3 - "$sim/rig.yaml" "$config" "$offset" <<'PY'
import sys, yaml
config = yaml.safe_load(open(sys.argv[1]))
offset = int(sys.argv[3])
config["live"].update(lidar_port=7502 + offset, imu_port=7503 + offset, idle_timeout_s=3,
                      pose_udp=f"127.0.0.1:{9870 + offset}")
yaml.safe_dump(config, open(sys.argv[2], "w"))
PY
  rm -rf "$out/live_$rate"
  python3 "$(dirname "$0")/pose_listener.py" $((9870 + offset)) "$out/poses_$rate.txt" 8 &
  listener=$!
  "$taiga" run --live --config "$config" --out "$out/live_$rate" >"$out/live_$rate.log" 2>&1 &
  live=$!
  sleep 1
  "$taiga" replay "$sim/capture.pcap" --rate "$rate" --port-offset "$offset" >"$out/replay_$rate.log"
  wait "$live" || true
  wait "$listener"
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$out" $rates <<'PY'
import json, sys, filecmp
out, rates = sys.argv[1], sys.argv[2:]
print("| pace | scans processed | dropped | lost packets (columns) | kernel drops | trajectory = file run | latency p50 / p99 / max ms |")
print("|---|---|---|---|---|---|---|")
file_scans = json.load(open(f"{out}/file/summary.json"))["scans_processed"]
for rate in rates:
    s = json.load(open(f"{out}/live_{rate}/summary.json"))
    r, l = s["realtime"], s["live"]
    same = filecmp.cmp(f"{out}/file/trajectory.tum", f"{out}/live_{rate}/trajectory.tum", shallow=False)
    lat = r["latency_ms"]
    print(f"| {rate}x | {s['scans_processed']} of {file_scans} | {r['dropped_scans']} | "
          f"{l['missing_columns']} | {l['kernel_drops']} | {'identical' if same else 'differs'} | "
          f"{lat['p50']:.1f} / {lat['p99']:.1f} / {lat['max']:.1f} |")
PY
for rate in $rates; do
  echo "pose stream at ${rate}x, end to end:"
  python3 "$(dirname "$0")/pose_latency.py" "$out/poses_$rate.txt" "$out/replay_$rate.log" "$rate"
done
