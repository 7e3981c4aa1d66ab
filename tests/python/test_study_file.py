"""The study file as its readers meet it: h5py reads the documented layout
(docs/study-format.md) and the numbers in it are the ones the run computed."""
import json
import math
import subprocess

import h5py
import numpy as np
import pytest

FIELDS = ["dt", "steps", "force_evals", "err_pos_final", "err_vel_final", "err_pos_max",
          "err_pos_rms", "energy_drift", "energy_err_max", "diverged"]


@pytest.fixture(scope="module")
def study(stepbench, tmp_path_factory):
    path = tmp_path_factory.mktemp("study") / "study.h5"
    subprocess.run([stepbench, "sweep", "--levels", "8", "--quiet", "--out", str(path)], check=True)
    with h5py.File(path, "r") as f:
        yield f


def test_root_attributes(study):
    for key in ["format_version", "version", "git_commit", "compiler", "build_type", "created_utc", "cpu"]:
        assert key in study.attrs, key
    assert study.attrs["levels"] == 8


def test_every_problem_and_integrator(study, stepbench):
    listing = json.loads(subprocess.run([stepbench, "list", "--json"], check=True,
                                        capture_output=True, text=True).stdout)
    for p in listing["problems"]:
        g = study[p["name"]]
        for param in p["parameters"]:
            assert g.attrs[param["name"]] == pytest.approx(param["default"])
        assert g.attrs["horizon"] == pytest.approx(p["horizon"])
        assert set(g["reference"]) == {"gsl_rk8pd", "cvode_bdf", "cvode_adams"}
        for ref in g["reference"].values():
            assert ref["position"].shape == (p["dim"],)
            assert ref["velocity"].shape == (p["dim"],)
            for stat in ["steps", "failed_steps", "rhs_evals", "lin_rhs_evals", "rhs_evals_counted"]:
                assert stat in ref.attrs
        for i in listing["integrators"]:
            ig = g[i["name"]]
            assert ig.attrs["expected_order"] == i["expected_order"]
            conv = ig["convergence"][()]
            assert list(conv.dtype.names) == FIELDS
            assert len(conv) == 8
            np.testing.assert_allclose(conv["dt"][:-1], 2 * conv["dt"][1:])


def test_rows_match_stepbench_run(study, stepbench):
    """A row of the study file is what `stepbench run` prints for the same case."""
    conv = study["pendulum"]["midpoint"]["convergence"][()]
    row = conv[3]
    out = json.loads(subprocess.run(
        [stepbench, "run", "--problem", "pendulum", "--integrator", "midpoint", "--dt", repr(float(row["dt"])),
         "--json"], check=True, capture_output=True, text=True).stdout)
    assert out["steps"] == row["steps"] and out["force_evals"] == row["force_evals"]
    for key in ["err_pos_final", "err_vel_final", "err_pos_max", "err_pos_rms", "energy_drift"]:
        assert out[key] == pytest.approx(float(row[key]), rel=1e-9), key


def test_exact_methods_have_nan_order(study):
    g = study["constant_acceleration"]["rk4"]
    assert g.attrs["exact_for_problem"] == 1
    assert math.isnan(g.attrs["observed_order"])
    assert g.attrs["fit_status"] == "exact"


def test_fit_levels_recorded(study):
    g = study["damped_spring"]["rk4"]
    levels = g.attrs["fit_levels"]
    assert len(levels) >= 3
    assert abs(g.attrs["observed_order"] - 4) < 0.15
