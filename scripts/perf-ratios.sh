#!/usr/bin/env bash
# Prints the performance ratios of the README (our rk4 against the hand-written
# baseline, GSL's rk4 and Boost.Odeint's runge_kutta4 on damped_spring; the cheapest
# method to 1e-6 on pendulum), each measured in this one run. Builds first if needed.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${STEPBENCH_BUILD_DIR:-$root/build}
[ -x "$build/stepbench_bench" ] || "$root/scripts/build.sh" >/dev/null
"$build/stepbench_bench" --benchmark_filter='^(damped_spring/(rk4|baseline_rk4|gsl_rk4|odeint_rk4)/|pendulum/)' \
  --benchmark_min_time=0.03 --benchmark_repetitions=3 "$@" 2>/dev/null | sed -n '/^Performance ratios/,$p'
