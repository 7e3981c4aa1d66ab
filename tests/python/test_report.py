"""scripts/report and `stepbench advise` on study files made by the real stepbench.

Two shapes of study file: a plain sweep (no timings, no peers), and a timed one. The
timed shape is a TEST FIXTURE (`add_fake_timings`): it copies a real study file and adds,
with h5py, the fields and groups docs/study-format.md documents for a timed study
(time_ns / repetitions / cut in `convergence`, peer groups with `work_precision`, the
benchmark root attributes), with made-up but deterministic numbers. It exercises the
timing paths before the benchmark writes them; it is not a model of real timings.

Every number a test checks against the report is recomputed here from the file with
h5py, independently of the report's code.
"""
import json
import math
import os
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
REPORT = os.path.join(ROOT, "scripts", "report")
PYTHON = "/usr/bin/python3"
THRESHOLDS = (1e-2, 1e-4, 1e-6)


# --- fixtures -------------------------------------------------------------------------------

def add_fake_timings(src, dst):
    """TEST FIXTURE: a copy of a real study file in the timed shape of docs/study-format.md."""
    shutil.copyfile(src, dst)
    with h5py.File(dst, "r+") as f:
        f.attrs.update({"timing": 1, "benchmark_mode": "quick", "benchmark_min_time_s": 0.01,
                        "benchmark_repetitions": 3, "benchmark_case_budget_s": 0.5, "cpu_scaling_enabled": 0,
                        "num_cpus": 2, "mhz_per_cpu": 2000.0})
        for pname, g in f.items():
            names = [n for n in g if isinstance(g[n], h5py.Group) and "convergence" in g[n]]
            for k, name in enumerate(sorted(names)):
                old = g[name]["convergence"][()]
                dtype = old.dtype.descr + [("time_ns", "<f8"), ("repetitions", "<i8"), ("cut", "i1")]
                new = np.zeros(len(old), dtype=dtype)
                for field in old.dtype.names:
                    new[field] = old[field]
                # Made-up cost model: 3 ns per force evaluation plus a per-step overhead
                # that differs by method, so time and force evaluations rank differently.
                new["time_ns"] = 3.0 * old["force_evals"] + (1.0 + k) * old["steps"] + 50.0
                new["repetitions"] = 3
                # The time budget cuts the finest level of every method.
                new["cut"][-1] = 1
                new["time_ns"][-1] = np.nan
                new["repetitions"][-1] = 0
                del g[name]["convergence"]
                g[name].create_dataset("convergence", data=new)
            rk4 = g["rk4"]["convergence"][()]
            wp_type = [("param", "<f8"), ("steps", "<i8"), ("force_evals", "<i8"), ("err_pos_final", "<f8"),
                       ("err_pos_max", "<f8"), ("diverged", "i1"), ("time_ns", "<f8"), ("repetitions", "<i8"),
                       ("cut", "i1")]
            # A fixed-step peer: GSL's RK4 at our dt, same errors as ours, slower.
            fixed = np.zeros(len(rk4), dtype=wp_type)
            for field in ("steps", "force_evals", "err_pos_final", "err_pos_max"):
                fixed[field] = rk4[field]
            fixed["param"] = rk4["dt"]
            fixed["time_ns"] = 2.5 * rk4["time_ns"]  # NaN where ours was cut
            fixed["repetitions"] = rk4["repetitions"]
            fixed["cut"] = rk4["cut"]
            pg = g.create_group("gsl_rk4")
            pg.attrs.update({"kind": "fixed_step", "declared_order": 4.0, "observed_order": 3.9876,
                             "fit_status": "fitted", "fit_levels": np.array([2, 3, 4], dtype=np.int32),
                             "description": "GSL rk4 (test fixture)"})
            pg.create_dataset("work_precision", data=fixed)
            # An adaptive peer over a ladder of tolerances; one row fails (NaN errors).
            rtol = 10.0 ** -np.arange(2, 11)
            scale = float(g.attrs["pos_scale"])
            ad = np.zeros(len(rtol), dtype=wp_type)
            ad["param"] = rtol
            ad["steps"] = (20 * rtol ** -0.2).astype(int)
            ad["force_evals"] = 6 * ad["steps"] + 2
            ad["err_pos_final"] = 0.5 * rtol * scale
            ad["err_pos_max"] = 2.0 * rtol * scale
            ad["time_ns"] = 40.0 * ad["force_evals"]
            ad["repetitions"] = 3
            ad["err_pos_final"][0] = ad["err_pos_max"][0] = np.nan
            ad["diverged"][0] = 1
            pg = g.create_group("cvode_bdf")
            pg.attrs.update({"kind": "adaptive", "declared_order": np.nan, "observed_order": np.nan,
                             "fit_status": "insufficient", "description": "CVODE BDF (test fixture)"})
            pg.create_dataset("work_precision", data=ad)


