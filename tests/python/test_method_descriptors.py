"""The methods' descriptors against what their runs do: a method that declares its force
evaluations a step (`stepbench list --json`, `evals_per_step`) makes that many a step in
a run, the first step's start aside (a method that reuses its last force evaluates it
once before the first step)."""
import json
import subprocess

import pytest


def list_methods(stepbench):
    out = subprocess.run([stepbench, "list", "--json"], capture_output=True, text=True, check=True).stdout
    return json.loads(out)["methods"]


def test_declared_evaluations_a_step_are_made(stepbench):
    checked = []
    for m in list_methods(stepbench):
        if m["evals_per_step"] is None or m["kind"] != "fixed_step":
            continue
        run = subprocess.run(
            [stepbench, "run", "--problem", "pendulum", "--integrator", m["name"], "--dt", "0.01", "--json"],
            capture_output=True, text=True, check=True)
        r = json.loads(run.stdout)
        per_step = m["evals_per_step"]
        assert per_step * r["steps"] <= r["force_evals"] <= per_step * r["steps"] + 1, (m["name"], r)
        checked.append(m["name"])
    # Every fixed-step method of ours with a constant count, the Odeint and baseline peers.
    for name in ("euler", "semi_implicit_euler", "midpoint", "rk4", "momentum", "forest_ruth", "rk8",
                 "baseline_rk4", "baseline_rk8"):
        assert name in checked
    assert len(checked) >= 9


@pytest.mark.parametrize("name", ["velocity_verlet", "implicit_euler", "implicit_midpoint"])
def test_counts_that_depend_on_the_problem_are_not_declared(stepbench, name):
    # velocity Verlet makes 1 or 2 a step with the force's velocity dependence; an
    # implicit method as many as its Newton solve takes.
    m = next(m for m in list_methods(stepbench) if m["name"] == name)
    assert m["evals_per_step"] is None
