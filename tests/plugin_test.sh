#!/usr/bin/env bash
# Plugins as a user meets them (docs/plugins.md): a plugin built outside the tree with the
# documented one-line command runs in `run --json` and in a sweep whose study records it;
# a bad plugin file is refused in one line with exit 2 and nothing written; a step that
# fails, and one that crashes under --isolate, becomes a failed row of a study written whole.
# usage: plugin_test.sh path/to/stepbench SOURCE_DIR PLUGIN_DIR (build/plugins)
set -u
bin=${1:?usage: plugin_test.sh stepbench source-dir plugin-dir}
src=${2:?}
plugins=${3:?}
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

# The documented build, outside the tree, of a copy of the example renamed.
sed 's/"plugin_rk4"/"my_rk4"/' "$src/examples/plugins/rk4.c" >"$work/my.c"
(cd "$work" && cc -shared -fPIC -O2 -I "$src/include" -o libmy.so my.c) || bad "the documented cc line failed"

out=$("$bin" run --plugin "$work/libmy.so" --problem pendulum --method my_rk4 --dt 0.01 --json) || bad "run --json"
ref=$("$bin" run --problem pendulum --method rk4 --dt 0.01 --json) || bad "run rk4 --json"
/usr/bin/python3 - "$out" "$ref" <<'PY' && ok || bad "run --json of the plugin: $out"
import json, sys
d, r = json.loads(sys.argv[1]), json.loads(sys.argv[2])
assert d["origin"] == "plugin" and d["integrator"] == "my_rk4", d
assert d["steps"] == 552 and d["force_evals"] == 4 * 552, d
assert d["position"] == r["position"] and d["err_pos_max"] == r["err_pos_max"], (d, r)
PY

# Refusals: one line naming the file and the problem, exit 2, nothing written.
echo "not a library" >"$work/text.so"
expect_error "plugin $work/text.so: not a shared library it can load" \
  sweep --plugin "$work/text.so" --problem pendulum --parts sweep --out "$work/never.h5"
expect_error "plugin $plugins/bad/libbad_no_entry.so: not a stepbench plugin" \
  sweep --plugin "$plugins/bad/libbad_no_entry.so" --problem pendulum --parts sweep --out "$work/never.h5"
expect_error "ABI version 2; this stepbench reads version 1" \
  run --plugin "$plugins/bad/libbad_abi.so" --problem pendulum --method rk4 --dt 0.01
expect_error "method 1 (rk4): the name is taken" \
  run --plugin "$plugins/bad/libbad_reserved.so" --problem pendulum --method rk4 --dt 0.01
expect_error "plugin $work/libmy.so: method 1 (my_rk4): the name is taken" \
  run --plugin "$work/libmy.so" --plugin "$work/libmy.so" --problem pendulum --method my_rk4 --dt 0.01
expect_error "its order is 0, not 1 to 16" \
  run --plugin "$plugins/bad/libbad_fields.so" --problem pendulum --method rk4 --dt 0.01

# A sweep with the plugin, a failing one and (under --isolate) a crashing one: the study
# is written whole, the plugin's rows fitted, the bad ones failed with their reasons, and
# the root attribute `plugins` names all three with their hashes.
"$bin" sweep --plugin "$work/libmy.so" --plugin "$plugins/bad/libbad_status.so" \
  --plugin "$plugins/bad/libbad_crash.so" --isolate --problem pendulum \
  --method rk4 --method my_rk4 --method bad_status --method bad_crash --parts sweep --quiet \
  --out "$work/study.h5" >"$work/out" 2>"$work/err" || bad "sweep with plugins: $(cat "$work/err")"
/usr/bin/python3 - "$work/study.h5" "$work/libmy.so" <<'PY' && ok || bad "the study of the sweep with plugins"
import h5py, json, sys
f = h5py.File(sys.argv[1], "r")
plugins = json.loads(f.attrs["plugins"])
assert [p["methods"] for p in plugins] == [["my_rk4"], ["bad_status"], ["bad_crash"]], plugins
assert all(p["abi_version"] == 1 and len(p["fnv1a_64"]) == 16 for p in plugins), plugins
# FNV-1a 64 of the file's bytes, computed here again.
h = 0xcbf29ce484222325
for b in open(sys.argv[2], "rb").read():
    h = ((h ^ b) * 0x100000001b3) % 2**64
