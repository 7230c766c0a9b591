#!/usr/bin/env bash
# `taiga run` at 1 and 2 worker threads (--threads), and at 1 worker pinned to one core (taskset:
# the pipeline's own threads then share that core too), run alternately on the same recording:
# per-scan median, p95, p99, max and the real-time factor, medians over the runs (issue 26).
#
# Usage: bench/threads_speed.sh TAIGA RECORDING_DIR [RUNS] [OUT_DIR]
set -euo pipefail
if [[ $# -lt 2 ]]; then
  echo "usage: $0 TAIGA RECORDING_DIR [RUNS] [OUT_DIR]" >&2
  exit 2
fi
taiga="$1" recording="$2" runs="${3:-3}" out="${4:-$(mktemp -d)}"
mkdir -p "$out"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for run in $(seq 1 "$runs"); do
  for label in threads2 threads1 core1; do
    dir="$out/${label}_$run"
    rm -rf "$dir"
    case "$label" in
      threads2) command=("$taiga" run --threads 2) ;;
      threads1) command=("$taiga" run --threads 1) ;;
      core1) command=(taskset -c 0 "$taiga" run --threads 1) ;;
    esac
    "${command[@]}" "$recording/recording.bag" --config "$recording/rig.yaml" --out "$dir" \
      >/dev/null 2>&1 || [[ $? -eq 3 ]]  # 3: track lost, outputs written
  done
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$out" "$runs" <<'PY'
import json, statistics, sys
out, runs = sys.argv[1], int(sys.argv[2])
names = {"threads2": "2 workers", "threads1": "1 worker", "core1": "1 worker, 1 core (taskset)"}
for label, name in names.items():
    rows = []
    for run in range(1, runs + 1):
        s = json.load(open(f"{out}/{label}_{run}/summary.json"))
        t = s["time_per_scan_ms"]
        rows.append((t["p50"], t["p95"], t["p99"], t["max"], s["realtime_factor"]))
    p50, p95, p99, mx, rtf = (statistics.median(c) for c in zip(*rows))
    print(f"{name:28s} per scan median {p50:.1f} ms, p95 {p95:.1f}, p99 {p99:.1f}, max {mx:.1f}; "
          f"real-time factor {rtf:.2f}")
PY
