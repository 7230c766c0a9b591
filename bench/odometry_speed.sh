#!/usr/bin/env bash
# Odometry speed of two taiga binaries on the same recording, run alternately so that both see
# the same machine load: the real-time factor (recording duration / wall time, summary.json) and
# the per-scan processing time, per run, then the medians and the ratio NEW / REFERENCE.
#
# Usage: bench/odometry_speed.sh REFERENCE_TAIGA NEW_TAIGA RECORDING_DIR [RUNS] [OUT_DIR]
#   RECORDING_DIR holds recording.bag and rig.yaml (taiga simulate's output).
# Example (the full OS0-128 demo recording):
#   build/bin/taiga simulate --scenario mixed --duration 60 --seed 1 --out /tmp/demo
#   bench/odometry_speed.sh /tmp/base/bin/taiga build/bin/taiga /tmp/demo 3
set -euo pipefail
if [[ $# -lt 3 ]]; then
  echo "usage: $0 REFERENCE_TAIGA NEW_TAIGA RECORDING_DIR [RUNS] [OUT_DIR]" >&2
  exit 2
fi
reference="$1" new="$2" recording="$3" runs="${4:-3}" out="${5:-$(mktemp -d)}"
mkdir -p "$out"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for run in $(seq 1 "$runs"); do
  for label in reference new; do
    binary="$reference"; [[ "$label" == new ]] && binary="$new"
    dir="$out/${label}_$run"
    rm -rf "$dir"
    "$binary" run "$recording/recording.bag" --config "$recording/rig.yaml" --out "$dir" >/dev/null 2>&1
  done
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$out" "$runs" <<'PY'
import json, statistics, sys
out, runs = sys.argv[1], int(sys.argv[2])
rows = {}
for label in ("reference", "new"):
    rows[label] = []
    for run in range(1, runs + 1):
        s = json.load(open(f"{out}/{label}_{run}/summary.json"))
        t = s["time_per_scan_ms"]
        rows[label].append((s["realtime_factor"], t["p50"], t["p95"], t["mean"], s["wall_time_s"],
                            t["p99"], t["max"]))
        print(f"{label:9s} run {run}: real-time factor {s['realtime_factor']:.2f}, per scan "
              f"median {t['p50']:.1f} ms, p95 {t['p95']:.1f} ms, p99 {t['p99']:.1f} ms, "
              f"max {t['max']:.1f} ms, mean {t['mean']:.1f} ms, wall {s['wall_time_s']:.1f} s")
med = {label: [statistics.median(column) for column in zip(*rows[label])] for label in rows}
for label in rows:
    rtf, p50, p95, mean, wall, p99, worst = med[label]
    print(f"{label:9s} median: real-time factor {rtf:.2f}, per scan median {p50:.1f} ms, "
          f"p95 {p95:.1f} ms, p99 {p99:.1f} ms, max {worst:.1f} ms, mean {mean:.1f} ms")
print(f"ratio new/reference: real-time factor {med['new'][0] / med['reference'][0]:.2f}x, "
      f"per-scan median time {med['new'][1] / med['reference'][1]:.2f}, "
      f"wall time {med['new'][4] / med['reference'][4]:.2f}")
PY