assert plugins[0]["fnv1a_64"] == f"{h:016x}", plugins[0]
m = f["problems/pendulum/methods"]
mine, ours = m["my_rk4"], m["rk4"]
assert mine.attrs["origin"] == "plugin" and mine.attrs["fit_status"] == "fitted", dict(mine.attrs)
assert mine.attrs["fit_slope"] == ours.attrs["fit_slope"], (mine.attrs["fit_slope"], ours.attrs["fit_slope"])
assert (mine["runs"]["err_pos_max"] == ours["runs"]["err_pos_max"]).all()
for name, why in (("bad_status", "returned status 7"), ("bad_crash", "--isolate: the run crashed: signal 11")):
    runs = m[name]["runs"]
    assert len(runs) > 0 and all(runs["failed"]), (name, runs["failed"])
    reasons = {r.decode() if isinstance(r, bytes) else r for r in runs["note"]}
    assert all(why in r for r in reasons), (name, reasons)
PY

# loop --plugin: the plugin's RK4 in the game loop shows what rk4 shows, its errors over
# the frames and its end state (bit for bit: the pendulum's mass is 1, docs/plugins.md);
# --isolate is not a loop option.
for m in plugin_rk4 rk4; do
  "$bin" loop --plugin "$plugins/librk4.so" --problem pendulum --integrator $m --design interpolated --json \
    >"$work/loop_$m.json" 2>"$work/err" || bad "loop --plugin ($m): $(cat "$work/err")"
done
/usr/bin/python3 - "$work/loop_plugin_rk4.json" "$work/loop_rk4.json" <<'PY' && ok || bad "loop --plugin against rk4"
import json, sys
mine, ours = (json.load(open(p)) for p in sys.argv[1:3])
assert mine["integrator"] == "plugin_rk4" and mine["frames"] > 100, mine
for key in ("final_physics_position", "final_physics_velocity", "final_shown_position", "shown_err_max",
            "shown_err_rms", "physics_steps", "force_evals", "frames"):
    assert mine[key] == ours[key], (key, mine[key], ours[key])
assert 0 < mine["shown_err_max"] < 0.2, mine["shown_err_max"]  # the shown state lags a step at most
PY
expect_error "The following argument was not expected: --isolate" loop --plugin "$plugins/librk4.so" --isolate --problem pendulum \
  --integrator plugin_rk4 --design fixed

# The plugins' line of the verdict: the plugin RK4 against the fastest of ours (rk4 alone
# here, whose rows it equals bit for bit) and the fastest peer (odeint_rk4), at each target:
# its cost is rk4's, so it is 1x ours, within the rounding, and what ours is to the peer.
"$bin" sweep --plugin "$work/libmy.so" --problem pendulum --method rk4 --method my_rk4 --method odeint_rk4 \
  --parts sweep,verdict --out "$work/verdict.h5" >"$work/verdict.txt" 2>"$work/err" || bad "sweep, verdict: $(cat "$work/err")"
/usr/bin/python3 - "$work/verdict.h5" <<'PY' && ok || bad "the plugins' verdict table"
import h5py, math, sys
v = h5py.File(sys.argv[1], "r")["verdict"]
pe, ee = v["plugin_equal_error"][()], v["equal_error"][()]
assert len(pe) == len(ee) > 0, (len(pe), len(ee))
reached = 0
for p, e in zip(pe, ee):
    assert p["target"] == e["target"] and p["problem"] == e["problem"] == b"pendulum"
    if not e["ours_method"]:
        assert not p["plugin_method"] and p["verdict_ours"] == b"not reached", p  # rk4's rows, the plugin's
        continue
    reached += 1
    assert e["ours_method"] == b"rk4" and p["plugin_method"] == b"my_rk4", (e, p)
    assert p["plugin_cost"] == e["ours_cost"] and p["vs_ours"] == 1.0 and p["verdict_ours"] == b"within spread", p
    if e["peer_method"]:
        assert math.isclose(p["vs_peer"], e["ratio"], rel_tol=1e-15) and p["verdict_peer"] == e["verdict"], (p, e)
assert reached >= 3, reached
PY
# The report's first page shows it after the equal-error table.
/usr/bin/python3 "$src/scripts/report" "$work/verdict.h5" --out "$work/report" >/dev/null 2>"$work/err" \
  || bad "report of the plugin study: $(cat "$work/err")"
grep -q "Your plugin&#x27;s methods at equal error\|Your plugin's methods at equal error" "$work/report/index.html" \
  && grep -q "my_rk4" "$work/report/index.html" && ok || bad "the report shows no plugin table"
# A study without plugins has no such table.
"$bin" sweep --problem pendulum --method rk4 --method odeint_rk4 --parts sweep,verdict --out "$work/none.h5" \
  >/dev/null 2>&1 || bad "sweep without plugins"
