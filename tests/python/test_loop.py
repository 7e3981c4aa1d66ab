"""The game-loop study as its readers meet it (docs/study-format.md, `/loop`): the
default study holds it for pendulum and damped_spring with rk4 and semi_implicit_euler;
`stepbench loop` runs one configuration (--json) or a pair's whole study into a study
file; bad input is one line and exit 2; the report draws and tabulates what the file
holds. The cheapest-design rule is written a second time here, as a cross-check of the
C++ (study/loop.cpp)."""
import json
import math
import os
import subprocess
import sys

import h5py
import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RUN_FIELDS = ["design", "clock", "display_hz", "physics_hz", "dt", "substeps", "clamp_s", "jitter_seed", "stall_at_s",
              "frames", "physics_steps", "force_evals", "shown_err_max", "shown_err_rms", "final_shown_err",
              "clock_dependence", "physics_clock_dependence", "judder", "lag_s", "lag_clock_s",
              "steps_per_frame_mean", "steps_per_frame_max", "stall_burst_steps", "clamp_hits", "alpha_min",
              "alpha_max", "physics_t", "diverged", "note", "step_cost_ns", "frame_budget_ns", "worst_frame_work_ns",
              "late_frames", "physics_load", "outcome", "outcome_without_clamp", "clamp_prevented_spiral"]
DESIGNS = ["variable", "fixed", "interpolated", "substeps"]


def text(v):
    return v.decode() if isinstance(v, bytes) else v


def decoded(rows):
    out = {n: rows[n] for n in rows.dtype.names}
    for n in ("design", "clock", "note", "outcome", "outcome_without_clamp"):
        if n in out:
            out[n] = np.array([text(v) for v in rows[n]])
    return out


@pytest.fixture(scope="module")
def plain(plain_study):
    with h5py.File(plain_study, "r") as f:
        yield f


def loop(stepbench, *args):
    return subprocess.run([stepbench, "loop", *args], capture_output=True, text=True, timeout=120)


def test_layout(plain):
    g = plain["loop"]
    for key in ["designs", "display_hz", "physics_hz", "reference_display_hz", "clamp_s", "stall_s",
                "stall_at_fraction", "jitter", "jitter_seed", "jitter_distribution", "accumulator_slack", "target",
                "stated_step_cost_ns", "spiral_factor", "settle_frames", "wall_seconds"]:
        assert key in g.attrs, key
    assert text(g.attrs["designs"]) == ",".join(DESIGNS)
    assert g.attrs["clamp_s"] == 0.25 and g.attrs["stall_s"] == 1.0
    assert g.attrs["wall_seconds"] > 0
    assert set(g) == {"pendulum", "damped_spring"}
    clocks = len(g.attrs["display_hz"]) + 3  # constant rates, jitter, stall with and without the clamp
    for pname, pg in g.items():
        assert text(pg.attrs["position_unit"]) == ("rad" if pname == "pendulum" else "m")
        assert pg.attrs["horizon"] == pytest.approx(plain["problems"][pname].attrs["horizon"])
        assert set(pg) == {"rk4", "semi_implicit_euler"}
        for mg in pg.values():
            assert text(mg.attrs["step_cost_source"]) == "stated"  # a plain sweep has no timings
            assert mg.attrs["step_cost_ns"] == g.attrs["stated_step_cost_ns"]
            runs = mg["runs"][()]
            assert list(runs.dtype.names) == RUN_FIELDS
            assert len(runs) == clocks * (1 + 3 * len(g.attrs["physics_hz"]))
            assert mg["final_physics_state"].shape == (len(runs), 2)
            assert set(mg["cheapest"].dtype.names) >= {"display_hz", "target", "found", "design", "physics_hz",
                                                       "steps_per_frame_mean", "shown_err_max"}


