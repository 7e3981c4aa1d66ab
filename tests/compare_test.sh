#!/usr/bin/env bash
# `stepbench compare` as CI meets it: exit 0 when nothing regressed, 1 on a regression
# (and on a flagged slowdown only with --gate-timing), 2 when the files cannot be
# compared, with one line on stderr; the JSON and Markdown forms. Study files come from
# small `stepbench sweep` runs, changed with h5py (Debian's python3-h5py).
set -u
bin=${1:?usage: compare_test.sh path/to/stepbench}
py=/usr/bin/python3
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

# expect_exit CODE args...: the exit status, and nothing on stderr unless asked.
expect_exit() {
  local want=$1; shift
  "$bin" compare "$@" >"$work/out" 2>"$work/err"
  local rc=$?
  [ "$rc" -eq "$want" ] || { bad "exit $rc (want $want) for: compare $* :: $(head -c 300 "$work/err")"; return 1; }
  ok
}
# expect_cannot "<what the line must contain>" args...: exit 2 and one line on stderr.
expect_cannot() {
  local msg=$1; shift
  expect_exit 2 "$@" || return
  local lines; lines=$(wc -l <"$work/err")
  [ "$lines" -eq 1 ] || { bad "$lines lines on stderr for: compare $* :: $(cat "$work/err")"; return; }
  grep -qF -- "$msg" "$work/err" || bad "message lacks '$msg' for: compare $* :: $(cat "$work/err")"
  [ ! -s "$work/out" ] || bad "stdout not empty for: compare $*"
}

# The sweep part alone: compare reads every part a study has, and these tests change its rows.
sweep() { "$bin" sweep --problem damped_spring --levels 4 --parts sweep --quiet "$@" 2>/dev/null; }
sweep --integrator rk4 --integrator euler --integrator velocity_verlet --out "$work/base.h5" || bad "sweep base"
sweep --integrator rk4 --integrator euler --integrator velocity_verlet --out "$work/same.h5" || bad "sweep same"
sweep --integrator rk4 --integrator euler --out "$work/fewer.h5" || bad "sweep fewer"

