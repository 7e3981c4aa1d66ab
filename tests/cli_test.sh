#!/usr/bin/env bash
# The command line as a user meets it: the lecture's example through `run --json`, and
# every kind of bad input getting one line on stderr, exit 2 (1 for a file it cannot read or
# write), and an existing results file left as it was.
set -u
bin=${1:?usage: cli_test.sh path/to/stepbench}
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

# The lecture's example: 450 m with explicit Euler, exact 500 m.
out=$("$bin" run --problem constant_acceleration --integrator euler --dt 1 --json) || bad "run --json failed"
/usr/bin/python3 - "$out" <<'PY' && ok || bad "run --json content"
import json, sys
d = json.loads(sys.argv[1])
need = {"problem", "integrator", "dt", "horizon", "steps", "force_evals", "position", "velocity",
        "err_pos_final", "err_vel_final", "energy_drift", "diverged"}
assert need <= d.keys(), need - d.keys()
assert d["position"] == [450.0] and d["steps"] == 10 and d["force_evals"] == 10, d
assert d["err_pos_final"] == 50.0 and d["diverged"] is False, d
PY
"$bin" list --json | /usr/bin/python3 -c '
import json, sys
d = json.load(sys.stdin)
names = {p["name"] for p in d["problems"]}
assert names == {"constant_acceleration", "projectile", "damped_spring", "pendulum", "n_pendulum", "stiff_spring", "spring_chain",
                 "kepler", "falling_drag", "sliding_block", "sliding_block_stick", "bouncing_ball",
                 "bouncing_ball_locate", "bouncing_balls"}, names
orders = {m["name"]: m["declared_order"] for m in d["methods"] if m["origin"] == "ours" and m["kind"] == "fixed_step"}
assert orders == {"euler": 1, "semi_implicit_euler": 1, "midpoint": 2, "rk4": 4, "momentum": 1, "velocity_verlet": 2,
                  "forest_ruth": 4, "implicit_euler": 1, "implicit_midpoint": 2, "rk8": 8, "vern7_fixed": 7,
                  "vern9_fixed": 9, "xpbd": 1, "xpbd_iterations": 1}, orders
adaptive = {m["name"]: m["declared_order"] for m in d["methods"] if m["origin"] == "ours" and m["kind"] == "adaptive"}
assert adaptive == {"adaptive_euler": 1, "rk45": 5, "dop853": 8, "vern7": 7, "vern9": 9}, adaptive
origins = {m["name"]: m["origin"] for m in d["methods"]}
assert origins["baseline_rk4"] == "baseline" and origins["gsl_rk4"] == "peer" and origins["cvode_bdf"] == "peer", origins
caps = {m["name"]: m["capabilities"] for m in d["methods"]}
assert caps["velocity_verlet"]["symplectic"] and caps["velocity_verlet"]["reuses_last_force"], caps
assert not caps["rk4"]["symplectic"] and caps["cvode_bdf"]["error_estimate"], caps
assert caps["implicit_midpoint"]["symplectic"] and caps["implicit_midpoint"]["needs_jacobian"], caps
assert caps["rk45"]["dense_output"] and caps["rk45"]["reuses_last_force"], caps
# Where each runs: xpbd only on the scenes with a constraint view; rk4 everywhere.
on = {m["name"]: set(m["runs_on"]) for m in d["methods"]}
views = {"pendulum", "n_pendulum", "stiff_spring", "damped_spring", "spring_chain"}
assert on["xpbd"] == on["xpbd_iterations"] == views, on["xpbd"]
assert on["rk4"] == names, on["rk4"]
' && ok || bad "list --json"
"$bin" list | grep -q "^  xpbd, xpbd_iterations: only on damped_spring, pendulum, n_pendulum, stiff_spring, spring_chain$" && ok ||
  bad "list: where xpbd runs"

