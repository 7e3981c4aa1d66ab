#!/usr/bin/env bash
# Configures and builds stepbench into build/ (or $STEPBENCH_BUILD_DIR), in Release (or
# $STEPBENCH_BUILD_TYPE: Sanitize is the AddressSanitizer + UBSan build CI tests too).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${STEPBENCH_BUILD_DIR:-$root/build}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE="${STEPBENCH_BUILD_TYPE:-Release}" >/dev/null
cmake --build "$build" -j"$(nproc)"
