#!/usr/bin/env bash
# The web viewer on maps of growing size (issue 24: "smooth on a 100 million point map"): a run's
# map.las laid out in copies side by side (bench/tile_cloud) to about 2.6, 25 and 100 million
# points; for each, `taiga view`'s load time and peak memory, and in headless Chromium
# (tools/viewer-check --orbit: the view dragged around for 5 s) the points shown, the nodes and
# bytes fetched, and the frames drawn per second. Chromium draws with SwiftShader (software
# WebGL on the CPU, sharing the 2 cores with taiga), so its frame rate is a floor, not what a GPU
# gives; what matters is that it does not fall as the map grows.
#
# Usage: bench/viewer.sh RUN_DIR [OUT_DIR]   (environment: TAIGA, TILE_CLOUD, SIZES)
# Example: bench/viewer.sh /tmp/vrun /tmp/viewer_bench   (RUN_DIR: any `taiga run` output)
set -euo pipefail
taiga="${TAIGA:-build/bin/taiga}"
tile="${TILE_CLOUD:-build/bin/tile_cloud}"
run="$1"
out="${2:-$(mktemp -d)}"
sizes="${SIZES:-0 25e6 100e6}"  # 0: the run's own map
port=18480
mkdir -p "$out"
printf "| map points | nodes | load s | peak MB | points shown | nodes fetched | MB fetched | frames/s while dragged |\n|---|---|---|---|---|---|---|---|\n"
for size in $sizes; do
  map="$run/map.las"
  if [[ "$size" != 0 ]]; then
    map="$out/map_$size.las"
    [[ -f "$map" ]] || "$tile" "$run/map.las" "$size" "$map" >/dev/null
  fi
  log="$out/view_$size.log"
  /usr/bin/time -v "$taiga" view "$map" --bind "127.0.0.1:$port" >"$log" 2>&1 &
  for _ in $(seq 1 300); do grep -q serving "$log" && break; sleep 1; done
  report=$(node tools/viewer-check/viewer-check.mjs "http://127.0.0.1:$port/" "$out/view_$size.png" 120 --orbit)
  pkill -INT -f "taiga view $map --bind" || true
  wait
  python3 - "$log" "$report" <<'PY'
import json, re, sys
log = open(sys.argv[1]).read()
r = json.loads(sys.argv[2])
points, nodes, load = re.search(r"view +(\d+) points in (\d+) level-of-detail nodes, read and indexed in ([\d.]+) s", log).groups()
peak_mb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", log).group(1)) / 1024
o = r["orbit"]
assert not r["consoleErrors"] and not r["pageErrors"], r
print(f"| {int(points):,} | {nodes} | {load} | {peak_mb:.0f} | {o['maxPointsShown']:,} | "
      f"{o['fetched']['nodes']} | {o['fetched']['bytes'] / 1e6:.1f} | {o['fps']:.1f} |")
PY
done
