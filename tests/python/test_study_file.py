"""The study file as its readers meet it (docs/study-format.md, format 2): h5py reads the
documented layout, the numbers in it are the ones the run computed, and the derived
tables (`equal_error`, `front_*`) follow the documented rules. Those rules are written
a second time here, as a cross-check of the C++ (core/work_precision.cpp); the report
itself only reads the tables."""
import json
import math
import subprocess

import h5py
import numpy as np
import pytest

RUN_FIELDS = ["param", "steps", "rejected_steps", "force_evals", "jacobian_evals", "newton_iterations",
              "linear_solves", "err_pos_final", "err_vel_final", "err_pos_max", "err_pos_rms", "energy_drift",
              "energy_err_max", "angmom_drift", "angmom_err_max", "constraint_violation_max", "contacts", "contact_count_err", "contact_time_err",
              "contact_pos_err", "tunnelled", "max_penetration", "diverged", "failed", "skipped", "note"]
TIMED_FIELDS = ["time_ns", "time_ns_min", "time_ns_max", "repetitions", "cut"]
ROOT_ATTRS = ["format_version", "version", "git_commit", "compiler", "build_type", "dependencies", "created_utc",
              "cpu", "cores", "levels", "base_steps", "tolerances", "sample_count", "reference_rtol",
              "reference_atol", "fit_metric", "divergence_factor", "equal_error_targets", "wall_seconds", "timing"]
METHOD_ATTRS = ["origin", "kind", "param_kind", "declared_order", "description", "library", "symplectic",
                "reuses_last_force", "needs_jacobian", "error_estimate", "dense_output", "fit_status", "fit_metric",
                "fit_param", "fit_slope", "observed_order", "fit_levels", "fit_residual_log10", "fit_note",
                "exact_for_problem", "declared_order_holds", "ladder_end"]


@pytest.fixture(scope="module")
def plain(plain_study):
    with h5py.File(plain_study, "r") as f:
        yield f


@pytest.fixture(scope="module")
def timed(timed_study):
    with h5py.File(timed_study[0], "r") as f:
        yield f


@pytest.fixture(scope="module")
def listing(stepbench):
    return json.loads(subprocess.run([stepbench, "list", "--json"], check=True, capture_output=True,
                                     text=True).stdout)


def text(v):
    return v.decode() if isinstance(v, bytes) else v


def test_root_attributes(plain):
    for key in ROOT_ATTRS:
        assert key in plain.attrs, key
    assert plain.attrs["format_version"] == 4 and plain.attrs["timing"] == 0
    assert plain.attrs["levels"] == 8  # --quick
    assert "GSL" in plain.attrs["dependencies"] and "SUNDIALS" in plain.attrs["dependencies"]
    for target in (1e-2, 1e-4, 1e-6):
        assert np.isclose(plain.attrs["equal_error_targets"], target, rtol=1e-12).any()