# n_pendulum's state is link angles; `run` prints what its errors are measured on, the
# bobs' positions in m: the first bob sits on its 0.3 m circle, each next one 0.3 m on.
"$bin" run --problem n_pendulum --integrator rk4 --dt 1e-3 --json | /usr/bin/python3 -c '
import json, math, sys
d = json.load(sys.stdin)
p, q = d["position"], d["true_position"]
assert len(p) == 6 and len(d["velocity"]) == 6 and len(q) == 6, d
bobs = [(0.0, 0.0)] + [(p[2 * i], p[2 * i + 1]) for i in range(3)]
for a, b in zip(bobs, bobs[1:]):
    assert abs(math.dist(a, b) - 0.3) < 1e-12, bobs
# The error is the worst bob's, not the 6-vector's norm (docs/measurement.md).
worst = max(math.dist(p[2 * i:2 * i + 2], q[2 * i:2 * i + 2]) for i in range(3))
assert abs(d["err_pos_final"] - worst) <= 1e-15 * worst, d
assert d["err_pos_final"] < math.dist(p, q), d
' && ok || bad "run --problem n_pendulum prints the bobs"
# xpbd on it: the bobs it draws (its particles, links a little stretched) and the worst one's error.
"$bin" run --problem n_pendulum --integrator xpbd --dt 1e-3 --json | /usr/bin/python3 -c '
import json, math, sys
d = json.load(sys.stdin)
p, q = d["position"], d["true_position"]
assert abs(math.hypot(p[0], p[1]) - 0.3) > 1e-9, p  # not put back on the link
worst = max(math.dist(p[2 * i:2 * i + 2], q[2 * i:2 * i + 2]) for i in range(3))
assert abs(d["err_pos_final"] - worst) <= 1e-15 * worst, d
' && ok || bad "run --problem n_pendulum --integrator xpbd prints the bobs it draws"

# A parameter override changes the answer as the closed form says: 20 N gives 1000 m.
"$bin" run --problem constant_acceleration --integrator rk4 --dt 0.5 --set force_n=20 --json |
  /usr/bin/python3 -c 'import json,sys; d=json.load(sys.stdin); assert abs(d["position"][0]-1000.0) < 1e-9, d' && ok || bad "--set"

# Bad input.
expect_error_re "unknown problem 'nope'" run --problem nope --integrator rk4 --dt 0.1
expect_error_re "unknown method 'rk5'" run --problem pendulum --integrator rk5 --dt 0.1
expect_error_re "--dt must be > 0" run --problem pendulum --integrator rk4 --dt 0
expect_error_re "--dt must be > 0" run --problem pendulum --integrator rk4 --dt -1
expect_error_re "--dt must be a finite number, got 'abc'" run --problem pendulum --integrator rk4 --dt abc
expect_error_re "--dt must be a finite number, got 'nan'" run --problem pendulum --integrator rk4 --dt nan
expect_error_re "--dt must be a finite number, got '0.1x'" run --problem pendulum --integrator rk4 --dt 0.1x
expect_error_re "--horizon must be > 0" run --problem pendulum --integrator rk4 --dt 0.1 --horizon 0
expect_error_re "--horizon must be a finite number" run --problem pendulum --integrator rk4 --dt 0.1 --horizon inf
expect_error_re "malformed --set 'theta0_deg'" run --problem pendulum --integrator rk4 --dt 0.1 --set theta0_deg
expect_error_re "malformed --set '=3'" run --problem pendulum --integrator rk4 --dt 0.1 --set =3
expect_error_re "--set pendulum.theta0_deg must be a finite number, got 'big'" run --problem pendulum --integrator rk4 --dt 0.1 --set theta0_deg=big
expect_error_re "unknown parameter 'k' for problem pendulum" run --problem pendulum --integrator rk4 --dt 0.1 --set k=1
expect_error_re "theta0_deg must be in (0, 180)" run --problem pendulum --integrator rk4 --dt 0.1 --set theta0_deg=200
expect_error_re "--problem is required" run --integrator rk4 --dt 0.1
expect_error_re "unknown problem 'nope'" sweep --problem nope --out "$work/s.h5"
expect_error_re "unknown method 'rk5'" sweep --integrator rk5 --out "$work/s.h5"
expect_file_error "cannot write results file '$work/missing/s.h5'" sweep --levels 3 --out "$work/missing/s.h5"
expect_file_error "it is a directory" sweep --levels 3 --out "$work"

