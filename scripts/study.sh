#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to results/study.h5: installs what is
# missing, builds in Release, runs the default study (every problem x every integrator
# over the timestep ladder, references included). Extra arguments go to `stepbench sweep`.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
cd "$root"
"${STEPBENCH_BUILD_DIR:-$root/build}/stepbench" sweep --out results/study.h5 "$@"