def test_every_problem_and_method(plain, listing):
    tolerances = plain.attrs["tolerances"]
    for p in listing["problems"]:
        g = plain["problems"][p["name"]]
        # The declared parameters in one table, exactly those `list` declares, and no
        # parameter among the derived attributes.
        table = g["parameters"][()]
        assert [text(n) for n in table["name"]] == [q["name"] for q in p["parameters"]]
        for row, param in zip(table, p["parameters"]):
            assert row["value"] == pytest.approx(param["default"]) and row["default"] == row["value"]
            assert text(row["unit"]) == param["unit"] and text(row["kind"]) == param["kind"]
            assert text(row["allowed"]) == param["allowed"]
            assert param["name"] not in g.attrs
        assert g.attrs["horizon"] == pytest.approx(p["horizon"])
        assert g.attrs["position_unit"] == p["position_unit"]
        assert set(g["reference"]) == {"gsl_rk8pd", "cvode_bdf", "cvode_adams", "arkode_erk8"}
        for src, ref in g["reference"].items():
            status = ref.attrs["status"]
            # Where a closed form is the truth a reference may fail, disagree or not apply (no
            # root finding to stop at contacts); on these scenes every one agrees.
            if p["name"] in ("constant_acceleration", "projectile", "damped_spring", "pendulum", "stiff_spring",
                             "spring_chain"):
                assert status == "ok", (p["name"], src)
            else:
                assert status in ("ok", "disagrees", "failed", "unsupported"), (p["name"], src, status)
            if status in ("ok", "disagrees"):
                assert ref["position"].shape == (p["dim"],) and ref["velocity"].shape == (p["dim"],)
            for stat in ["steps", "failed_steps", "rhs_evals", "lin_rhs_evals", "rhs_evals_counted"]:
                assert stat in ref.attrs
        assert set(g["methods"]) == set(p["methods"])
        described = {m["name"]: m for m in listing["methods"]}
        for name in p["methods"]:
            m = g["methods"][name]
            for key in METHOD_ATTRS:
                assert key in m.attrs, (p["name"], name, key)
            assert m.attrs["origin"] == described[name]["origin"]
            assert m.attrs["kind"] == described[name]["kind"]
            runs = m["runs"][()]
            assert list(runs.dtype.names) == RUN_FIELDS
            if m.attrs["kind"] == "fixed_step":
                assert m.attrs["param_kind"] == "dt" and len(runs) == 8
                np.testing.assert_allclose(runs["param"][:-1], 2 * runs["param"][1:])
            else:
                assert m.attrs["param_kind"] == "tolerance"
                np.testing.assert_array_equal(runs["param"], tolerances)
    # The hand-written baseline runs where it applies, and only there.
    assert [m["origin"] for m in listing["methods"] if m["name"] == "baseline_rk4"] == ["baseline"]


def test_timed_rows_carry_timings(timed):
    assert timed.attrs["timing"] == 1
    runs = timed["problems/damped_spring/methods/rk4/runs"][()]
    assert list(runs.dtype.names) == RUN_FIELDS + TIMED_FIELDS
    assert set(timed["problems/pendulum"]) >= {"equal_error", "front_force_evals", "front_time"}


@pytest.mark.parametrize("method, args", [("midpoint", ["--dt"]), ("gsl_rk4", ["--dt"]), ("cvode_bdf", ["--tol"])])
def test_rows_match_stepbench_run(plain, stepbench, method, args):
    """A row of the study file is what `stepbench run` prints for the same case, for ours
    and for peers, fixed-step and adaptive alike: one code measures them all."""
    row = plain[f"problems/pendulum/methods/{method}/runs"][()][3]
    out = json.loads(subprocess.run(
        [stepbench, "run", "--problem", "pendulum", "--method", method, *args, repr(float(row["param"])), "--json"],
        check=True, capture_output=True, text=True).stdout)
    for key in ["steps", "force_evals", "rejected_steps", "jacobian_evals"]:
        assert out[key] == row[key], key
    for key in ["err_pos_final", "err_vel_final", "err_pos_max", "err_pos_rms", "energy_drift"]:
        assert out[key] == pytest.approx(float(row[key]), rel=1e-9), key


def test_exact_methods_have_nan_order(plain):
    g = plain["problems/constant_acceleration/methods/rk4"]
    assert g.attrs["exact_for_problem"] == 1 and g.attrs["fit_status"] == "exact"
    assert math.isnan(g.attrs["observed_order"])
    assert g.attrs["declared_order_holds"] == -1


def test_fit_levels_recorded(plain):
    g = plain["problems/damped_spring/methods/rk4"]
    assert len(g.attrs["fit_levels"]) >= 3
    assert abs(g.attrs["observed_order"] - 4) < 0.15
    assert g.attrs["declared_order_holds"] == 1


def test_declared_orders_are_checked(plain):
    """GSL's rk2 declares 2 and advances with the third-order member of its pair; an
    adaptive method has no observed order to hold a declaration to."""
    rk2 = plain["problems/pendulum/methods/gsl_rk2"].attrs
    assert rk2["declared_order"] == 2 and abs(rk2["observed_order"] - 3) < 0.1 and rk2["declared_order_holds"] == 0
    bdf = plain["problems/pendulum/methods/cvode_bdf"].attrs
    assert math.isnan(bdf["observed_order"]) and bdf["declared_order_holds"] == -1