# An existing results file survives every failed sweep, byte for byte.
echo "previous results" >"$work/study.h5"
expect_error_re "unknown parameter 'zzz'" sweep --problem pendulum --set zzz=1 --out "$work/study.h5"
expect_error_re "levels must be between 2 and 20" sweep --levels 1 --out "$work/study.h5"
[ "$(cat "$work/study.h5")" = "previous results" ] && ok || bad "existing results file was touched"
[ -z "$(ls "$work" | grep tmp)" ] && ok || bad "temporary file left behind: $(ls "$work")"

# A good sweep replaces it whole.
"$bin" sweep --problem damped_spring --integrator rk4 --levels 3 --quiet --out "$work/study.h5" >/dev/null || bad "small sweep failed"
head -c 4 "$work/study.h5" | grep -q HDF && ok || bad "study file is not HDF5"
# h5dump (hdf5-tools) reads it: the compound convergence table with its documented fields.
h5dump -d /problems/damped_spring/methods/rk4/runs "$work/study.h5" >"$work/dump" 2>&1 &&
  grep -q '"err_pos_max"' "$work/dump" && grep -q '"diverged"' "$work/dump" && ok || bad "h5dump cannot read the study file"

# A method that fails on a case is a finding, not an error of the run: implicit Euler's
# numerical damping drains the 0.9-eccentric orbit into its centre at the coarse steps.
# The study is written and exits 0, with one summary line on stderr for the method and
# problem naming what happened in the scene; --strict makes it exit 3. (The sweep part
# alone: its rows are what fails.)
"$bin" sweep --problem kepler --integrator implicit_euler --levels 8 --parts sweep --quiet --out "$work/kepler.h5" >/dev/null 2>"$work/err"
rc=$?
[ "$rc" -eq 0 ] && ok || bad "a study with failed cases exited $rc: $(cat "$work/err")"
[ "$(grep -c '^stepbench: implicit_euler: [0-9]* of 8 failed on kepler at dt ' "$work/err")" -eq 1 ] && ok ||
  bad "no one-line summary of the failures: $(cat "$work/err")"
grep -q "the orbit collapsed: r = " "$work/err" && grep -q "Newton found no root" "$work/err" && ok ||
  bad "the failure does not say what happened: $(cat "$work/err")"
"$bin" sweep --problem kepler --integrator implicit_euler --levels 8 --parts sweep --quiet --strict --out "$work/kepler.h5" >/dev/null 2>&1
rc=$?
[ "$rc" -eq 3 ] && ok || bad "--strict with failed cases exited $rc, want 3"

# --version: the version, commit and build type on the first line, then the compiler,
# flags and dependencies the study file records.
"$bin" --version >"$work/out" 2>&1 && ok || bad "--version exited non-zero"
head -1 "$work/out" | grep -Eq '^stepbench [0-9][^ ]* \(commit [0-9a-f]+(-dirty)?|unknown, [A-Za-z]* ?build\)$' && ok ||
  bad "--version line: $(head -1 "$work/out")"
grep -q '^compiler: .*; flags: ' "$work/out" && grep -q '^dependencies: .*Google Benchmark' "$work/out" && ok ||
  bad "--version lacks the compiler, flags or dependencies: $(cat "$work/out")"

# Usage errors exit 2 with one line naming what is wrong.
expect_error_re "--dt 20 s is longer than the horizon of constant_acceleration (10 s)" \
  run --problem constant_acceleration --integrator euler --dt 20
expect_error_re "--dt 3 s is longer than the horizon of pendulum (2 s)" run --problem pendulum --integrator rk4 --dt 3 --horizon 2
expect_error_re "unknown problem 'nosuch' (known: constant_acceleration, " ratios --problem nosuch
expect_error_re "unknown problem 'nosuch'" ratios --study "$work/none.h5" --problem damped_spring --problem nosuch

# run's text: every vector once, compact beyond six entries, never "-0"; counts with the
# right plural; units on every quantity.
"$bin" run --problem spring_chain --integrator rk4 --dt 0.0001 >"$work/out" || bad "run spring_chain failed"
[ "$(grep -c '96 entries' "$work/out")" -eq 2 ] && ok || bad "spring_chain vectors not compact: $(cat "$work/out")"
[ "$(awk '{ if (length($0) > 160) n++ } END { print n + 0 }' "$work/out")" -eq 0 ] && ok ||
  bad "run prints lines over 160 characters: $(cat "$work/out")"
