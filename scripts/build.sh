#!/usr/bin/env bash
# Configures (once) and builds taiga into build/. Extra arguments go to the first cmake configure,
# e.g. scripts/build.sh -DTAIGA_BUILD_BENCHMARKS=ON. The build type defaults to RelWithDebInfo.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -G Ninja "$@"
elif [ $# -gt 0 ]; then
  cmake -S . -B build "$@"
fi
cmake --build build --parallel "$(nproc)"