# --- the derived tables, against the documented rules written again --------------------------

def methods_of(g):
    return {name: (text(m.attrs["origin"]), m["runs"][()]) for name, m in g["methods"].items()}


def completed(runs):
    return (runs["diverged"] == 0) & (runs["failed"] == 0) & (runs["skipped"] == 0)


def at_equal_error(runs, target, metric, cost, timed):
    """docs/study-format.md, `equal_error`: the cost at the target interpolated log-log
    between neighbouring rows of the curve that bracket it, never extrapolated; the
    coarsest row when it already meets the target; the cheapest crossing. (cost, error,
    param) or None."""
    err, c = runs[metric], runs[cost].astype(float)
    on = completed(runs) & np.isfinite(err) & (err >= 0) & np.isfinite(c) & (c > 0)
    if timed:
        on &= runs["cut"] == 0
    curve = runs[on]
    if len(curve) == 0:
        return None
    # Every measured row under the target bounds the cost (error 0 included).
    found = [(float(r[cost]), float(r[metric]), float(r["param"])) for r in curve if r[metric] <= target]
    for a, b in zip(curve[:-1], curve[1:]):
        ea, eb = float(a[metric]), float(b[metric])
        if not (min(ea, eb) <= target <= max(ea, eb)) or ea == eb or ea == 0 or eb == 0:
            continue
        s = math.log(target / ea) / math.log(eb / ea)
        lerp = lambda u, v: math.exp(math.log(u) + s * (math.log(v) - math.log(u)))  # noqa: E731
        found.append((lerp(float(a[cost]), float(b[cost])), target, lerp(float(a["param"]), float(b["param"]))))
    return min(found, key=lambda x: x[0]) if found else None


def cheapest_by_the_rule(methods, target, metric, timed):
    """docs/study-format.md, `equal_error`: (cost kind, [(cost, error, method, param)] ranked)."""
    by_time = timed
    for _, runs in methods.values():
        if not timed:
            break
        ok = completed(runs) & np.isfinite(runs[metric]) & (runs[metric] <= target) & (runs["cut"] == 0)
        if not (np.isfinite(runs["time_ns"][ok]) & (runs["time_ns"][ok] > 0)).all():
            by_time = False
    cost = "time_ns" if by_time else "force_evals"
    picks = []
    for name, (_, runs) in methods.items():
        p = at_equal_error(runs, target, metric, cost, timed)
        if p is not None:
            picks.append((p[0], p[1], name, p[2]))
    return cost, sorted(picks)


@pytest.mark.parametrize("shape", ["plain", "timed"])
def test_equal_error_follows_the_rule(plain, timed, shape):
    f = plain if shape == "plain" else timed
    is_timed = shape == "timed"
    for pname, g in f["problems"].items():
        methods = methods_of(g)
        table = g["equal_error"][()]
        for metric in ("err_pos_max", "err_pos_final"):
            for target in f.attrs["equal_error_targets"]:
                rows = table[(np.char.equal(table["metric"].astype(str), metric)) & (table["target"] == target)]
                cost, picks = cheapest_by_the_rule(methods, target, metric, is_timed)
                where = (pname, metric, target)
                assert [text(m) for m in rows["method"]] == [p[2] for p in picks], where
                assert list(rows["rank"]) == list(range(1, len(picks) + 1)), where
                assert all(text(c) == cost for c in rows["cost_kind"]), where
                np.testing.assert_allclose(rows["param"], [p[3] for p in picks], rtol=1e-12)
                np.testing.assert_allclose(rows["cost"], [p[0] for p in picks], rtol=1e-12)
                # The answer: the first ranked method that is not the baseline.
                answers = [text(m) for m, a in zip(rows["method"], rows["is_answer"]) if a]
                first = [p[2] for p in picks if methods[p[2]][0] != "baseline"][:1]
                assert answers == first, where


