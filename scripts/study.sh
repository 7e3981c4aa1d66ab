#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to results/study.h5: installs what is
# missing, builds in Release, runs the full study: the accuracy sweep (every problem x
# every integrator over the timestep ladder, references included) and the Google
# Benchmark timing of every case and peer, each timing written next to its accuracy row.
# The run shows one progress line on stderr and ends with the verdict on stdout; Google
# Benchmark's own results go to results/bench.json (its JSON format: compare.py reads it);
# the README's answer table as data to results/summary.json (`stepbench summary`).
# Extra arguments go to stepbench_bench (e.g. --quick, --problem=pendulum, --verbose for
# Google Benchmark's table on the terminal too; stepbench_bench --help lists them).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
cd "$root"
build=${STEPBENCH_BUILD_DIR:-$root/build}
"$build/stepbench_bench" --study_out=results/study.h5 "$@"
# The README's answer as data (cli/summary.cpp): committed, so the README's block is checked
# against it (tests/python/test_readme.py); `scripts/report --readme README.md` renders it.
"$build/stepbench" summary --study results/study.h5 --out results/summary.json