grep -q '^  position \[m\] ' "$work/out" && grep -q '^  velocity \[m/s\]' "$work/out" && grep -q 'err_pos_max .* m$' "$work/out" &&
  ok || bad "run lacks units: $(cat "$work/out")"
for args in "--problem spring_chain --integrator rk4 --dt 0.0001" "--problem kepler --integrator rk4 --dt 0.01" \
  "--problem pendulum --integrator velocity_verlet --dt 0.01"; do
  # shellcheck disable=SC2086
  "$bin" run $args >"$work/out" || bad "run $args failed"
  grep -Eq '(^|[^0-9.e])-0([^.0-9e]|$)' "$work/out" && bad "run $args prints -0: $(grep -E -- '-0([^.0-9e]|$)' "$work/out")" || ok
done
"$bin" run --problem constant_acceleration --integrator euler --dt 10 >"$work/out" || bad "one-step run failed"
grep -q 'dt 10 s to t = 10 s, 1 step, 1 force evaluation$' "$work/out" && ok || bad "plural of one: $(head -1 "$work/out")"

# loop: times in the unit that fits them.
"$bin" loop --problem pendulum --integrator rk4 --design fixed >"$work/out" || bad "loop --design failed"
grep -q 'cost model  *1 us a step (stated default): worst frame 1 us of a 16.7 ms budget' "$work/out" && ok ||
  bad "loop's cost model units: $(grep 'cost model' "$work/out")"
grep -q 'e+0[0-9] ns' "$work/out" && bad "loop prints powers of ten of ns: $(cat "$work/out")" || ok

# list: the friction table once; stability: labelled columns.
[ "$("$bin" list | grep -c 'aluminum_on_aluminum')" -eq 1 ] && ok || bad "list prints the friction table more than once"
"$bin" stability | grep -q 'y_max theory (a)  y_max measured (b)' && ok || bad "stability's columns are not labelled"

# scan: one line and exit 2 for a bad axis; the answer as JSON on stdout, progress on
# stderr; advise --scan answers from the file; a file without a scan is exit 1.
expect_error_re "outside the parameter's range: k_s must be a positive finite number" scan --problem stiff_spring --param stiff_spring.k_s=-1:1e7:5 --out "$work/scan.h5"
expect_error_re "stiff_spring has no parameter 'kk'" scan --problem stiff_spring --param stiff_spring.kk=1:2:3 --out "$work/scan.h5"
expect_error_re "frame rate 45 Hz does not divide the fastest, 60 Hz" scan --problem stiff_spring --param stiff_spring.k_s=1:2:3 --hz 60,45 --out "$work/scan.h5"
# Rates and horizons are bounded before anything is allocated (a scan at 1e9 Hz grew past
# 8 GB): 0.533 s x 1e9 Hz = 5.33e8 frame ends, refused; a grid point over the bound is not
# run, with the reason, and the scan goes on (durations 1 and 1e9 s at 240 Hz).
expect_error_re "scan: 5.33e+08 frame ends (1e+09 Hz over 0.533 s); the limit is 1e+07" \
  scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e7:5:log --hz 1e9 --out "$work/scan.h5"
"$bin" scan --problem stiff_spring --param stiff_spring.duration=1:1e9:2:log --hz 240 --integrator rk4 --substeps 16 \
  --quiet --out "$work/long.h5" >/dev/null && /usr/bin/python3 -c '
import sys, h5py
with h5py.File(sys.argv[1]) as f:
    notes = [n.decode() for n in f["scan/stiff_spring/points"]["note"]]
    runs = f["scan/stiff_spring/runs"][:]
assert notes == ["", "not run: 2.4e+11 frame ends (240 Hz over 1e+09 s); the limit is 1e+07"], notes
assert list(runs["point"]) == [0] and runs["err_pos_max"][0] < 1e-3, runs
' "$work/long.h5" && ok || bad "scan over long horizons: the points over the frame bound are not run"
[ ! -e "$work/scan.h5" ] && ok || bad "a refused scan wrote its file"
"$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e7:25:log --hz 60 --substeps 1,8 --json \
  --out "$work/scan.h5" >"$work/out" 2>"$work/err" || bad "scan failed: $(cat "$work/err")"
