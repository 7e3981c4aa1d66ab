#!/usr/bin/env bash
# Configures and builds stepbench into build/ (or $STEPBENCH_BUILD_DIR), in Release (or
# $STEPBENCH_BUILD_TYPE: Sanitize is the AddressSanitizer + UBSan build CI tests too).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${STEPBENCH_BUILD_DIR:-$root/build}
# A new build tree uses Ninja where it is installed (scripts/install-deps.sh installs it):
# it compiles a test while the last problem unit still compiles, where make waits for the
# library first (a clean -j2 build: 7 min 3 s against 7 min 25 s, docs/ci.md). An existing
# tree keeps its generator; $CMAKE_GENERATOR, if set, wins.
if [ -z "${CMAKE_GENERATOR:-}" ] && command -v ninja >/dev/null; then
  export CMAKE_GENERATOR=Ninja
fi
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE="${STEPBENCH_BUILD_TYPE:-Release}" >/dev/null
# The compiler's output goes to a log, not the terminal, which shows one line per tenth
# of the build (a clean build takes about 7 minutes on 2 cores, docs/ci.md); on failure, the
# log's end.
echo "building stepbench in $build (log: $build/build.log)" >&2
progress() {
  local last=-10 line p
  while IFS= read -r line; do
    if [[ $line =~ ^\[\ *([0-9]+)%\] ]]; then  # make: "[ 42%] ..."
      p=${BASH_REMATCH[1]}
    elif [[ $line =~ ^\[([0-9]+)/([0-9]+)\] ]]; then  # ninja: "[36/87] ..."
      p=$((100 * BASH_REMATCH[1] / BASH_REMATCH[2]))
    else
      continue
    fi
    if ((p >= last + 10)); then
      echo "building: $p %" >&2
      last=$p
    fi
  done
}
if ! cmake --build "$build" -j"$(nproc)" 2>&1 | tee "$build/build.log" | progress; then
  tail -n 60 "$build/build.log" >&2
  echo "build failed: the whole log is $build/build.log" >&2
  exit 1
fi
