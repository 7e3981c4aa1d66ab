#!/usr/bin/env bash
# One answer (issue 32): `scan` and `advise --hz` rank one scene alike. On the default rope
# at 60 Hz and 1 mm, a scan of its one point ranked by the timed study's ns per force
# evaluation names the method and substeps `advise` reads from that study's frame-rate
# runs, at the same cost a frame; a rate or a scene the study lacks is run by `advise`
# itself, by the same rule, and says so.
set -u
bin=${1:?usage: one_answer_test.sh path/to/stepbench path/to/timed-study.h5 [path/to/stepbench_bench]}
timed=${2:?usage: one_answer_test.sh path/to/stepbench path/to/timed-study.h5 [path/to/stepbench_bench]}
bench=${3:-}
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

"$bin" advise --study "$timed" --problem spring_chain --hz 60 --tol 1e-3 --json >"$work/advise.json" ||
  bad "advise --hz 60 on the timed study exited $?"
"$bin" scan --problem spring_chain --hz 60 --tol 1e-3 --costs "$timed" --quiet --json --out "$work/scan.h5" \
  >"$work/scan.json" || bad "scan of the default rope exited $?"
/usr/bin/python3 - "$work/advise.json" "$work/scan.json" "$timed" <<'PY' && ok || bad "scan and advise disagree"
import json, sys
advise, scan = (json.load(open(p)) for p in sys.argv[1:3])
a, c = advise["choice"], scan["choices"][0]
assert advise["cost_kind"] == "time_ns" and scan["cost_kind"] == "time_ns", (advise["cost_kind"], scan["cost_kind"])
assert scan["cost_source"] == sys.argv[3], scan["cost_source"]
assert (c["method"], c["substeps"]) == (a["method"], a["substeps"]), (c, a)
# The same cost a frame: ns per evaluation x evaluations a frame against ns per step x
# steps a frame (a fixed-step explicit method takes the same evaluations every step).
assert abs(c["max_cost_per_frame"] / a["cost_per_frame"] - 1) < 1e-9, (c, a)
assert c["worst_err_pos_max"] == a["err_pos_max"] or abs(c["worst_err_pos_max"] / a["err_pos_max"] - 1) < 1e-6, (c, a)
assert "masses = 32," in scan["range"], scan["range"]  # the answer names the scene
PY

# The README's summary (stepbench summary) quotes the same answer: the study's verdict tables.
"$bin" summary --study "$timed" --out - >"$work/summary.json" || bad "summary exited $?"
/usr/bin/python3 - "$work/advise.json" "$work/summary.json" <<'PY' && ok || bad "summary and advise disagree"
import json, sys
advise, summary = (json.load(open(p)) for p in sys.argv[1:3])
rope = next(p for p in summary["problems"] if p["name"] == "spring_chain")
(s,) = [x for x in rope["answers"] if x["target"] == 1e-3]
a = advise["choice"]
assert (s["method"], s["substeps"], s["cost_per_frame"]) == (a["method"], a["substeps"], a["cost_per_frame"]), (s, a)
assert summary["hz"] == 60 and summary["study"]["cost_kind"] == advise["cost_kind"] == "time_ns", summary["study"]
assert rope["methods_at_one_step"] == len(advise["one_step"]), rope
assert rope["stable_at_one_step"] == sum(o["completed"] for o in advise["one_step"]), (rope, advise["one_step"])
PY

# Untimed (no costs): the scan ranks by force evaluations and says so.
"$bin" scan --problem spring_chain --hz 60 --tol 1e-3 --costs none --quiet --json --out "$work/none.h5" |
  /usr/bin/python3 -c '
import json, sys
d = json.load(sys.stdin)
assert d["cost_kind"] == "force_evals" and d["cost_source"] == "" and d["ns_per_force_eval"] == {}, d
c = d["choices"][0]
assert c["max_cost_per_frame"] == c["max_force_evals_per_frame"], c
' && ok || bad "scan --costs none ranks by force evaluations"

# A rate the study lacks: advise runs it, says why on stderr, and answers by the same rule.
"$bin" advise --study "$timed" --problem n_pendulum --hz 144 --tol 1e-3 --json >"$work/144.json" 2>"$work/144.err" ||
  bad "advise --hz 144 exited $?: $(cat "$work/144.err")"
grep -q "ran n_pendulum at 30, 60, 120, 240 Hz only: running n_pendulum's frame-rate runs at 144 Hz here" \
  "$work/144.err" && ok || bad "advise --hz 144 stderr: $(cat "$work/144.err")"