/usr/bin/python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["points"] == 25 and d["grid_points"] == 25, d' "$work/out" && ok ||
  bad "scan --json is not one JSON object: $(head -3 "$work/out")"
grep -q '^wrote .*scan.h5 (/scan/stiff_spring: 25 points' "$work/err" && ok || bad "scan's summary: $(cat "$work/err")"
# Progress and the summary never end a scan: with stderr closed it is written and exits 0.
"$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e3:3:log --hz 60 --substeps 1 \
  --out "$work/closed.h5" >/dev/null 2>&-
rc=$?
[ "$rc" -eq 0 ] && [ -e "$work/closed.h5" ] && ok || bad "scan with stderr closed exited $rc"
"$bin" advise --scan "$work/scan.h5" --tol 1e-3 >"$work/out"
rc=$?  # 3: with at most 8 substeps nothing holds 1 mm over the whole range
[ "$rc" -eq 3 ] && grep -q '60 Hz: no method of the scan stays within 0.001 m over the whole range' "$work/out" && ok ||
  bad "advise --scan at 1e-3 exited $rc: $(cat "$work/out")"
grep -q '60 Hz  rk4  *diverges for k_s >= 5.62e+04 N/m' "$work/out" && ok || bad "advise --scan: $(cat "$work/out")"
"$bin" advise --scan "$work/none.h5" --tol 1e-3 >/dev/null 2>"$work/err"
[ $? -eq 1 ] && grep -q "cannot read study file '.*none.h5': no such file" "$work/err" && ok ||
  bad "advise --scan of a missing file: $(cat "$work/err")"
# A scan file given as a study: one line pointing to --scan, with and without --hz.
expect_error_re "holds a scan of stiff_spring, not a study: read it with \`stepbench advise --scan" \
  advise --study "$work/scan.h5" --problem stiff_spring --tol 1e-3
expect_error_re "holds a scan of stiff_spring, not a study" advise --study "$work/scan.h5" --problem stiff_spring --hz 60 --tol 1e-3

# scan --shard K/N and merge: three shards join to the unsharded scan's answer; a shard
# twice, a missing shard, another build: one line, exit 2, no file.
for k in 1 2 3; do
  "$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e7:13:log --hz 60 --substeps 1,4 --shard "$k/3" \
    --quiet --out "$work/shard$k.h5" >/dev/null || bad "scan --shard $k/3 failed"
done
"$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e7:13:log --hz 60 --substeps 1,4 --quiet \
  --out "$work/whole.h5" >"$work/whole.txt" || bad "the unsharded scan failed"
"$bin" merge "$work/shard2.h5" "$work/shard1.h5" "$work/shard3.h5" -o "$work/merged.h5" 2>"$work/err" ||
  bad "merge failed: $(cat "$work/err")"
"$bin" advise --scan "$work/merged.h5" --tol 1e-3 >"$work/merged.txt"
cmp -s "$work/merged.txt" "$work/whole.txt" && ok || bad "the merged scan answers otherwise: $(diff "$work/merged.txt" "$work/whole.txt")"
cp "$work/shard3.h5" "$work/shard3copy.h5"
expect_error_re "grid point .* is in two shards" merge "$work/shard1.h5" "$work/shard2.h5" "$work/shard3.h5" "$work/shard3copy.h5" -o "$work/m2.h5"
expect_error_re "is named twice" merge "$work/shard1.h5" "$work/shard1.h5" -o "$work/m2.h5"
expect_error_re "4 of 13 grid points are in no shard\|grid points are in no shard" merge "$work/shard1.h5" "$work/shard2.h5" -o "$work/m2.h5"
[ ! -e "$work/m2.h5" ] && ok || bad "a refused merge wrote its file"
"$bin" merge "$work/shard1.h5" "$work/shard2.h5" --partial -o "$work/m2.h5" 2>"$work/err" && grep -q "lacks .* of 13 grid points (--partial)" "$work/err" && ok ||
  bad "merge --partial: $(cat "$work/err")"
