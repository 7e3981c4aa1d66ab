#!/usr/bin/env bash
# Scene files as a user meets them (docs/scenes.md): `scene check` summarises a file;
# `--scene FILE` stands for the scene on run, sweep, advise, scan, list and
# stepbench_bench, with --set on its parameters; the study records the file; a bad file,
# a clash of names and a bad flag are refused in one line with exit 2 and nothing written.
# usage: scene_test.sh path/to/stepbench path/to/stepbench_bench SOURCE_DIR
set -u
bin=${1:?usage: scene_test.sh stepbench stepbench_bench source-dir}
bench=${2:?}
src=${3:?}
scenes="$src/examples/scenes"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

# scene check: the answer first, then what the file holds.
out=$("$bin" scene check "$scenes/cloth.toml") || bad "scene check cloth"
head -1 <<<"$out" | grep -q "cloth.toml: valid: scene 'cloth', 3-D, 32 masses (30 moving, 2 fixed), 94 springs, gravity" &&
  ok || bad "scene check's first line: $out"
grep -q "next: stepbench advise --scene" <<<"$out" && ok || bad "scene check names the next step: $out"
"$bin" scene check "$scenes/pleiades.toml" --json | /usr/bin/python3 -c '
import json, sys
d = json.load(sys.stdin)
assert d["name"] == "pleiades" and d["moving"] == 7 and d["attraction"] and not d["gravity"], d
assert d["state_size"] == 28 and abs(d["moving_mass_kg"] - 28.0) < 1e-12, d
assert [p["name"] for p in d["parameters"]][:2] == ["stiffness_scale", "damping_scale"], d' && ok || bad "scene check --json"

out=$("$bin" scene check "$scenes/bouncing_ball.toml") || bad "scene check bouncing_ball"
head -1 <<<"$out" | grep -q "1 mass (1 moving, 0 fixed), gravity, 1 plane; horizon 2 s" && ok || bad "a plane in scene check: $out"

# run: the scene's name, its truth from the references.
out=$("$bin" run --scene "$scenes/damped_spring.toml" --method rk4 --dt 0.01 --json) || bad "run --scene"
/usr/bin/python3 - "$out" <<'PY' && ok || bad "run --scene --json: $out"
import json, sys
d = json.loads(sys.argv[1])
assert d["problem"] == "damped_spring_file" and d["steps"] == 1000, d
assert 0 < d["err_pos_final"] < 1e-8, d
PY
# --set on a scene's parameter changes the motion; the same with the name left out.
a=$("$bin" run --scene "$scenes/web.toml" --method rk4 --dt 1e-3 --json | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["position"][0])')
b=$("$bin" run --scene "$scenes/web.toml" --method rk4 --dt 1e-3 --set web.stiffness_scale=2 --json |
  /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["position"][0])')
c=$("$bin" run --scene "$scenes/web.toml" --method rk4 --dt 1e-3 --set stiffness_scale=2 --json |
  /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["position"][0])')
[ -n "$a" ] && [ "$a" != "$b" ] && [ "$b" = "$c" ] && ok || bad "--set web.stiffness_scale: $a $b $c"

# list --scene: the scene with its parameters among the problems.
"$bin" list --scene "$scenes/rope.toml" --json | /usr/bin/python3 -c '
import json, sys
d = json.load(sys.stdin)
rope = [p for p in d["problems"] if p["name"] == "rope"]
assert len(rope) == 1 and rope[0]["dim"] == 189, rope
assert "duration" in [q["name"] for q in rope[0]["parameters"]], rope' && ok || bad "list --scene"

# sweep --scene: its rows and fitted orders in the study, the file recorded.
"$bin" sweep --scene "$scenes/damped_spring.toml" --scene "$scenes/pleiades.toml" --quick --parts sweep,verdict --quiet \
  --out "$work/s.h5" 2>"$work/err" ||
  bad "sweep --scene: $(cat "$work/err")"
/usr/bin/python3 - "$work/s.h5" <<'PY' && ok || bad "the sweep's study of pleiades"
import json, sys, h5py
with h5py.File(sys.argv[1]) as f:
    scenes = json.loads(f.attrs["scenes"])
    assert [s["name"] for s in scenes] == ["damped_spring_file", "pleiades"], scenes
    assert all(len(s["fnv1a_64"]) == 16 for s in scenes), scenes
    assert f["problems/pleiades"].attrs["dim"] == 14
    # The quick ladder's steps on the Pleiades are pre-asymptotic (close encounters): its
    # orders are fitted on the spring, whose rk4 is fourth order from the first level.
    order = float(f["problems/damped_spring_file/methods/rk4"].attrs["observed_order"])
    assert 3.8 < order < 4.2, order
PY

# The report of one scene: --scene FILE finds its name in the study's `scenes`.
/usr/bin/python3 "$src/scripts/report" "$work/s.h5" --scene "$scenes/pleiades.toml" --markdown "$work/p.md" \
  >/dev/null 2>"$work/err" && grep -q "^| pleiades" "$work/p.md" && ! grep -q "^| damped_spring_file" "$work/p.md" && ok ||
  bad "report --scene: $(cat "$work/err") $(head -c 300 "$work/p.md")"
/usr/bin/python3 "$src/scripts/report" "$work/s.h5" --scene "$scenes/web.toml" --markdown "$work/never.md" \
  >/dev/null 2>"$work/err"
[ $? -eq 2 ] && grep -q "not one of the study's scene files (damped_spring_file" "$work/err" && [ ! -e "$work/never.md" ] &&
  ok || bad "report --scene of a file the study did not run: $(cat "$work/err")"