/usr/bin/python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
c = d["choices"][0]
assert c["hz"] == 144 and c["method"] and 0 < c["worst_err_pos_max"] <= 1e-3, d
' "$work/144.json" && ok || bad "advise --hz 144 answer: $(cat "$work/144.json")"

# A scene the study did not run: the default's answer (velocity_verlet x16) misses 1 mm on a
# rope of 64 masses; advise --set runs that rope and answers with what holds there.
"$bin" advise --study "$timed" --problem spring_chain --hz 60 --tol 1e-3 --set spring_chain.masses=64 --json \
  >"$work/64.json" 2>"$work/64.err" || bad "advise --set masses=64 exited $?: $(cat "$work/64.err")"
"$bin" scan --problem spring_chain --hz 60 --set spring_chain.masses=64 --substeps 16 --integrator velocity_verlet \
  --costs none --quiet --out "$work/64.h5" >/dev/null || bad "scan of 64 masses exited $?"
/usr/bin/python3 - "$work/64.json" "$work/64.h5" <<'PY' && ok || bad "advise --set masses=64"
import json, sys
import h5py
d = json.load(open(sys.argv[1]))
assert "masses = 64 (set)" in d["range"], d["range"]
c = d["choices"][0]
assert c["method"] and c["worst_err_pos_max"] <= 1e-3, c
with h5py.File(sys.argv[2]) as f:
    (run,) = f["scan/spring_chain/runs"][:]
    assert run["substeps"] == 16 and run["err_pos_max"] > 1e-3, run  # the default's answer misses it here
assert (c["method"], c["substeps"]) != ("velocity_verlet", 16), c
PY

# --time: the rope of 64 masses at 144 Hz, ranked by each method's time a force evaluation
# measured on that rope here (a longer rope's evaluation costs more than the study's 32-mass
# one: the cost is of this scene), and said so; without --hz, --time is refused.
"$bin" advise --study "$timed" --problem spring_chain --hz 144 --tol 1e-3 --set spring_chain.masses=64 --time --json \
  >"$work/time.json" 2>"$work/time.err" || bad "advise --time exited $?: $(cat "$work/time.err")"
grep -q "^--time: timed each method's force evaluation on this scene here" "$work/time.err" && ok ||
  bad "advise --time stderr: $(cat "$work/time.err")"
/usr/bin/python3 - "$work/time.json" "$work/64.json" <<'PY' && ok || bad "advise --time answer"
import json, sys
d, untimed = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert d["cost_kind"] == "time_ns" and d["cost_source"] == "timed here on this scene (advise --time)", d
c = d["choices"][0]
assert c["hz"] == 144 and c["method"] and 0 < c["worst_err_pos_max"] <= 1e-3, c
ns = d["ns_per_force_eval"]
assert set(ns) >= {"rk4", "velocity_verlet", "semi_implicit_euler"} and all(v > 0 for v in ns.values()), ns
# The cost a frame is the counted evaluations times the evaluation's measured time.
assert abs(c["max_cost_per_frame"] - c["max_force_evals_per_frame"] * ns[c["method"]]) <= 1e-9 * c["max_cost_per_frame"], c
PY
"$bin" advise --study "$timed" --problem pendulum --tol 1e-3 --time >/dev/null 2>"$work/t.err"
[ $? -eq 2 ] && [ "$(wc -l <"$work/t.err")" -eq 1 ] && grep -q "give --hz" "$work/t.err" && ok ||
  bad "advise --time without --hz: $(cat "$work/t.err")"

# A timed study that timed rk4 alone on the stiff spring: the scan ranks rk4 by it and names
# the methods it cannot rank (no measured cost), instead of dropping them unseen.
if [ -n "$bench" ]; then
  "$bench" --quick --problem=stiff_spring --benchmark_filter='^stiff_spring/rk4/' --study_out="$work/rk4.h5" \
    >/dev/null 2>&1 || bad "the rk4-only timed study exited $?"
  "$bin" scan --problem stiff_spring --hz 60 --tol 1e-3 --costs "$work/rk4.h5" --quiet --json --out "$work/k.h5" |
    /usr/bin/python3 -c '
import json, sys
d = json.load(sys.stdin)
assert list(d["ns_per_force_eval"]) == ["rk4"] and d["cost_kind"] == "time_ns", d
assert "velocity_verlet" in d["uncosted"] and "rk4" not in d["uncosted"], d["uncosted"]
assert d["choices"][0]["method"] in (None, "rk4"), d["choices"]
' && ok || bad "scan --costs with rk4 alone timed"
fi

finish one_answer