@pytest.mark.parametrize("shape", ["plain", "timed"])
def test_verdict_is_the_fastest_of_ours_against_the_fastest_peer(plain, timed, shape):
    """/verdict/equal_error: per problem and target, the first of ours and the first peer
    in the problem's equal_error ranking (err_pos_max), their ratio, and ahead/behind only
    beyond the spread."""
    f = plain if shape == "plain" else timed
    v = f["verdict/equal_error"][()]
    assert len(v) == len(f["problems"]) * len(f["verdict"].attrs["targets"])
    for row in v:
        ranked = f[f"problems/{text(row['problem'])}/equal_error"][()]
        ranked = ranked[(ranked["metric"].astype(str) == "err_pos_max") & (ranked["target"] == row["target"])]
        ours = [r for r in ranked if text(r["origin"]) == "ours"][:1]
        peer = [r for r in ranked if text(r["origin"]) == "peer"][:1]
        assert text(row["ours_method"]) == (text(ours[0]["method"]) if ours else "")
        assert text(row["peer_method"]) == (text(peer[0]["method"]) if peer else "")
        if ours and peer:
            assert row["ratio"] == pytest.approx(ours[0]["cost"] / peer[0]["cost"], rel=1e-12)
            assert text(row["cost_kind"]) == text(ours[0]["cost_kind"])
            # The noise band of core/work_precision.hpp (study/compare's timing threshold).
            threshold = 1e-9
            if text(row["cost_kind"]) == "time_ns":
                def spread(r):
                    return (r["cost_hi"] - r["cost_lo"]) / r["cost"] if r["cost_hi"] > r["cost_lo"] else 0.0
                both = all(r["cost_hi"] > r["cost_lo"] for r in (ours[0], peer[0]))
                threshold = max(0.15 if both else 0.25, 3 * max(spread(ours[0]), spread(peer[0])))
            ratio = ours[0]["cost"] / peer[0]["cost"]
            want = "ahead" if ratio < 1 / (1 + threshold) else "behind" if ratio > 1 + threshold else "within spread"
            # The side found dearer charged only an upper bound decides nothing (its true cost may be lower).
            if (want == "ahead" and not peer[0]["interpolated"]) or (want == "behind" and not ours[0]["interpolated"]):
                want = "bounded"
            assert text(row["verdict"]) == want
            assert row["ours_interpolated"] == ours[0]["interpolated"]
            assert row["peer_interpolated"] == peer[0]["interpolated"]
        else:
            assert math.isnan(row["ratio"])
            assert text(row["verdict"]) == ("ours only" if ours else "peers only" if peer else "not reached")


def front_by_the_rule(methods, cost_field, timed):
    """docs/study-format.md, `front_*`: by cost, a row joins if its error beats every
    cheaper row's by more than 1e-6 relative; the baseline is left out."""
    points = []
    for name, (origin, runs) in methods.items():
        if origin == "baseline":
            continue
        for r in runs:
            cost, err = float(r[cost_field]), float(r["err_pos_max"])
            if r["diverged"] or r["failed"] or not np.isfinite(err) or not (np.isfinite(cost) and cost > 0):
                continue
            if timed and r["cut"]:
                continue
            points.append((cost, err, name, float(r["param"])))
    front, best = [], math.inf
    for p in sorted(points, key=lambda p: (p[0], p[1])):
        if p[1] < best * (1 - 1e-6):
            front.append(p)
            best = p[1]
    return front


@pytest.mark.parametrize("shape, front, field", [("plain", "front_force_evals", "force_evals"),
                                                  ("timed", "front_force_evals", "force_evals"),
                                                  ("timed", "front_time", "time_ns")])
def test_fronts_follow_the_rule(plain, timed, shape, front, field):
    f = plain if shape == "plain" else timed
    for pname, g in f["problems"].items():
        want = front_by_the_rule(methods_of(g), field, shape == "timed")
        got = g[front][()]
        # (cost, error) pin a point; two methods may share both exactly (exact methods at
        # equal cost), and the rule does not say which of them is listed.
        assert [(float(r["cost"]), float(r["err_pos_max"])) for r in got] == [(p[0], p[1]) for p in want], pname
        for r in got:
            runs = g["methods"][text(r["method"])]["runs"][()]
            row = runs[runs["param"] == r["param"]]
            assert len(row) == 1 and row[field][0] == r["cost"] and row["err_pos_max"][0] == r["err_pos_max"]