# advise --scene --hz: the frame-rate answer, run here (the study lacks the scene).
out=$("$bin" advise --scene "$scenes/cloth.toml" --hz 60 --tol 1e-3 --study "$work/none.h5" 2>"$work/err")
rc=$?
[ "$rc" -eq 0 ] || [ "$rc" -eq 3 ] && ok || bad "advise --scene exit $rc: $(cat "$work/err")"
grep -q "cloth" <<<"$out$(cat "$work/err")" && ok || bad "advise --scene names the scene: $out"

# scan --scene: a range of one of the scene's parameters; loop --scene: one configuration.
"$bin" scan --scene "$scenes/web.toml" --param web.stiffness_scale=0.5:2:3 --hz 60 --substeps 1,4 --quiet \
  --out "$work/scan.h5" >"$work/out" 2>"$work/err" && [ -s "$work/scan.h5" ] && ok ||
  bad "scan --scene: $(cat "$work/err")"
"$bin" loop --scene "$scenes/web.toml" --integrator semi_implicit_euler --design fixed --json >"$work/out" 2>"$work/err" &&
  /usr/bin/python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["problem"] == "web", d' "$work/out" &&
  ok || bad "loop --scene: $(cat "$work/err") $(head -c 300 "$work/out")"

# energy --scene: an undamped mass on a spring, the period its horizon: explicit Euler
# gains energy, implicit Euler loses it (to rest about x = 1 m: its Newton solve ends at
# x's round-off), semi-implicit Euler's error stays bounded.
"$bin" energy --scene "$src/tests/data/undamped_spring.toml" --periods 200 --json >"$work/out" 2>"$work/err" &&
  /usr/bin/python3 - "$work/out" <<'PY' && ok || bad "energy --scene: $(cat "$work/err") $(head -c 300 "$work/out")"
import json, sys
runs = {r["method"]: r for r in json.load(open(sys.argv[1]))}
assert all(r["problem"] == "undamped_spring" and r["steps_per_period"] == 64 for r in runs.values()), runs
assert runs["euler"]["drift_sign"] == 1, runs["euler"]
assert runs["implicit_euler"]["completed"] and runs["implicit_euler"]["drift_sign"] == -1, runs["implicit_euler"]
assert runs["semi_implicit_euler"]["verdict"] == "bounded", runs["semi_implicit_euler"]
PY
"$bin" energy --scene "$src/tests/data/undamped_spring.toml" --periods 10 --period 0.1 --steps-per-period 32 >"$work/out" 2>"$work/err" &&
  grep -q "undamped_spring: 10 periods of 0.1 s (no period of its own" "$work/out" && ok ||
  bad "energy --period: $(cat "$work/err" "$work/out")"
expect_error "problem pendulum has a period of its own; leave out --period" energy --problem pendulum --period 2
expect_error "--steps-per-period must be a positive multiple of 32, got 50" energy --scene "$src/tests/data/undamped_spring.toml" \
  --steps-per-period 50

# stepbench_bench --scene=: swept and timed as a problem.
"$bench" --quick --scene="$scenes/damped_spring.toml" --parts=sweep --benchmark_min_time=0.0001 \
  --study_out="$work/t.h5" >/dev/null 2>"$work/err" || bad "stepbench_bench --scene: $(cat "$work/err")"
/usr/bin/python3 - "$work/t.h5" <<'PY' && ok || bad "the timed study of a scene"
import sys, h5py
with h5py.File(sys.argv[1]) as f:
    assert list(f["problems"].keys()) == ["damped_spring_file"], list(f["problems"].keys())
PY

# Refusals: one line, exit 2, nothing written.
printf 'name = "x"\ndim = 2\nhorizon = 1.0\n[[mass]]\nmass = 1.0\nposition = [0.0]\n' >"$work/short.toml"
expect_error "short.toml:6:12: 'position' must have 2 entries" sweep --scene "$work/short.toml" --out "$work/never.h5"
expect_error "short.toml:6:12:" scene check "$work/short.toml"
printf 'name = "pendulum"\ndim = 1\nhorizon = 1.0\n[[mass]]\nmass = 1.0\nposition = [0.0]\n' >"$work/clash.toml"
expect_error "clash.toml:1:8: the scene's name 'pendulum' is a built-in problem's" run --scene "$work/clash.toml" \
  --method rk4 --dt 0.1
sed 's/name = "web"/name = "web"  # a copy/' "$scenes/web.toml" >"$work/web2.toml"
expect_error "is taken by the scene file" run --scene "$scenes/web.toml" --scene "$work/web2.toml" --method rk4 --dt 0.1
expect_error "cannot open the scene file" run --scene "$work/missing.toml" --method rk4 --dt 0.1
expect_error "--scene needs a scene file" run --method rk4 --dt 0.1 --scene
head -c 3000 /dev/urandom >"$work/binary.toml"
"$bin" scene check "$work/binary.toml" >/dev/null 2>"$work/err"
[ $? -eq 2 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && grep -q "binary.toml:" "$work/err" && ok ||
  bad "a binary file: $(cat "$work/err")"
: >"$work/empty.toml"
expect_error "empty.toml:1:1: empty scene file" scene check "$work/empty.toml"
"$bench" --scene="$work/short.toml" >/dev/null 2>"$work/err"
[ $? -eq 2 ] && grep -q "short.toml:6:12:" "$work/err" && ok || bad "stepbench_bench --scene of a bad file: $(cat "$work/err")"

finish scene_test
