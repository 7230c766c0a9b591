#!/usr/bin/env bash
# Runs a command and samples its resident memory (VmRSS from /proc/PID/status) every INTERVAL
# seconds into a CSV "time_s,rss_mb,hwm_mb" (time since start; MB = 2^20 bytes; hwm_mb is VmHWM,
# the kernel's own peak RSS so far, which catches peaks between samples), so peak memory and
# whether memory stays flat over a long run can be measured and plotted (bench/plot_memory.py).
# Also records the load average once a minute in OUT.load, since the machine is shared.
#
# Usage: bench/memory_curve.sh [-i INTERVAL_S] OUT.csv -- COMMAND [ARGS...]
# Exit status: the command's. Prints peak RSS at the end.
set -euo pipefail

interval_s=2
while getopts "i:" opt; do
  case "$opt" in
    i) interval_s="$OPTARG" ;;
    *) echo "usage: $0 [-i INTERVAL_S] OUT.csv -- COMMAND [ARGS...]" >&2; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
if [[ $# -lt 3 || "$2" != "--" ]]; then
  echo "usage: $0 [-i INTERVAL_S] OUT.csv -- COMMAND [ARGS...]" >&2
  exit 2
fi
out_csv="$1"
shift 2

"$@" &
pid=$!
start_ns=$(date +%s%N)
echo "time_s,rss_mb,hwm_mb" > "$out_csv"
: > "$out_csv.load"
last_load_s=-60
peak_mb=0
while kill -0 "$pid" 2>/dev/null; do
  read -r rss_kb hwm_kb < <(awk '/^VmRSS:/ {r = $2} /^VmHWM:/ {h = $2} END {print r, h}' \
    "/proc/$pid/status" 2>/dev/null || true) || true
  now_s=$(awk -v a="$start_ns" -v b="$(date +%s%N)" 'BEGIN {printf "%.1f", (b - a) / 1e9}')
  if [[ -n "${rss_kb:-}" && -n "${hwm_kb:-}" && "$rss_kb" != 0 ]]; then
    row=$(awk -v r="$rss_kb" -v h="$hwm_kb" 'BEGIN {printf "%.1f,%.1f", r / 1024, h / 1024}')
    echo "$now_s,$row" >> "$out_csv"
    peak_mb=${row#*,}
  fi
  if awk -v n="$now_s" -v l="$last_load_s" 'BEGIN {exit !(n - l >= 60)}'; then
    echo "$now_s $(cut -d' ' -f1-3 /proc/loadavg)" >> "$out_csv.load"
    last_load_s=$now_s
  fi
  sleep "$interval_s"
done
status=0
wait "$pid" || status=$?
echo "memory_curve: peak RSS (VmHWM at the last sample) ${peak_mb} MB (every ${interval_s} s), exit status $status, samples in $out_csv" >&2
exit "$status"
