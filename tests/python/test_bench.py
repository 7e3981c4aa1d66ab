"""The benchmark executable as a user meets it: the cases it registers from the
registries, one case in quick mode whose counters agree with `stepbench run`, the quick
timed study file, and its bad-flag handling."""
import json
import math
import os
import subprocess
import time

import h5py
import pytest

PEERS_FIXED = ["gsl_rk4", "gsl_rk2", "gsl_rkf45"]
PEERS_ADAPTIVE = ["gsl_rkf45_adaptive", "gsl_rk8pd_adaptive", "cvode_adams", "cvode_bdf"]
BASELINE_PROBLEMS = {"damped_spring", "pendulum"}


@pytest.fixture(scope="module")
def bench(stepbench):
    path = os.path.join(os.path.dirname(stepbench), "stepbench_bench")
    assert os.access(path, os.X_OK), path
    return path


@pytest.fixture(scope="module")
def listing(stepbench):
    return json.loads(subprocess.run([stepbench, "list", "--json"], check=True, capture_output=True,
                                     text=True).stdout)


def listed(bench, *args):
    out = subprocess.run([bench, "--quick", "--benchmark_list_tests", *args], check=True, capture_output=True,
                         text=True).stdout
    return out.split()


def test_lists_every_case_of_the_registry(bench, listing):
    names = set(listed(bench))
    has_odeint = any("/odeint_rk4/" in n for n in names)
    expected = set()
    for p in listing["problems"]:
        dts = [p["horizon"] / (32 * 2 ** k) for k in range(8)]  # the quick ladder
        methods = [i["name"] for i in listing["integrators"]] + PEERS_FIXED
        if has_odeint:
            methods += ["odeint_rk4", "odeint_velocity_verlet"]
        if p["name"] in BASELINE_PROBLEMS:
            methods.append("baseline_rk4")
        expected |= {f"{p['name']}/{m}/dt:{dt:.6g}" for m in methods for dt in dts}
        tols = [10.0 ** -e for e in range(2, 13, 2)]  # thinned in quick mode
        expected |= {f"{p['name']}/{m}/tol:{tol:.0e}" for m in PEERS_ADAPTIVE for tol in tols}
    assert names == expected, (sorted(expected - names)[:5], sorted(names - expected)[:5])


def test_filter_selects_one_family(bench):
    names = listed(bench, "--benchmark_filter=pendulum/rk4/")
    assert len(names) == 8 and all(n.startswith("pendulum/rk4/dt:") for n in names)


def test_one_case_agrees_with_stepbench_run(bench, stepbench, tmp_path):
    out = tmp_path / "case.json"
    subprocess.run([bench, "--quick", "--benchmark_filter=^damped_spring/rk4/dt:0.0390625$",
                    f"--benchmark_out={out}", "--benchmark_out_format=json"], check=True, capture_output=True)
    runs = [b for b in json.loads(out.read_text())["benchmarks"] if b["run_type"] == "iteration"]
    assert len(runs) == 1 and runs[0]["name"] == "damped_spring/rk4/dt:0.0390625"
    case = runs[0]
    for counter in ["err_pos_final", "err_pos_max", "steps", "force_evals", "ns_per_step"]:
        assert counter in case, counter
    assert case["real_time"] > 0 and case["ns_per_step"] > 0
    run = json.loads(subprocess.run([stepbench, "run", "--problem", "damped_spring", "--integrator", "rk4",
                                     "--dt", "0.0390625", "--json"], check=True, capture_output=True,
                                    text=True).stdout)
    assert case["steps"] == run["steps"] == 256
    assert case["force_evals"] == run["force_evals"] == 4 * 256
    assert case["err_pos_final"] == pytest.approx(run["err_pos_final"], rel=1e-12)
    assert case["err_pos_max"] == pytest.approx(run["err_pos_max"], rel=1e-12)
    # ns_per_step is the case's wall time over its steps (measured around the same loop).
    assert case["ns_per_step"] == pytest.approx(case["real_time"] * 1e3 / 256, rel=0.05)  # real_time in us


