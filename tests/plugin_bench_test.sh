#!/usr/bin/env bash
# A plugin in the timed study, as docs/plugins.md shows it: `stepbench_bench --plugin=PATH
# --quick` on the pendulum times the example RK4 beside rk4, fits its order, ranks it in the
# plugins' verdict by measured time, and `stepbench ratios` prints its time a step against
# rk4's; a bad --plugin is refused in one line before anything runs.
# A user's plugin is built outside the tree with docs/plugins.md's one cc line (a copy of the
# example renamed my_rk4) and joins the example's own build (plugin_rk4, which `ratios` names).
# usage: plugin_bench_test.sh path/to/stepbench path/to/stepbench_bench SOURCE_DIR PLUGIN_DIR (build/plugins)
set -u
bin=${1:?usage: plugin_bench_test.sh stepbench stepbench_bench source-dir plugin-dir}
bench=${2:?}
src=${3:?}
plugins=${4:?}
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

sed 's/"plugin_rk4"/"my_rk4"/' "$src/examples/plugins/rk4.c" >"$work/my.c"
(cd "$work" && cc -shared -fPIC -O2 -I "$src/include" -o libmy.so my.c) || bad "the documented cc line failed"
"$bench" --plugin="$work/libmy.so" --plugin="$plugins/librk4.so" --quick --problem=pendulum --parts=sweep,verdict \
  --study_out="$work/timed.h5" >"$work/out" 2>"$work/err" || bad "stepbench_bench --plugin: $(tail -3 "$work/err")"
/usr/bin/python3 - "$work/timed.h5" "$src/tests/python" <<'PY' && ok || bad "the timed study with the plugins"
import h5py, json, sys
f = h5py.File(sys.argv[1], "r")
assert [p["methods"] for p in json.loads(f.attrs["plugins"])] == [["my_rk4"], ["plugin_rk4"]], f.attrs["plugins"]
m = f["problems/pendulum/methods"]
for name in ("my_rk4", "plugin_rk4"):
    mine, ours = m[name], m["rk4"]
    assert mine.attrs["origin"] == "plugin" and mine.attrs["fit_status"] == "fitted", dict(mine.attrs)
    assert mine.attrs["fit_slope"] == ours.attrs["fit_slope"]
    runs = mine["runs"][()]
    assert (runs["err_pos_max"] == ours["runs"]["err_pos_max"]).all()
    assert (runs["time_ns"] > 0).any(), f"{name}'s rows are not timed"
v = f["verdict"]
assert v.attrs["cost_kind"] == "time_ns"
pe = v["plugin_equal_error"][()]
reached = [p for p in pe if p["plugin_method"] in (b"my_rk4", b"plugin_rk4")]
assert len(reached) >= 3, pe
assert all(p["plugin_cost"] > 0 and p["vs_ours"] > 0 for p in reached), reached
ee = v["equal_error"][()]
assert list(pe["cost_kind"]) == list(ee["cost_kind"]) and b"time_ns" in set(pe["cost_kind"]), pe["cost_kind"]
assert any("plugins' fastest method" in line for line in v.attrs["findings"].split("\n")), v.attrs["findings"]
# Ours against the peer, timed: the noise factor is the rule's (the larger of 1.15, or 1.25
# with a side of one repetition, and 1 + 3 x either side's relative spread) and decides the
# verdict; each side's force evaluations at equal error are its own curve's, interpolated
# log-log between the rows that bracket the target (or a bounding row's); the ratio is the
# two costs' and splits into the evaluations' ratio and the time an evaluation's.
both = [e for e in ee if e["ours_method"] and e["peer_method"] and e["cost_kind"] == b"time_ns"]
assert len(both) >= 3, ee
sys.path.insert(0, sys.argv[2])
import curve_reading
def evals_at(method, target, interpolated):
    return curve_reading.at_target(m[method.decode()]["runs"][()], target, interpolated)
for e in both:
    b, r, t = e["noise_factor"], e["ratio"], e["target"]
    spread = [(e[f"{k}_cost_hi"] - e[f"{k}_cost_lo"]) / e[f"{k}_cost"] for k in ("ours", "peer")]
    floor = 1.15 if min(spread) > 0 else 1.25
    assert abs(b - max(floor, 1 + 3 * max(spread))) <= 1e-12, e
    decided = b"ahead" if r < 1 / b else b"behind" if r > b else b"within spread"
    assert e["verdict"] in (decided, b"bounded"), e
    for k in ("ours", "peer"):
        mine = evals_at(e[f"{k}_method"], t, e[f"{k}_interpolated"])
        assert any(abs(x / e[f"{k}_force_evals"] - 1) < 1e-9 for x in mine), (k, e, mine)
    assert abs(r / (e["ours_cost"] / e["peer_cost"]) - 1) < 1e-12, e
    assert abs(e["evals_ratio"] * e["per_eval_ratio"] / r - 1) < 1e-12, e
PY
grep -q "Fastest plugin method at equal error" "$work/out" "$work/err" && ok || bad "the printed verdict has no plugin table"
"$bin" ratios --study "$work/timed.h5" >"$work/ratios" 2>&1 || bad "ratios: $(cat "$work/ratios")"
grep -q "Step cost, the example plugin RK4" "$work/ratios" && ok || bad "ratios prints no plugin step cost: $(cat "$work/ratios")"

# A bad plugin: one line, exit 2, no study.
"$bench" --plugin="$work/none.so" --quick --problem=pendulum --study_out="$work/never.h5" >/dev/null 2>"$work/err"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && grep -q "none.so" "$work/err" && [ ! -e "$work/never.h5" ] \
  && ok || bad "a missing plugin file: exit $rc, $(cat "$work/err")"

finish plugin_bench_test
