#!/usr/bin/env bash
# Sets everything up on a fresh Debian 12 machine, builds, and runs every test (unit and scenario).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
scripts/build.sh
ctest --test-dir build --output-on-failure --parallel "$(nproc)"