def test_quick_timed_study(bench, tmp_path):
    path = tmp_path / "study.h5"
    start = time.monotonic()
    done = subprocess.run([bench, "--quick", f"--study_out={path}"], check=True, capture_output=True, text=True)
    elapsed = time.monotonic() - start
    print(f"\nquick timed study: {elapsed:.1f} s")  # the figure the README quotes
    assert "Performance ratios" in done.stdout
    with h5py.File(path, "r") as f:
        assert f.attrs["timing"] == 1 and f.attrs["benchmark_mode"] == "quick"
        for key in ["benchmark_min_time_s", "benchmark_repetitions", "cpu_scaling_enabled", "num_cpus", "cpu"]:
            assert key in f.attrs, key
        conv = f["damped_spring/rk4/convergence"][()]
        assert len(conv) == 8
        assert (conv["time_ns"] > 0).all() and (conv["repetitions"] >= 1).all() and not conv["cut"].any()
        # A finer dt costs more: time grows with the step count (allow noise, not order).
        assert conv["time_ns"][-1] > 20 * conv["time_ns"][0]
        peer = f["pendulum/gsl_rk4"]
        assert peer.attrs["kind"] == "fixed_step" and peer.attrs["declared_order"] == 4
        assert abs(peer.attrs["observed_order"] - 4) < 0.3
        wp = peer["work_precision"][()]
        assert list(wp.dtype.names) == ["param", "steps", "force_evals", "err_pos_final", "err_pos_max",
                                        "diverged", "time_ns", "repetitions", "cut"]
        # GSL's rk4 estimates its error by step doubling: 11 evaluations a step (3 RK4
        # steps sharing the first stage) after the first.
        assert wp["force_evals"][0] == 11 * wp["steps"][0] + 1
        cvode = f["pendulum/cvode_bdf"]["work_precision"][()]
        assert cvode["param"][0] == pytest.approx(1e-2) and (cvode["time_ns"] > 0).all()
        # Tighter tolerance, smaller error (over the whole ladder, not step by step).
        assert cvode["err_pos_max"][-1] < 1e-3 * cvode["err_pos_max"][0]
        if "odeint_velocity_verlet" in f["pendulum"]:
            vv = f["pendulum/odeint_velocity_verlet"]
            # Boost declares order 1 for a second-order method: reported, not hidden.
            assert vv.attrs["declared_order"] == 1 and abs(vv.attrs["observed_order"] - 2) < 0.15


@pytest.mark.parametrize("args, message", [
    (["--case_budget=abc"], "--case_budget must be a finite number"),
    (["--case_budget=0"], "--case_budget must be > 0"),
    (["--study_out=/nonexistent/dir/study.h5"], "cannot write results file"),
    (["--no_such_flag"], "unrecognized command-line flag"),
])
def test_bad_flags(bench, args, message):
    done = subprocess.run([bench, "--quick", *args], capture_output=True, text=True, timeout=60)
    assert done.returncode != 0
    assert message in done.stderr
    assert done.stdout == ""


def test_time_budget_cuts_and_marks_the_fine_end(bench, tmp_path):
    """A budget far below one iteration's time: each family's first (coarsest) case runs,
    every finer one is cut, and the study file says so instead of holding a number."""
    path = tmp_path / "cut.h5"
    subprocess.run([bench, "--quick", "--case_budget=1e-9", "--benchmark_filter=^pendulum/(rk4|cvode_bdf)/",
                    f"--study_out={path}"], check=True, capture_output=True, text=True)
    with h5py.File(path, "r") as f:
        assert f.attrs["benchmark_case_budget_s"] == 1e-9
        for table in [f["pendulum/rk4/convergence"][()], f["pendulum/cvode_bdf/work_precision"][()]]:
            assert table["time_ns"][0] > 0 and not table["cut"][0]
            assert table["cut"][1:].all()
            assert all(math.isnan(t) for t in table["time_ns"][1:])
        # Cases the filter left out are neither timed nor cut.
        other = f["pendulum/euler/convergence"][()]
        assert not other["cut"].any() and all(math.isnan(t) for t in other["time_ns"])


def test_two_json_outputs_compare_with_google_benchmarks_compare_py(bench, tmp_path):
    compare = "/usr/share/benchmark/compare.py"
    if not os.path.exists(compare):
        pytest.skip("libbenchmark-tools is not installed")
    outs = []
    for name in ["a.json", "b.json"]:
        out = tmp_path / name
        subprocess.run([bench, "--quick", "--benchmark_filter=^damped_spring/(rk4|gsl_rk4)/",
                        f"--benchmark_out={out}", "--benchmark_out_format=json"], check=True, capture_output=True)
        outs.append(str(out))
    done = subprocess.run(["/usr/bin/python3", compare, "benchmarks", *outs], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    rows = [line for line in done.stdout.splitlines() if "damped_spring/" in line]
    assert len(rows) == 16  # 8 quick levels x 2 methods, each compared old against new


def test_set_reaches_the_timed_cases_and_the_study(bench, stepbench, tmp_path):
    """--set changes the scene for the sweep and for the timed loop alike: the study
    records the parameter, and a timed case's counters equal `stepbench run --set`."""
    path, out = tmp_path / "set.h5", tmp_path / "set.json"
    subprocess.run([bench, "--quick", "--set=damped_spring.k_d=3", "--benchmark_filter=^damped_spring/rk4/dt:0.0390625$",
                    f"--benchmark_out={out}", "--benchmark_out_format=json", f"--study_out={path}"],
                   check=True, capture_output=True)
    with h5py.File(path, "r") as f:
        assert f["damped_spring"].attrs["k_d"] == 3.0
    case = [b for b in json.loads(out.read_text())["benchmarks"] if b["run_type"] == "iteration"][0]
    run = json.loads(subprocess.run([stepbench, "run", "--problem", "damped_spring", "--integrator", "rk4",
                                     "--dt", "0.0390625", "--set", "k_d=3", "--json"], check=True,
                                    capture_output=True, text=True).stdout)
    assert case["err_pos_max"] == pytest.approx(run["err_pos_max"], rel=1e-12)
    default = json.loads(subprocess.run([stepbench, "run", "--problem", "damped_spring", "--integrator", "rk4",
                                         "--dt", "0.0390625", "--json"], check=True, capture_output=True,
                                        text=True).stdout)
    assert case["err_pos_max"] != pytest.approx(default["err_pos_max"], rel=1e-3)