/usr/bin/python3 -c 'import h5py, sys; assert "plugin_equal_error" not in h5py.File(sys.argv[1], "r")["verdict"]' \
  "$work/none.h5" && ok || bad "a study without plugins has a plugin table"

# Shards that loaded different plugins (by path or bytes) are not one study: merge refuses
# them in one line (the sweep's options name each plugin and its hash); the same plugin joins.
for k in 1 2; do
  "$bin" sweep --plugin "$plugins/libruth3.so" --problem pendulum --problem damped_spring --method rk4 \
    --method ruth3 --parts sweep,verdict --shard $k/2 --quiet --out "$work/s$k.h5" 2>/dev/null || bad "shard $k"
done
# Another build of ruth3: the same library with one byte more (it loads the same).
cp "$plugins/libruth3.so" "$work/libruth3_other.so" && printf '\0' >>"$work/libruth3_other.so"
"$bin" sweep --plugin "$work/libruth3_other.so" --problem pendulum --problem damped_spring --method rk4 \
  --method ruth3 --parts sweep,verdict --shard 2/2 --quiet --out "$work/other.h5" 2>/dev/null \
  || bad "shard 2 with another plugin"
expect_error "has plugin: $work/libruth3_other.so fnv1a_64" merge "$work/s1.h5" "$work/other.h5" --out "$work/never.h5"
"$bin" merge "$work/s1.h5" "$work/s2.h5" --out "$work/merged.h5" >/dev/null 2>&1 && ok || bad "merge of shards with one plugin"
# The plugins' verdict rows of both shards' problems, joined; ruth3 (third order) against
# rk4 by force evaluations: each ratio is ruth3's cost over rk4's at the same target, and
# its verdict is from ruth3's side (ahead when cheaper).
/usr/bin/python3 - "$work/merged.h5" <<'PY' && ok || bad "the merged study's plugin verdict"
import h5py, math, sys
v = h5py.File(sys.argv[1], "r")["verdict"]
pe, ee = v["plugin_equal_error"][()], v["equal_error"][()]
assert {p.decode() for p in pe["problem"]} == {"pendulum", "damped_spring"}, set(pe["problem"])
assert {m.decode() for m in pe["plugin_method"] if m} == {"ruth3"}, set(pe["plugin_method"])
seen = set()
for p in pe:
    e = next(e for e in ee if e["problem"] == p["problem"] and e["target"] == p["target"])
    if p["plugin_method"] and e["ours_method"]:
        assert math.isclose(p["vs_ours"], p["plugin_cost"] / e["ours_cost"], rel_tol=1e-15), (p, e)
        want = "ahead" if p["vs_ours"] < 1 / (1 + 1e-9) else "behind" if p["vs_ours"] > 1 + 1e-9 else "within spread"
        assert p["verdict_ours"].decode() in (want, "bounded"), (p["verdict_ours"], want, p["vs_ours"])
    elif e["ours_method"]:
        assert p["verdict_ours"] == b"others only" and math.isnan(p["vs_ours"]), p
    seen.add(p["verdict_ours"].decode())
assert "behind" in seen and "ahead" in seen, seen  # rk4 needs fewer evaluations at tight targets, not at loose ones
PY
# A shard that ran no problem has no plugin table: merged in either order, the table is
# the other shard's rows.
"$bin" sweep --plugin "$plugins/libruth3.so" --problem pendulum --method rk4 --method ruth3 --parts sweep,verdict \
  --shard 1/2 --quiet --out "$work/p1.h5" 2>/dev/null || bad "shard 1 of one problem"
"$bin" sweep --plugin "$plugins/libruth3.so" --problem pendulum --method rk4 --method ruth3 --parts sweep,verdict \
  --shard 2/2 --quiet --out "$work/p2.h5" 2>/dev/null || bad "shard 2 of one problem (none)"
for order in "p1 p2" "p2 p1"; do
  set -- $order
  "$bin" merge "$work/$1.h5" "$work/$2.h5" --out "$work/m_$1.h5" >/dev/null 2>"$work/err" || bad "merge $order: $(cat "$work/err")"
  /usr/bin/python3 -c 'import h5py, sys; pe = h5py.File(sys.argv[1], "r")["verdict/plugin_equal_error"][()]
assert len(pe) > 0 and set(pe["problem"]) == {b"pendulum"}, pe' "$work/m_$1.h5" && ok || bad "merge $order: the plugin table"
done

finish plugin_test
