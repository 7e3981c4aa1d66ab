"""One --set grammar for every command and the benchmark: `P.name=value` everywhere, a
name wherever a number is accepted, and every command given the same --set runs the same
scene (the same closed-form truth at the horizon, the same declared parameters in the
study file)."""
import json
import math
import os
import subprocess

import h5py
import numpy as np
import pytest
from scipy.special import ellipk


def text(v):
    return v.decode() if isinstance(v, bytes) else v


def run_cli(stepbench, *args):
    return subprocess.run([stepbench, *args], capture_output=True, text=True, timeout=600)


def parameters(path, problem):
    with h5py.File(path, "r") as f:
        table = f[f"problems/{problem}/parameters"][()]
        truth = f[f"problems/{problem}/truth_state"][()]
        horizon = float(f[f"problems/{problem}"].attrs["horizon"])
    return {text(r["name"]): (float(r["value"]), text(r["value_name"])) for r in table}, truth, horizon


@pytest.fixture(scope="module")
def bench(stepbench):
    return os.path.join(os.path.dirname(stepbench), "stepbench_bench")


# Each scene with the --set that changes it and a fixed-step method that runs on it.
SCENES = [("pendulum", "pendulum.theta0_deg=150", "theta0_deg", 150.0, ""),
          ("sliding_block", "sliding_block.material=steel_on_steel", "material", None, "steel_on_steel")]


@pytest.mark.parametrize("problem,assignment,param,value,value_name", SCENES)
def test_every_command_runs_the_same_scene(stepbench, bench, tmp_path, problem, assignment, param, value,
                                           value_name):
    # `run`: the truth at the horizon.
    r = run_cli(stepbench, "run", "--problem", problem, "--integrator", "rk4", "--dt", "0.01", "--set", assignment,
                "--json")
    assert r.returncode == 0, r.stderr
    ran = json.loads(r.stdout)
    # The unqualified form is the same scene where one problem is selected.
    short = run_cli(stepbench, "run", "--problem", problem, "--integrator", "rk4", "--dt", "0.01", "--set",
                    assignment.split(".", 1)[1], "--json")
    assert short.returncode == 0, short.stderr
    assert json.loads(short.stdout)["true_position"] == ran["true_position"]

    # `sweep` and the benchmark: the declared parameter in the study file, and the same truth.
    sweep_out = tmp_path / "sweep.h5"
    r = run_cli(stepbench, "sweep", "--problem", problem, "--integrator", "rk4", "--levels", "2", "--quiet",
                "--set", assignment, "--out", str(sweep_out))
    assert r.returncode == 0, r.stderr
    bench_out = tmp_path / "bench.h5"
    r = subprocess.run([bench, f"--problem={problem}", f"--set={assignment}", "--quick",
                        f"--benchmark_filter=^{problem}/rk4/", f"--study_out={bench_out}"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    for path in (sweep_out, bench_out):
        params, truth, horizon = parameters(path, problem)
        got, got_name = params[param]
        if value is not None:
            assert got == value
        assert got_name == value_name
        assert horizon == pytest.approx(ran["horizon"], rel=1e-15)
        dim = len(ran["true_position"])
        np.testing.assert_allclose(truth[-1][:dim], ran["true_position"], rtol=1e-13, atol=1e-15)

    # `loop`: the game loop's study of the same scene.
    loop_out = tmp_path / "loop.h5"
    r = run_cli(stepbench, "loop", "--problem", problem, "--integrator", "semi_implicit_euler", "--quiet",
                "--set", assignment, "--out", str(loop_out))
    assert r.returncode == 0, r.stderr
    params, truth, horizon = parameters(loop_out, problem)
    assert params[param][1] == value_name and (value is None or params[param][0] == value)


def test_energy_takes_the_same_set(stepbench):
    """`energy` on the pendulum released at 150 deg: its period is the closed form's,
    4 K(k) / omega0 with k = sin(75 deg)."""
    r = run_cli(stepbench, "energy", "--problem", "pendulum", "--periods", "2", "--set",
                "pendulum.theta0_deg=150", "--json")
    assert r.returncode == 0, r.stderr
    rows = json.loads(r.stdout)
    k = math.sin(math.radians(75.0))
    period = 4.0 * ellipk(k * k) / math.sqrt(9.8)
    assert rows and all(row["dt"] * row["steps_per_period"] == pytest.approx(period, rel=1e-12) for row in rows)


@pytest.mark.parametrize("args", [
    ["run", "--problem", "sliding_block", "--integrator", "rk4", "--dt", "0.01"],
    ["sweep", "--problem", "sliding_block", "--levels", "2", "--out", "/nonexistent/never.h5"],
    ["loop", "--problem", "sliding_block", "--integrator", "rk4", "--out", "/nonexistent/never.h5"],
])
def test_an_unknown_name_lists_the_valid_ones(stepbench, args):
    r = run_cli(stepbench, *args, "--set", "sliding_block.material=unobtainium")
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "unobtainium" in r.stderr and "steel_on_steel" in r.stderr and "rubber_on_concrete" in r.stderr


def test_bench_refuses_like_the_commands(bench):
    r = subprocess.run([bench, "--set=sliding_block.material=unobtainium", "--benchmark_list_tests"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "steel_on_steel" in r.stderr, r.stderr


def test_unqualified_needs_one_problem(stepbench, bench):
    r = run_cli(stepbench, "sweep", "--set", "theta0_deg=90", "--out", "/nonexistent/never.h5")
    assert r.returncode == 2 and "name the problem" in r.stderr, r.stderr
    r = run_cli(stepbench, "sweep", "--problem", "pendulum", "--problem", "kepler", "--set", "theta0_deg=90",
                "--out", "/nonexistent/never.h5")
    assert r.returncode == 2 and "2 problems are selected" in r.stderr, r.stderr
    r = subprocess.run([bench, "--set=theta0_deg=90", "--benchmark_list_tests"], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 2 and "name the problem" in r.stderr, r.stderr
