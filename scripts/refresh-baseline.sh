#!/usr/bin/env bash
# Rewrites results/baseline.h5, the accuracy baseline CI gates on (`stepbench compare`),
# from the quick study of the present build. Run it deliberately, when a change is meant
# to change the accuracy tables (a new method, a corrected step), after reading what
# `stepbench compare results/baseline.h5 <new quick study>` reports, and commit the new
# file with the reason in the commit message.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${STEPBENCH_BUILD_DIR:-$root/build}
[ -x "$build/stepbench_bench" ] || "$root/scripts/build.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# A method that fails on a case is recorded in the file with its reason (exit 0).
status=0
"$build/stepbench_bench" --quick --study_out="$tmp/quick.h5" >/dev/null || status=$?
[ "$status" -eq 0 ] || exit "$status"
if [ -f "$root/results/baseline.h5" ]; then
  "$build/stepbench" compare "$root/results/baseline.h5" "$tmp/quick.h5" || true
fi
# Only what the gate reads (stepbench compare: the root attributes, /problems, the
# stability limits) is kept: the figures' data (stability regions, loop, energy, scans)
# would more than double the committed file. h5py's copy keeps every type as written.
/usr/bin/python3 - "$tmp/quick.h5" "$tmp/baseline.h5" <<'PY'
import sys
import h5py
with h5py.File(sys.argv[1], "r") as src, h5py.File(sys.argv[2], "w") as dst:
    for k, v in src.attrs.items():
        dst.attrs.create(k, v, dtype=src.attrs.get_id(k).dtype)
    src.copy(src["problems"], dst, "problems")
    if "stability" in src:
        stab = dst.create_group("stability")
        for k, v in src["stability"].attrs.items():
            stab.attrs.create(k, v, dtype=src["stability"].attrs.get_id(k).dtype)
        src.copy(src["stability/limits"], stab, "limits")
PY
"$build/stepbench" compare "$tmp/baseline.h5" "$tmp/quick.h5" --require-base >/dev/null
mv "$tmp/baseline.h5" "$root/results/baseline.h5"
echo "wrote results/baseline.h5; commit it with the reason"
