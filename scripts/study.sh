#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to results/study.h5: installs what is
# missing, builds in Release, runs the full study: the accuracy sweep (every problem x
# every integrator over the timestep ladder, references included) and the Google
# Benchmark timing of every case and peer, each timing written next to its accuracy row.
# Extra arguments go to stepbench_bench (e.g. --quick, --benchmark_filter=pendulum).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
cd "$root"
"${STEPBENCH_BUILD_DIR:-$root/build}/stepbench_bench" --study_out=results/study.h5 "$@"