cp "$work/shard3.h5" "$work/other.h5"
/usr/bin/python3 -c 'import h5py,sys; f=h5py.File(sys.argv[1],"r+"); f.attrs["git_commit"]="0000000"' "$work/other.h5"
expect_error_re "was written by another build" merge "$work/shard1.h5" "$work/shard2.h5" "$work/other.h5" -o "$work/m3.h5"
expect_error_re "shard 4 of 3\|1 <= K <= N" scan --problem stiff_spring --param stiff_spring.k_s=1:2:3 --shard 4/3 --out "$work/x.h5"

# A 10^4-point scan over 4 local shards (xargs -P 2, the README's recipe) finishes and
# merges: every grid point once, in grid order, each with its runs.
start=$(date +%s.%N)
seq 1 4 | xargs -P 2 -I{} "$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e7:100:log \
  --param stiff_spring.k_d=0:40:100 --hz 60 --substeps 1,4 --method rk4 --method semi_implicit_euler \
  --shard {}/4 --quiet --out "$work/big{}.h5" >/dev/null || bad "the 10^4-point shards failed"
"$bin" merge "$work"/big[1-4].h5 -o "$work/big.h5" 2>"$work/err" || bad "merging the 10^4-point shards: $(cat "$work/err")"
/usr/bin/python3 -c '
import h5py, numpy as np, sys
g = h5py.File(sys.argv[1], "r")["scan/stiff_spring"]
pts, runs = g["points"][:], g["runs"][:]
assert g.attrs["grid_points"] == 10000 and len(pts) == 10000, (g.attrs["grid_points"], len(pts))
assert (pts["point"] == np.arange(10000)).all()
assert len(runs) == 10000 * 2 * 2, len(runs)
' "$work/big.h5" && ok || bad "the merged 10^4-point scan"
fmt_secs=$(/usr/bin/python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.2f}')" "$start" "$(date +%s.%N)")
echo "10^4-point scan, 4 shards by xargs -P 2, and merge: $fmt_secs s" >&2

expect_error_re "frame rate 60 Hz is given twice" scan --problem stiff_spring --param stiff_spring.k_s=1:2:3 --hz 60,60 --out "$work/x.h5"
expect_file_error "not an HDF5 file" merge "$work/out" "$work/shard1.h5" -o "$work/m4.h5"

# Shards run with another --set or other methods are another scan: refused in one line
# naming what differs and both values.
"$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e7:13:log --hz 60 --substeps 1,4 --shard 3/3 \
  --set stiff_spring.mass_kg=2 --quiet --out "$work/set3.h5" >/dev/null || bad "scan --shard 3/3 --set failed"
expect_error_re "differ in their fixed parameters (--set): '.*shard1.h5' has none, '.*set3.h5' has mass_kg=2$" \
  merge "$work/shard1.h5" "$work/shard2.h5" "$work/set3.h5" -o "$work/m5.h5"
"$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e7:13:log --hz 60 --substeps 1,4 --shard 3/3 \
  --method rk4 --quiet --out "$work/rk4only3.h5" >/dev/null || bad "scan --shard 3/3 --method rk4 failed"
expect_error_re "differ in their methods: '.*shard1.h5' has .*rk4.*, '.*rk4only3.h5' has rk4$" \
  merge "$work/shard1.h5" "$work/shard2.h5" "$work/rk4only3.h5" -o "$work/m5.h5"
[ ! -e "$work/m5.h5" ] && ok || bad "a refused merge wrote its file"
# A shard with no point (more shards than points) is written, read and merged; the merged
# scan answers as the unsharded one.
for k in 1 2 3 4 5; do
  "$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e3:3:log --hz 60 --substeps 1 --shard "$k/5" \
    --quiet --out "$work/small$k.h5" >/dev/null || bad "scan --shard $k/5 of 3 points failed"
done
"$bin" advise --scan "$work/small5.h5" --tol 1e-3 --json | /usr/bin/python3 -c '
import json, sys
d = json.load(sys.stdin)
assert d["points"] == 0 and d["grid_points"] == 3, d' && ok || bad "an empty shard does not read back"
"$bin" merge "$work"/small[1-5].h5 -o "$work/small.h5" 2>"$work/err" || bad "merge with an empty shard: $(cat "$work/err")"
"$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e3:3:log --hz 60 --substeps 1 --quiet \
  --out "$work/smallwhole.h5" >"$work/smallwhole.txt" || bad "the unsharded small scan failed"