def run_report(study, out, jobs=1):
    return subprocess.Popen([PYTHON, REPORT, str(study), "--out", str(out), "--jobs", str(jobs)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


@pytest.fixture(scope="module")
def studies(stepbench, tmp_path_factory):
    """A plain study, its timed twin, and a report of each (drawn in parallel)."""
    d = tmp_path_factory.mktemp("report")
    plain = d / "study.h5"
    subprocess.run([stepbench, "sweep", "--levels", "8", "--quiet", "--out", str(plain)], check=True,
                   stdout=subprocess.DEVNULL)
    timed = d / "timed.h5"
    add_fake_timings(plain, timed)
    procs = {"plain": (plain, d / "plain_report", run_report(plain, d / "plain_report")),
             "timed": (timed, d / "timed_report", run_report(timed, d / "timed_report"))}
    out = {}
    for key, (study, folder, proc) in procs.items():
        stdout, stderr = proc.communicate(timeout=120)
        assert proc.returncode == 0, stderr
        assert re.search(r"report written in \d+(\.\d+)? s", stdout), stdout
        out[key] = (study, folder)
    return out


# --- reading the outputs ----------------------------------------------------------------------

def md_table(text, heading):
    """The first markdown table after the line `heading`: (headers, rows of cells)."""
    lines = text.splitlines()
    i = lines.index(heading)
    while not lines[i].startswith("|"):
        i += 1
    table = []
    while i < len(lines) and lines[i].startswith("|"):
        table.append([c.strip() for c in re.split(r"(?<!\\)\|", lines[i].strip())[1:-1]])
        i += 1
    return table[0], table[2:]


def md_dict(text, heading, key_col=0):
    head, rows = md_table(text, heading)
    return {r[key_col]: dict(zip(head, r)) for r in rows}


def report_text(folder):
    with open(folder / "REPORT.md") as f:
        return f.read()


def methods(g):
    ours = {n: g[n]["convergence"][()] for n in g if isinstance(g[n], h5py.Group) and "convergence" in g[n]}
    peers = {n: g[n]["work_precision"][()] for n in g if isinstance(g[n], h5py.Group) and "work_precision" in g[n]}
    return ours, peers


def direct_cheapest(g, tol, metric, timed):
    """The documented rule, written again: rows that did not diverge, meet the tolerance
    and were not cut; cost is time_ns if every such row has it, else force_evals."""
    ours, peers = methods(g)
    rows = []
    for name, conv in list(ours.items()) + list(peers.items()):
        for r in conv:
            err = float(r[metric])
            diverged = ("diverged" in conv.dtype.names and r["diverged"]) or not np.isfinite(r["err_pos_max"])
            cut = timed and "cut" in conv.dtype.names and r["cut"] == 1
            if not diverged and not cut and np.isfinite(err) and err <= tol:
                param = float(r["dt"] if "dt" in conv.dtype.names else r["param"])
                t = float(r["time_ns"]) if "time_ns" in conv.dtype.names else math.nan
                rows.append((name, param, int(r["force_evals"]), t, err))
    if not rows:
        return None, None
    use_time = timed and all(np.isfinite(r[3]) and r[3] > 0 for r in rows)
    # Ties: the lower error, then the method name.
    key = (lambda r: (r[3], r[4], r[0])) if use_time else (lambda r: (r[2], r[4], r[0]))
    return min(rows, key=key), ("time_ns" if use_time else "force_evals")


# --- the report -------------------------------------------------------------------------------

@pytest.mark.parametrize("shape", ["plain", "timed"])
def test_outputs_exist_and_images_resolve(studies, shape):
    _, folder = studies[shape]
    md = report_text(folder)
    html = (folder / "index.html").read_text()
    assert len(md) > 1000 and len(html) > 1000
    images = re.findall(r"!\[[^\]]*\]\((fig/[^)]+\.png)\)", md)
    assert len(images) >= 7, images
    for img in images:
        path = folder / img
        assert path.is_file() and path.stat().st_size > 10_000, img
        assert f'src="{img}"' in html, img
    assert sorted(os.listdir(folder / "fig")) == sorted(os.path.basename(i) for i in images)
    # Opens offline: nothing is fetched from the network.
    assert not re.search(r"(src|href)=\"(https?:)?//", html)
    expected = {"convergence_constant_acceleration.png", "convergence_damped_spring.png", "convergence_pendulum.png",
                "convergence_projectile.png", "work_precision_force_evals.png", "stability_regions.png",
                "energy_drift.png"}
    if shape == "timed":
        expected.add("work_precision_time.png")
    assert set(os.path.basename(i) for i in images) == expected


@pytest.mark.parametrize("shape", ["plain", "timed"])
def test_metadata_comes_first(studies, shape):
    study, folder = studies[shape]
    md = report_text(folder)
    assert md.index("## Study") < md.index("## Summary") < md.index("## Convergence")
    meta = md_dict(md, "## Study")
    with h5py.File(study) as f:
        for key in ["version", "git_commit", "compiler", "build_type", "created_utc", "cpu"]:
            assert meta[key]["value"] == str(f.attrs[key]), key
        assert meta["cores"]["value"] == str(int(f.attrs["cores"]))
    if shape == "timed":
        bench = md_dict(md, "Timing run (Google Benchmark):")
        assert bench["benchmark_mode"]["value"] == "quick"
        assert bench["benchmark_repetitions"]["value"] == "3"
    else:
        assert "Timings: absent" in md


@pytest.mark.parametrize("shape", ["plain", "timed"])
def test_observed_orders_match_the_file(studies, shape):
    study, folder = studies[shape]
    md = report_text(folder)
    with h5py.File(study) as f:
        for pname, g in f.items():
            table = md_dict(md, f"#### {pname}: observed order")
            ours, _ = methods(g)
            assert set(table) == set(ours)
            for name in ours:
                a = g[name].attrs
                row = table[name]
                assert row["expected order"] == str(int(a["expected_order"]))
                if a["exact_for_problem"] == 1:
                    assert row["observed order"] == "exact for this problem", (pname, name)
                elif a["fit_status"] != "fitted":
                    assert row["observed order"].startswith("not fitted"), (pname, name)
                    assert a["fit_note"] in row["observed order"]
                else:
                    assert float(row["observed order"]) == pytest.approx(round(float(a["observed_order"]), 3),
                                                                         abs=1e-9), (pname, name)
                    assert row["fit levels"] == ",".join(str(k) for k in a["fit_levels"])


@pytest.mark.parametrize("shape", ["plain", "timed"])
@pytest.mark.parametrize("metric,title", [("err_pos_final", "by final error"),
                                          ("err_pos_max", "by max error over the run")])
def test_cheapest_tables_match_a_direct_computation(studies, shape, metric, title):
    study, folder = studies[shape]
    md = report_text(folder)
    timed = shape == "timed"
    with h5py.File(study) as f:
        for pname, g in f.items():
            table = md_dict(md, f"#### {pname}: cheapest {title}")
            for tol in THRESHOLDS:
                row = table[f"{tol:g}"]
                want, cost = direct_cheapest(g, tol, metric, timed)
                if want is None:
                    assert row["cheapest method"] == "none"
                    continue
                name, param, evals, t, err = want
                assert row["cheapest method"].replace(" (peer)", "") == name, (pname, tol, row)
                value = float(re.search(r"= ([0-9.e+-]+)", row["dt or tolerance"]).group(1))
                assert value == pytest.approx(param, rel=1e-5)
                if cost == "force_evals":
                    assert row["cost"] == f"{evals} force evals"
                else:
                    assert re.fullmatch(r"[0-9.]+ (ns|us|ms|s)", row["cost"]), row["cost"]
                unit = "rad" if pname == "pendulum" else "m"
                assert float(row[f"{metric} [{unit}]"]) == pytest.approx(err, rel=5e-3, abs=0)


def test_timed_summary_ranks_by_time_and_includes_peers(studies):
    study, folder = studies["timed"]
    md = report_text(folder)
    with h5py.File(study) as f:
        g = f["damped_spring"]
        want, cost = direct_cheapest(g, 1e-4, "err_pos_max", True)
    assert cost == "time_ns"
    row = md_dict(md, "#### damped_spring: cheapest by max error over the run")["0.0001"]
    assert row["cheapest method"].replace(" (peer)", "") == want[0]
    # The peers are on the work-precision figure's front table and in the order table.
    assert "gsl_rk4" in md and "cvode_bdf" in md
    peer_orders = md_dict(md, "#### damped_spring: observed order")
    assert "gsl_rk4" not in peer_orders  # ours only in that table; peers in their own
    assert "| gsl_rk4 | 4 | 3.988 |" in md


@pytest.mark.parametrize("shape", ["plain"])
def test_references_table_matches_the_file(studies, shape):
    study, folder = studies[shape]
    md = report_text(folder)
    with h5py.File(study) as f:
        for pname, g in f.items():
            table = md_dict(md, f"### {pname}: references")
            for src, ref in g["reference"].items():
                row = table[src]
                for col, attr in [("steps", "steps"), ("failed steps", "failed_steps"), ("rhs_evals", "rhs_evals"),
                                  ("lin_rhs_evals", "lin_rhs_evals"), ("rhs_evals_counted", "rhs_evals_counted")]:
                    assert row[col] == str(int(ref.attrs[attr])), (pname, src, col)
                assert float(row["position agreement (rel.)"]) == pytest.approx(ref.attrs["err_pos_rel"], rel=0.05)
                assert row["is truth"] == ("yes" if ref.attrs["is_truth"] else "")


def test_stability_theory_numbers(studies):
    _, folder = studies["plain"]
    md = report_text(folder)
    head, rows = md_table(md, "### Theoretical limits on the oscillator")
    t = {r[0]: dict(zip(head, r)) for r in rows}
    assert t["euler"]["stable for w dt <"] == "unstable for every dt"
    assert t["midpoint"]["stable for w dt <"] == "unstable for every dt"
    assert t["midpoint"]["det M(y) - 1"] == "y^4/4"  # |R(iy)|^2 - 1 = y^4 / 4 > 0
    for name in ("semi_implicit_euler", "momentum", "velocity_verlet"):
        assert float(t[name]["stable for w dt <"]) == pytest.approx(2.0, abs=1e-5)
    assert float(t["rk4"]["stable for w dt <"]) == pytest.approx(2 * math.sqrt(2), abs=1e-5)
    # damped_spring: w0 = sqrt(k_s / m) = sqrt(10); dt < 2 / w0 for the symplectic methods.
    col = [h for h in head if h.startswith("damped_spring: dt limit, undamped")][0]
    assert float(t["velocity_verlet"][col]) == pytest.approx(2 / math.sqrt(10), rel=1e-3)
    assert float(t["rk4"][col]) == pytest.approx(2 * math.sqrt(2) / math.sqrt(10), rel=1e-3)
    # With its damping, explicit Euler is stable for dt < 2 zeta / w0 = k_d / k_s = 0.1 s:
    # |1 + dt lambda| < 1 for lambda = -gamma +- i w_d, i.e. dt < 2 gamma / |lambda|^2.
    col = [h for h in head if h.startswith("damped_spring: dt limit with its damping")][0]
    assert float(t["euler"][col]) == pytest.approx(0.1, rel=1e-3)


def test_absent_sections_are_named(studies):
    _, folder = studies["plain"]
    md = report_text(folder)
    assert "Measured stability limits: absent" in md
    assert "Energy drift over time on long runs: absent" in md
    assert "Game-loop figures: absent" in md


def test_bad_study_file_leaves_the_old_report(tmp_path):
    out = tmp_path / "report"
    out.mkdir()
    (out / "REPORT.md").write_text("old\n")
    for bad in [tmp_path / "missing.h5", tmp_path / "garbage.h5"]:
        if bad.name == "garbage.h5":
            bad.write_text("not an HDF5 file\n")
        p = subprocess.run([PYTHON, REPORT, str(bad), "--out", str(out)], capture_output=True, text=True)
        assert p.returncode == 1
        assert len(p.stderr.strip().splitlines()) == 1 and p.stderr.startswith("report: error: cannot read study"), \
            p.stderr
        assert (out / "REPORT.md").read_text() == "old\n"
    assert sorted(os.listdir(tmp_path)) == ["garbage.h5", "report"]  # no temporary folder left


def test_a_peer_that_misdeclares_its_order_is_flagged(studies, tmp_path):
    """The fixture's gsl_rk4 declares 4 and achieves 3.99: "yes". Made to declare 1 (as
    Boost's velocity_verlet does for a second-order method), the report says so."""
    study, folder = studies["timed"]
    md = (folder / "REPORT.md").read_text()
    assert re.search(r"\| gsl_rk4 \| 4 \| 3\.988 \|.*\| yes \|", md), md
    wrong = tmp_path / "wrong.h5"
    shutil.copy(study, wrong)
    with h5py.File(wrong, "r+") as f:
        for p in f:
            if isinstance(f[p], h5py.Group) and "gsl_rk4" in f[p]:
                f[p]["gsl_rk4"].attrs["declared_order"] = 1.0
    out = tmp_path / "report"
    p = subprocess.run([PYTHON, REPORT, str(wrong), "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "NO: declares 1, achieves 3.99" in (out / "REPORT.md").read_text()


def test_an_incomplete_study_is_reported_as_such(studies, tmp_path):
    study, _ = studies["plain"]
    cut = tmp_path / "cut.h5"
    shutil.copy(study, cut)
    with h5py.File(cut, "r+") as f:
        del f["pendulum/rk4"]
        del f["damped_spring/reference"]
    out = tmp_path / "report"
    p = subprocess.run([PYTHON, REPORT, str(cut), "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "warning: incomplete study file: pendulum: no convergence data for rk4" in p.stderr
    assert "warning: incomplete study file: damped_spring: no reference solutions" in p.stderr
    md = (out / "REPORT.md").read_text()
    assert "Incomplete study file: pendulum: no convergence data for rk4" in md
    clean = subprocess.run([PYTHON, REPORT, str(study), "--out", str(tmp_path / "clean")], capture_output=True,
                           text=True)
    assert "warning" not in clean.stderr


def test_never_replaces_a_folder_it_did_not_write(studies, tmp_path):
    """--out naming a folder with other files in it (results/, the working directory)
    is refused, and nothing in it is touched; a report folder it wrote is replaced."""
    study, _ = studies["plain"]
    precious = tmp_path / "results"
    precious.mkdir()
    (precious / "notes.txt").write_text("keep me\n")
    for out, cwd in [(str(precious), None), ("", str(precious)), (".", str(precious))]:
        p = subprocess.run([PYTHON, REPORT, str(study), "--out", out], capture_output=True, text=True, cwd=cwd)
        assert p.returncode == 1, p.stdout
        assert len(p.stderr.strip().splitlines()) == 1 and p.stderr.startswith("report: error:"), p.stderr
        assert sorted(os.listdir(precious)) == ["notes.txt"]
    report = tmp_path / "report"
    for _ in range(2):  # the second run replaces the first's folder
        p = subprocess.run([PYTHON, REPORT, str(study), "--out", str(report)], capture_output=True, text=True)
        assert p.returncode == 0, p.stderr
        assert (report / ".stepbench-report").exists() and (report / "index.html").exists()


# --- stepbench advise -------------------------------------------------------------------------

def advise(stepbench, study, *args):
    return subprocess.run([stepbench, "advise", "--study", str(study), *args], capture_output=True, text=True)


@pytest.mark.parametrize("shape", ["plain", "timed"])
def test_advise_answer_matches_the_file(stepbench, studies, shape):
    study, _ = studies[shape]
    p = advise(stepbench, study, "--problem", "pendulum", "--tol", "1e-4", "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    with h5py.File(study) as f:
        want, cost = direct_cheapest(f["pendulum"], 1e-4, "err_pos_max", shape == "timed")
    assert out["met"] is True and out["cost"] == cost
    assert out["choice"]["method"] == want[0]
    assert out["choice"]["param"] == pytest.approx(want[1], rel=1e-12)
    assert out["choice"]["error"] == pytest.approx(want[4], rel=1e-12)
    assert out["unit"] == "rad"
    costs = [out["choice"]["cost"]] + [r["cost"] for r in out["runners_up"]]
    assert costs == sorted(costs)
    excluded = {e["method"]: e["reason"] for e in out["excluded"]}
    assert excluded["euler"].startswith("too inaccurate: best err_pos_max")
    text = advise(stepbench, study, "--problem", "pendulum", "--tol", "1e-4").stdout
    assert text.splitlines()[1].startswith(f"use {want[0]}"), text


def test_advise_cut_rows_are_too_slow(stepbench, studies):
    """In the fixture only the finest level of every method reaches 1e-13 on damped_spring
    or none does; the finest levels are cut, so those methods are "too slow"."""
    study, _ = studies["timed"]
    with h5py.File(study) as f:
        conv = f["damped_spring/rk4/convergence"][()]
    tol = float(conv["err_pos_max"][-1]) * 1.01
    assert (conv["err_pos_max"][:-1] > tol).all()
    p = advise(stepbench, study, "--problem", "damped_spring", "--tol", repr(tol), "--json")
    reasons = {e["method"]: e["reason"] for e in json.loads(p.stdout)["excluded"]}
    assert reasons["rk4"].startswith("too slow: cut by the time budget"), reasons


def test_advise_unknown_problem(stepbench, studies):
    study, _ = studies["plain"]
    p = advise(stepbench, study, "--problem", "nope", "--tol", "1e-3")
    assert p.returncode == 2
    assert len(p.stderr.splitlines()) == 1
    assert "problem 'nope' is not in the study file" in p.stderr and "pendulum" in p.stderr


def test_advise_no_method_meets_the_tolerance(stepbench, studies):
    study, _ = studies["plain"]
    p = advise(stepbench, study, "--problem", "damped_spring", "--tol", "1e-30")
    assert p.returncode == 3
    assert "no method in the study meets err_pos_max <= 1e-30 m on damped_spring" in p.stdout
    assert "the best achieved is" in p.stdout


@pytest.mark.parametrize("args,code", [(["--tol", "0"], 2), (["--tol", "-1e-3"], 2), (["--tol", "abc"], 2),
                                       (["--tol", "1e-3", "--metric", "bogus"], 2)])
def test_advise_bad_input(stepbench, studies, args, code):
    study, _ = studies["plain"]
    p = advise(stepbench, study, "--problem", "pendulum", *args)
    assert p.returncode == code and len(p.stderr.splitlines()) == 1, p.stderr


def test_advise_missing_study(stepbench, tmp_path):
    p = advise(stepbench, tmp_path / "nope.h5", "--problem", "pendulum", "--tol", "1e-3")
    assert p.returncode == 1 and p.stderr.strip() == f"stepbench: error: cannot read study file " \
                                                      f"'{tmp_path / 'nope.h5'}': no such file"


if __name__ == "__main__":  # make a timed fixture by hand: test_report.py SRC DST
    add_fake_timings(sys.argv[1], sys.argv[2])
