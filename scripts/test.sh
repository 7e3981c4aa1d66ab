#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to a full test run: installs what is
# missing, builds in Release (or $STEPBENCH_BUILD_TYPE) and runs every test (ctest:
# GoogleTest, the command-line checks, pytest, the interruption test).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
cd "${STEPBENCH_BUILD_DIR:-$root/build}"
ctest --output-on-failure -j"$(nproc)"