def test_what_the_runs_show(plain):
    for pname, pg in plain["loop"].items():
        for mname, mg in pg.items():
            r = decoded(mg["runs"][()])
            acc = np.isin(r["design"], ["fixed", "interpolated"])
            # The accumulator loop's physics is independent of the clock, to the bit.
            assert (r["physics_clock_dependence"][acc] == 0).all(), (pname, mname)
            finals = mg["final_physics_state"][()]
            for d in ("fixed", "interpolated"):
                for rate in np.unique(r["physics_hz"][acc]):
                    sel = (r["design"] == d) & (r["physics_hz"] == rate)
                    assert (finals[sel] == finals[sel][0]).all()
            # Interpolation never extrapolates, and shows the past by one step (rk4's own error is far smaller).
            assert (r["alpha_min"][acc] >= 0).all() and (r["alpha_max"][acc] < 1).all()
            assert np.isnan(r["alpha_min"][~acc]).all()
            if mname == "rk4":
                interp = (r["design"] == "interpolated") & (r["clock"] == "constant")
                assert np.allclose(r["lag_s"][interp], r["dt"][interp], rtol=0.02)
            # The variable loop depends on the clock.
            var = (r["design"] == "variable") & (r["clock"] == "constant") & (r["display_hz"] != 60)
            assert (r["clock_dependence"][var] > 0).all()
            # The clamp bounds the stall's burst to ceil(clamp / dt); without it the whole second.
            stall = acc & (r["clock"] == "stall")
            on, off = stall & (r["clamp_s"] > 0), stall & (r["clamp_s"] == 0)
            assert (r["stall_burst_steps"][on] <= np.ceil(0.25 / r["dt"][on])).all()
            assert (r["steps_per_frame_max"][on] <= np.ceil(0.25 / r["dt"][on])).all()
            assert (r["stall_burst_steps"][off] >= np.floor(1.0 / r["dt"][off] - 1e-6)).all()
            assert (r["clamp_hits"][on] == 1).all() and (r["clamp_hits"][off] == 0).all()
            # At a stated 1 us a step nothing overruns a frame.
            assert (r["outcome"] == "keeps_up").all() and (r["late_frames"] == 0).all()


def test_cheapest_follows_its_rule(plain):
    """The documented rule, computed again from the runs."""
    order = {"fixed": 0, "interpolated": 1, "substeps": 2, "variable": 3}
    for pg in plain["loop"].values():
        for mg in pg.values():
            r = decoded(mg["runs"][()])
            for c in mg["cheapest"][()]:
                ok = ((r["clock"] == "constant") & (r["display_hz"] == c["display_hz"]) & (r["diverged"] == 0)
                      & (r["shown_err_max"] <= c["target"]))
                assert bool(c["found"]) == bool(ok.any())
                if not ok.any():
                    continue
                best = min(np.flatnonzero(ok), key=lambda i: (r["steps_per_frame_mean"][i], r["shown_err_max"][i],
                                                               order[r["design"][i]]))
                assert text(c["design"]) == r["design"][best]
                assert c["steps_per_frame_mean"] == r["steps_per_frame_mean"][best]
                assert c["shown_err_max"] == r["shown_err_max"][best]


def test_readme_table_cases_are_there(plain):
    """The README's table: 60 Hz display, each design, rk4 and semi_implicit_euler, 50 / 60 / 100 / 120 Hz."""
    for pname in ("pendulum", "damped_spring"):
        for mname in ("rk4", "semi_implicit_euler"):
            r = decoded(plain[f"loop/{pname}/{mname}/runs"][()])
            const60 = (r["clock"] == "constant") & (r["display_hz"] == 60)
            for design in DESIGNS:
                rates = [math.nan] if design == "variable" else [50, 60, 100, 120]
                for rate in rates:
                    sel = const60 & (r["design"] == design)
                    if design != "variable":
                        sel &= r["physics_hz"] == rate
                    assert sel.sum() == 1 and np.isfinite(r["shown_err_max"][sel]).all(), (pname, mname, design, rate)
            c = plain[f"loop/{pname}/{mname}/cheapest"][()]
            assert (c["display_hz"] == 60).sum() == 1


def test_one_configuration_json(stepbench, plain):
    p = loop(stepbench, "--problem", "pendulum", "--integrator", "rk4", "--design", "fixed", "--display-hz", "144",
             "--physics-hz", "60", "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    for key in ["final_physics_position", "final_physics_velocity", "final_physics_t", "shown_err_max",
                "shown_err_rms", "clock_dependence", "physics_clock_dependence", "judder", "lag_s", "lag_clock_s",
                "steps_per_frame_mean", "steps_per_frame_max", "stall_burst_steps", "alpha_min", "alpha_max", "cost"]:
        assert key in d, key
    assert d["cost"]["outcome"] == "keeps_up"
    # The same configuration as the study's row, the same figures.
    r = decoded(plain["loop/pendulum/rk4/runs"][()])
    sel = np.flatnonzero((r["design"] == "fixed") & (r["clock"] == "constant") & (r["display_hz"] == 144)
                         & (r["physics_hz"] == 60))
    assert len(sel) == 1
    i = sel[0]
    assert d["shown_err_max"] == r["shown_err_max"][i] and d["judder"] == r["judder"][i]
    assert d["final_physics_position"] == [plain["loop/pendulum/rk4/final_physics_state"][i, 0]]
    assert d["physics_clock_dependence"] == 0


