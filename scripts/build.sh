#!/usr/bin/env bash
# Configures and builds stepbench into build/ (or $STEPBENCH_BUILD_DIR), in Release (or
# $STEPBENCH_BUILD_TYPE: Sanitize is the AddressSanitizer + UBSan build CI tests too).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${STEPBENCH_BUILD_DIR:-$root/build}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE="${STEPBENCH_BUILD_TYPE:-Release}" >/dev/null
# The compiler's output goes to a log, not the terminal, which shows one line per tenth
# of the build (a clean build takes about 12 minutes on 2 cores); on failure, the
# log's end.
echo "building stepbench in $build (log: $build/build.log)" >&2
progress() {
  local last=-10 line p
  while IFS= read -r line; do
    if [[ $line =~ ^\[\ *([0-9]+)%\] ]]; then
      p=${BASH_REMATCH[1]}
      if ((p >= last + 10)); then
        echo "building: $p %" >&2
        last=$p
      fi
    fi
  done
}
if ! cmake --build "$build" -j"$(nproc)" 2>&1 | tee "$build/build.log" | progress; then
  tail -n 60 "$build/build.log" >&2
  echo "build failed: the whole log is $build/build.log" >&2
  exit 1
fi
