#!/usr/bin/env bash
# Checks that every C++ file of the project is formatted with the committed .clang-format
# (clang-format 14, Debian's); prints the files that are not and exits 1. `--fix` formats
# them in place.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
mapfile -t files < <(git ls-files '*.cpp' '*.hpp')
if [ "${1:-}" = "--fix" ]; then
  clang-format -i "${files[@]}"
  exit 0
fi
# One clang-format process for every file (one a file took 29 s of CI, docs/ci.md); the
# files it names in its warnings ("path:line:col: warning: ...") are the unformatted ones,
# and a failure that names none (no clang-format, a broken .clang-format) is printed whole.
rc=0
log=$(clang-format --dry-run --Werror "${files[@]}" 2>&1 >/dev/null) || rc=$?
mapfile -t bad < <(sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: \(warning\|error\):.*/\1/p' <<<"$log" | sort -u)
if [ "$rc" -ne 0 ] && [ ${#bad[@]} -eq 0 ]; then
  echo "clang-format failed (exit $rc): $log" >&2
  exit 1
fi
if [ ${#bad[@]} -gt 0 ]; then
  echo "not formatted with .clang-format (run scripts/check-format.sh --fix): ${bad[*]}" >&2
  exit 1
fi
echo "format: ${#files[@]} files formatted with .clang-format"
