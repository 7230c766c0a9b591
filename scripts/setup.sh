#!/usr/bin/env bash
# Installs every Debian package taiga needs to build, test and benchmark, and the Node.js packages:
# three.js for the web viewer (web/, compiled into the binary), and for tests an independent LAS
# reader (tools/las-check), Foxglove's WebSocket protocol client (tools/foxglove-check) and
# playwright-core driving Debian's Chromium (tools/viewer-check).
# Idempotent and non-interactive: installs only what is missing, runs `apt-get update` first when it
# has to install anything. Uses sudo when not run as root.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git
  # a compiler cache: rebuilding a fresh clone (CI) recompiles only what changed
  ccache
  # fuzzing (scripts/fuzz.sh): clang with libFuzzer and the sanitizer runtimes
  clang libclang-rt-14-dev
  # math, configuration, command line, logging
  libeigen3-dev libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev nlohmann-json3-dev
  # recordings: Ouster captures, ROS1 bags
  libpcap-dev librosbag-storage-dev libsensor-msgs-dev libstd-msgs-dev liblzf-dev
  # live streams: the Foxglove WebSocket server
  libwebsocketpp-dev libasio-dev
  # the web viewer: its files are compiled in with xxd; tests load it in headless Chromium
  xxd chromium
  # estimation, parallel loops, nearest neighbours, geodesy, ray casting for the simulator
  libceres-dev libtbb-dev libnanoflann-dev robin-map-dev libproj-dev proj-data libembree-dev
  # reference implementations (PCL's NDT/GICP) for tests and benchmarks, plots
  libpcl-dev python3-matplotlib
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
)
# Node.js runs the independent LAS reader in tests; any Node.js >= 18 on the PATH will do.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  packages+=(nodejs npm)
fi

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

install_node_tools() {
  local dir
  for dir in web tools/las-check tools/foxglove-check tools/viewer-check; do
    if [ ! -d "$dir/node_modules" ] || [ "$dir/package-lock.json" -nt "$dir/node_modules" ]; then
      echo "setup: installing the Node.js packages of $dir"
      (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error)
      touch "$dir/node_modules"
    fi
  done
}

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} Debian packages are installed"
  install_node_tools
  exit 0
fi

as_root=()
if [ "$(id -u)" -ne 0 ]; then
  if ! command -v sudo >/dev/null; then
    echo "setup: need root (or sudo) to install: ${missing[*]}" >&2
    exit 1
  fi
  as_root=(sudo)
fi

echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
install_node_tools