# h5py PATH CODE: runs CODE with `f` the file opened read-write.
h5edit() { $py -c "import h5py, numpy as np, sys
f = h5py.File(sys.argv[1], 'r+')
$2" "$1"; }

# Identical results: exit 0, the verdict, nothing on stderr.
expect_exit 0 "$work/base.h5" "$work/same.h5" && {
  grep -q "Result: no regression" "$work/out" || bad "no verdict in: $(cat "$work/out")"
  [ ! -s "$work/err" ] || bad "stderr not empty: $(cat "$work/err")"
}

# rk4's err_pos_max grown 100x in row 1: exit 1, the row named in every form.
cp "$work/base.h5" "$work/worse.h5"
h5edit "$work/worse.h5" "
d = f['problems/damped_spring/methods/rk4/runs']
r = d[()]; r['err_pos_max'][1] *= 100; d[...] = r" || bad "h5py edit"
dt=$($py -c "import h5py; print(h5py.File('$work/base.h5')['problems/damped_spring/methods/rk4/runs']['param'][1])")
expect_exit 1 "$work/base.h5" "$work/worse.h5" && {
  grep -E "damped_spring +rk4 +dt $dt s +err_pos_max" "$work/out" >/dev/null || bad "row not named (dt $dt): $(cat "$work/out")"
  grep -q "Result: REGRESSION" "$work/out" || bad "no REGRESSION verdict"
}
expect_exit 1 "$work/base.h5" "$work/worse.h5" --json && {
  $py - "$work/out" "$dt" <<'PY' || bad "compare --json content"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["result"] == "regression" and d["exit_status"] == 1, d["result"]
assert d["summary"]["regressions"] == 1 and d["summary"]["improvements"] == 0, d["summary"]
r = d["regressions"][0]
assert (r["problem"], r["method"], r["param_name"], r["what"]) == ("damped_spring", "rk4", "dt", "err_pos_max"), r
assert r["param"] == float(sys.argv[2]) and abs(r["ratio"] - 100) < 1e-9, r
for key in ("differences", "added", "removed", "improvements", "thresholds", "timing"):
    assert key in d, key
assert d["thresholds"]["error_floor_rel"] == 1e-12 and d["timing"]["compared"] is False
PY
  [ "$(wc -l <"$work/err")" -eq 1 ] && grep -q "1 regression" "$work/err" || bad "--json: verdict on stderr: $(cat "$work/err")"
}
expect_exit 1 "$work/base.h5" "$work/worse.h5" --format md && {
  grep -q "^## stepbench compare: REGRESSION" "$work/out" || bad "markdown heading"
  grep -qF "| damped_spring | rk4 | dt $dt s | err_pos_max |" "$work/out" || bad "markdown row: $(cat "$work/out")"
}
expect_exit 0 "$work/base.h5" "$work/worse.h5" --error-factor 1000

# A method only in BASE: listed as removed, not a regression (only what both hold is
# compared), unless --require-base; only in NEW: added.
expect_exit 0 "$work/base.h5" "$work/fewer.h5" && { grep -q "velocity_verlet" "$work/out" || bad "removed method not named"; }
expect_exit 0 "$work/base.h5" "$work/fewer.h5" --allow-removed
expect_exit 1 "$work/base.h5" "$work/fewer.h5" --require-base && { grep -q "velocity_verlet" "$work/out" || bad "removed method not named"; }
# ... and the result line and the Regressions section count it in the same words.
grep -qF "Result: REGRESSION (exit 1): 1 regression, " "$work/out" || bad "require-base: the result line does not count the removal"
grep -qF "Regressions (1): the removed, below (--require-base)" "$work/out" || bad "require-base: the section says no regressions"
! grep -q "Regressions: none" "$work/out" || bad "require-base: 'Regressions: none' under a REGRESSION result"
expect_exit 2 "$work/base.h5" "$work/fewer.h5" --require-base --allow-removed
expect_exit 0 "$work/fewer.h5" "$work/base.h5" && { grep -qE "Added, only in NEW \(1\)" "$work/out" || bad "added not listed"; }

# Timing: made-up timings (3 repetitions, +-2 %); rk4 twice as slow in NEW.
timed() { h5edit "$1" "
import numpy.lib.recfunctions as rf
f.attrs['timing'] = 1; f.attrs['benchmark_mode'] = 'full'
for m in f['problems/damped_spring/methods'].values():
    r = m['runs'][()]; n = len(r)
    t = np.full(n, 1000.0 * ($2 if m.name.endswith('/rk4') else 1.0))
    r = rf.append_fields(r, ['time_ns', 'time_ns_min', 'time_ns_max', 'repetitions', 'cut'],
                         [t, 0.98 * t, 1.02 * t, np.full(n, 3, 'i8'), np.zeros(n, 'i1')], usemask=False)
    del m['runs']; m['runs'] = r"; }
cp "$work/base.h5" "$work/tbase.h5" && timed "$work/tbase.h5" 1 || bad "timed base"
cp "$work/base.h5" "$work/tslow.h5" && timed "$work/tslow.h5" 2 || bad "timed slow"
cp "$work/base.h5" "$work/tnoise.h5" && timed "$work/tnoise.h5" 1.08 || bad "timed noise"
expect_exit 0 "$work/tbase.h5" "$work/tslow.h5" && { grep -q "slower" "$work/out" || bad "slowdown not flagged"; }
expect_exit 1 "$work/tbase.h5" "$work/tslow.h5" --gate-timing
expect_exit 0 "$work/tbase.h5" "$work/tnoise.h5" --gate-timing

# Files that cannot be compared: exit 2, one line naming the file.
head -c "$(($(stat -c %s "$work/base.h5") / 2))" "$work/base.h5" >"$work/cut.h5"
expect_cannot "cannot read study file '$work/cut.h5'" "$work/base.h5" "$work/cut.h5"
expect_cannot "cannot read study file '$work/nope.h5': no such file" "$work/nope.h5" "$work/base.h5"
echo "not a study" >"$work/text.h5"
expect_cannot "cannot read study file '$work/text.h5': not an HDF5 file" "$work/base.h5" "$work/text.h5"
$py -c "import h5py; h5py.File('$work/foreign.h5', 'w').attrs['x'] = 1"
expect_cannot "not a stepbench study" "$work/foreign.h5" "$work/base.h5"
cp "$work/base.h5" "$work/v5.h5" && h5edit "$work/v5.h5" "f.attrs['format_version'] = np.int64(5)"
expect_cannot "format_version 5" "$work/base.h5" "$work/v5.h5"
cp "$work/base.h5" "$work/v2.h5" && h5edit "$work/v2.h5" "f.attrs['format_version'] = np.int64(2)"
expect_cannot "format_version 2" "$work/v2.h5" "$work/base.h5"
expect_cannot "--error-factor must be a finite number, got 'abc'" "$work/base.h5" "$work/same.h5" --error-factor abc
expect_cannot "--error-factor must be a finite number >= 1" "$work/base.h5" "$work/same.h5" --error-factor 0.5
expect_cannot "--order-drop must be a finite number >= 0" "$work/base.h5" "$work/same.h5" --order-drop -1
expect_cannot "--json and --format md" "$work/base.h5" "$work/same.h5" --json --format md
expect_cannot "new is required" "$work/base.h5"
expect_cannot "--format" "$work/base.h5" "$work/same.h5" --format xml

# --help states the thresholds and the exit codes.
"$bin" compare --help >"$work/help" 2>&1
grep -q "1e-12 x pos_scale" "$work/help" && grep -q "2 could not" "$work/help" && ok || bad "--help: $(cat "$work/help")"

finish compare_test