def test_jitter_reproduces_and_the_clock_decides_variable(stepbench):
    args = ["--problem", "damped_spring", "--integrator", "semi_implicit_euler", "--json"]
    a = loop(stepbench, *args, "--design", "interpolated", "--physics-hz", "100", "--jitter", "7")
    b = loop(stepbench, *args, "--design", "interpolated", "--physics-hz", "100", "--jitter", "7")
    assert a.returncode == 0 and a.stdout == b.stdout
    fixed = [json.loads(loop(stepbench, *args, "--design", "fixed", "--display-hz", hz).stdout)["final_physics_position"]
             for hz in ("30", "144")]
    variable = [json.loads(loop(stepbench, *args, "--design", "variable", "--display-hz", hz).stdout)[
        "final_physics_position"] for hz in ("30", "144")]
    assert fixed[0] == fixed[1]
    assert variable[0] != variable[1]


def test_spiral_and_the_clamp(stepbench):
    """A step costing more than the simulated time it advances: without the clamp the loop spirals."""
    args = ["--problem", "damped_spring", "--integrator", "rk4", "--design", "fixed", "--physics-hz", "60",
            "--stall-at", "5", "--step-cost", str(1.5e9 / 60), "--json"]
    on = json.loads(loop(stepbench, *args).stdout)["cost"]
    off = json.loads(loop(stepbench, *args, "--clamp", "off").stdout)["cost"]
    assert on["outcome"] == "slow_motion" and on["clamp_prevented_spiral"] is True
    assert off["outcome"] == "spiral"


@pytest.mark.parametrize("args, message", [
    (["--design", "fixed", "--display-hz", "0"], "--display-hz must be > 0"),
    (["--design", "fixed", "--display-hz=-60"], "--display-hz must be > 0"),
    (["--design", "fixed", "--physics-hz", "0"], "--physics-hz must be > 0"),
    (["--design", "fixed", "--physics-hz", "100", "--clamp", "0.005"], "below the physics dt"),
    (["--design", "fixed", "--clamp", "0"], "--clamp must be a time > 0 or off"),
    (["--design", "fixed", "--stall-at", "9.5"], "longer than the run"),
    (["--design", "fixed", "--stall-at", "20"], "longer than the run"),
    (["--design", "sideways"], "unknown --design 'sideways'"),
    (["--design", "fixed", "--jitter", "x"], "--jitter must be a seed"),
    (["--design", "fixed", "--display-hz", "abc"], "--display-hz must be a finite number"),
    (["--display-hz", "60"], "--display-hz applies to one configuration"),
    (["--design", "fixed", "--out", "x.h5"], "--out writes the whole loop study"),
])
def test_bad_input(stepbench, tmp_path, args, message):
    p = subprocess.run([stepbench, "loop", "--problem", "damped_spring", "--integrator", "rk4", *args],
                       capture_output=True, text=True, cwd=tmp_path)
    assert p.returncode == 2, (p.returncode, p.stderr)
    assert p.stderr.count("\n") == 1 and message in p.stderr, p.stderr
    assert p.stdout == ""


@pytest.mark.parametrize("method, message", [("rk45", "rk45 is adaptive"), ("gsl_rk4", "gsl_rk4 is a peer method")])
def test_only_our_fixed_step_methods(stepbench, method, message):
    p = loop(stepbench, "--problem", "pendulum", "--integrator", method, "--design", "fixed")
    assert p.returncode == 2 and message in p.stderr and p.stderr.count("\n") == 1, p.stderr


def test_pair_study_into_a_study_file(stepbench, tmp_path):
    out = tmp_path / "vv.h5"
    p = loop(stepbench, "--problem", "damped_spring", "--integrator", "velocity_verlet", "--out", str(out))
    assert p.returncode == 0, p.stderr
    assert "cheapest under 0.001 m" in p.stdout
    with h5py.File(out) as f:
        assert list(f["loop"]) == ["damped_spring"] and list(f["loop/damped_spring"]) == ["velocity_verlet"]
        assert list(f["problems"]) == ["damped_spring"]
        assert list(f["problems/damped_spring/methods"]) == ["velocity_verlet"]
    # The report reads it (its section and figure, drawn from the file).
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    try:
        from stepbench_report import figures, loop as loop_section, render, study
        s = study.load(str(out))
        assert [p.name for p in s.loop.problems] == ["damped_spring"]
        doc = render.Doc("t")
        loop_section.section(doc, s, {"loop_shown_error.png"})
        md = render.markdown(doc)
        assert "velocity_verlet" in md and "fig/loop_shown_error.png" in md
        loop_section.figure(s.loop, figures.Styles(s), str(tmp_path / "loop.png"))
        assert (tmp_path / "loop.png").stat().st_size > 10_000
    finally:
        sys.path.pop(0)
