#!/usr/bin/env bash
# Prints the performance ratios of the README from one timed run: a timed study of the
# problems the ratios read (damped_spring and pendulum: every method on them, so the
# equal-error table ranks them all; the accuracy sweep still covers everything, a few
# seconds), then `stepbench ratios` on it: the rk4 and rk8 step costs against the
# hand-written baselines and the library steps, ns per right-hand-side call of the
# library solvers, and the time to err_pos_max = 1e-6 .. 1e-12 for the cheapest of ours
# and the cheapest peer. Extra arguments go to stepbench_bench (e.g. --quick). Builds
# first if needed. STUDY_OUT=FILE keeps the study file.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${STEPBENCH_BUILD_DIR:-$root/build}
[ -x "$build/stepbench_bench" ] && [ -x "$build/stepbench" ] || "$root/scripts/build.sh" >/dev/null
study=${STUDY_OUT:-$(mktemp --suffix=.h5)}
# Google Benchmark's own results go beside the study (bench.json's place); kept with it.
[ -n "${STUDY_OUT:-}" ] || trap 'rm -f "$study" "$study.json"' EXIT
# A method's failure on a case is recorded in the file with its reason (exit 0); only a
# missing file stops here.
"$build/stepbench_bench" --problem=damped_spring --problem=pendulum --problem=kepler \
  --benchmark_filter='^(damped_spring|pendulum|kepler)/' --study_out="$study" --benchmark_out="$study.json" "$@" \
  >/dev/null 2>"$study.log" || status=$?
if [ ! -s "$study" ]; then
  cat "$study.log" >&2
  rm -f "$study.log"
  exit "${status:-1}"
fi
tail -n 1 "$study.log" >&2
rm -f "$study.log"
"$build/stepbench" ratios --study "$study"