"$bin" advise --scan "$work/small.h5" --tol 1e-3 >"$work/small.txt"
cmp -s "$work/small.txt" "$work/smallwhole.txt" && ok ||
  bad "the merge with an empty shard answers otherwise: $(diff "$work/small.txt" "$work/smallwhole.txt")"
# A file whose grid_points is not the product of its axes' counts is refused by name.
cp "$work/whole.h5" "$work/badgrid.h5"
/usr/bin/python3 -c 'import h5py,sys; f=h5py.File(sys.argv[1],"r+"); f["scan/stiff_spring"].attrs["grid_points"]=14' "$work/badgrid.h5"
expect_file_error "cannot read study file '.*badgrid.h5': scan 'stiff_spring': grid_points 14 is not the product of its axes' counts, 13" \
  advise --scan "$work/badgrid.h5" --tol 1e-3

# stepbench_bench, beside stepbench: --help lists our flags, one line each, above Google
# Benchmark's.
bench=$(dirname "$bin")/stepbench_bench
if [ -x "$bench" ]; then
  "$bench" --help >"$work/out" 2>&1 && ok || bad "stepbench_bench --help exited non-zero"
  for flag in --quick --study_out= --problem= --set= --case_budget= --strict --verbose --benchmark_filter; do
    [ "$(grep -c -- "^ *\[\?$flag" "$work/out")" -eq 1 ] && ok || bad "stepbench_bench --help does not list $flag once"
  done
  "$bench" --benchmark_format=xml >/dev/null 2>"$work/err"
  rc=$?
  [ "$rc" -eq 2 ] && grep -q "benchmark_format must be console, json or csv, got 'xml'" "$work/err" && ok ||
    bad "stepbench_bench --benchmark_format=xml exited $rc: $(cat "$work/err")"
fi

# Extreme rates, counts and horizons, each command under a 3 GB address-space limit (the
# budget of any process): refused before the work in one line, exit 2, never an allocation.
# AddressSanitizer reserves terabytes of address space at start, so a sanitized build runs
# them without the limit (the Release run has it).
limit=3000000
ldd "$bin" | grep -q libasan && limit=unlimited
extreme() {
  local want=$1; shift
  (ulimit -v "$limit"; "$bin" "$@") >"$work/out" 2>"$work/err"
  local rc=$?
  [ "$rc" -eq 2 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && grep -q -- "$want" "$work/err" && ok ||
    bad "extreme value: $* exited $rc: $(head -c 300 "$work/err")"
}
extreme "frame ends (1e+09 Hz over 0.533 s); the limit is 1e+07" scan --problem stiff_spring --hz 1e9 --out "$work/x.h5"
extreme "frame ends (1e+09 Hz over 5.51 s); the limit is 1e+07" advise --problem pendulum --hz 1e9 --tol 1e-3 \
  --study "$work/none.h5"
extreme "coordinates (60 Hz over 0.533 s) = 1.01e+08; the limit is 2e+07" scan --problem spring_chain \
  --set spring_chain.masses=1048576 --hz 60 --out "$work/x.h5"
extreme "needs more than 1e9 steps" run --problem pendulum --integrator rk4 --dt 1e-300
extreme "needs more than 1e9 steps to reach 1e+300" run --problem pendulum --integrator rk4 --dt 1e-3 --horizon 1e300
extreme "periods must be a whole number from 1 to 1e7" energy --periods 1000000000000
extreme "the limit is 1e+07" loop --problem pendulum --integrator rk4 --set pendulum.periods=1e9 --design fixed
extreme "max levels must be between" sweep --max-levels 1000 --out "$work/x.h5"
extreme "substeps 2.09715e+06 is not a whole number from 1 to 2^20" scan --problem pendulum --substeps 2097152 \
  --out "$work/x.h5"
[ ! -e "$work/x.h5" ] && ok || bad "an extreme value left a file behind"

finish cli
