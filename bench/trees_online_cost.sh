#!/usr/bin/env bash
# What the online tree map (mapping.trees) costs `taiga run`: two binaries, each with and without
# the tree map, run alternately on the same recording so that all four see the same machine load.
# Prints per run the real-time factor (summary.json) and the tree map's updates, worker time and
# final inventory time, then the medians and the cost (1 - with / without) per binary.
#
# Usage: bench/trees_online_cost.sh REFERENCE_TAIGA NEW_TAIGA RECORDING_DIR [RUNS] [OUT_DIR]
#   RECORDING_DIR holds recording.bag and rig.yaml (taiga simulate's output, which states
#   `trees: false` in its mapping section).
# Example (the handheld walk of BENCHMARK.md, "Session 45"):
#   build/bin/taiga simulate --scenario handheld-loop --duration 60 --seed 12 --beams 64 --out /tmp/hl12
#   bench/trees_online_cost.sh /tmp/base/build/bin/taiga build/bin/taiga /tmp/hl12 3
set -euo pipefail
if [[ $# -lt 3 ]]; then
  echo "usage: $0 REFERENCE_TAIGA NEW_TAIGA RECORDING_DIR [RUNS] [OUT_DIR]" >&2
  exit 2
fi
reference="$1" new="$2" recording="$3" runs="${4:-3}" out="${5:-$(mktemp -d)}"
mkdir -p "$out"
grep -q "^  trees: false" "$recording/rig.yaml" || {
  echo "$recording/rig.yaml: no 'trees: false' line in its mapping section" >&2
  exit 2
}
sed 's/^  trees: false/  trees: true/' "$recording/rig.yaml" >"$out/rig_trees.yaml"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for run in $(seq 1 "$runs"); do
  for label in reference new; do
    binary="$reference"; [[ "$label" == new ]] && binary="$new"
    for trees in off on; do
      config="$recording/rig.yaml"; [[ "$trees" == on ]] && config="$out/rig_trees.yaml"
      dir="$out/${label}_${trees}_$run"
      rm -rf "$dir"
      "$binary" run "$recording/recording.bag" --config "$config" --out "$dir" >/dev/null 2>&1
    done
  done
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$out" "$runs" <<'PY'
import json, statistics, sys
out, runs = sys.argv[1], int(sys.argv[2])
for label in ("reference", "new"):
    rtf = {"off": [], "on": []}
    for run in range(1, runs + 1):
        for trees in ("off", "on"):
            s = json.load(open(f"{out}/{label}_{trees}_{run}/summary.json"))
            rtf[trees].append(s["realtime_factor"])
            line = f"{label:9s} trees {trees:3s} run {run}: real-time factor {s['realtime_factor']:.2f}"
            t = s.get("trees_online")
            if t:
                line += (f", {t['stems']} stems, {t.get('updates', '-')} updates, worker "
                         f"{t['worker_s']:.1f} s, final inventory {t['final_s']:.1f} s")
            print(line)
    off, on = statistics.median(rtf["off"]), statistics.median(rtf["on"])
    print(f"{label:9s} median real-time factor: without {off:.2f}, with {on:.2f}, "
          f"cost {100 * (1 - on / off):.1f} %")
PY
