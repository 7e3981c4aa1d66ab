"""Shared fixtures: the executables, two real study files made once per session (under
ctest, once a run of the suite, for both pytest runs: tests/CMakeLists.txt), a plain
sweep and a quick timed study (every method, every problem), that the study-file, report
and benchmark tests all read, and the report of each, drawn once per session, that the
report, scan, challenge and browser tests read."""
import os
import re
import pathlib
import subprocess
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
REPORT = os.path.join(ROOT, "scripts", "report")
PYTHON = "/usr/bin/python3"

# The exit code of a study that was written whole: 0, also where a method failed on a
# case (a finding, recorded with its reason and summed up on stderr; exit 3 only with
# --strict). Anything else is an error.
STUDY_WRITTEN = (0,)


def run_study(args, **kwargs):
    done = subprocess.run(args, **kwargs)
    if done.returncode not in STUDY_WRITTEN:
        raise subprocess.CalledProcessError(done.returncode, args, done.stdout, done.stderr)
    return done


def pytest_addoption(parser):
    parser.addoption("--stepbench", required=True, help="path to the stepbench executable")
    parser.addoption("--plain-study", default=None,
                     help="a quick sweep already made (ctest's plain_study fixture: stepbench sweep "
                          "--quick --out PATH); without it the session makes one")
    parser.addoption("--timed-study", default=None,
                     help="a quick timed study already made (ctest's quick_study fixture: "
                          "stepbench_bench --quick --study_out=PATH, its stdout and stderr in "
                          "PATH with .out and .err for .h5); without it the session makes one")


@pytest.fixture(scope="session")
def stepbench(request):
    # Absolute: some tests run it from a temporary working directory.
    return os.path.abspath(request.config.getoption("--stepbench"))


@pytest.fixture(scope="session")
def bench(stepbench):
    path = os.path.join(os.path.dirname(stepbench), "stepbench_bench")
    assert os.access(path, os.X_OK), path
    return path


@pytest.fixture(scope="session")
def plain_study(stepbench, tmp_path_factory, request):
    """`stepbench sweep --quick`: every method on every problem, no timings. Under ctest it
    is made once (fixture plain_study) for the two pytest runs that read it."""
    given = request.config.getoption("--plain-study")
    if given:
        assert pathlib.Path(given).is_file(), f"--plain-study {given}: not made"
        return pathlib.Path(given)
    path = tmp_path_factory.mktemp("plain") / "study.h5"
    run_study([stepbench, "sweep", "--quick", "--quiet", "--out", str(path)], stdout=subprocess.DEVNULL)
    return path


@pytest.fixture(scope="session")
def small_study(stepbench, tmp_path_factory):
    """`stepbench sweep --quick` of three problems: every part of the study (the substeps
    and the scan on stiff_spring), for the tests that cut a part out of a complete study
    and read what the report makes of it; its report draws in a fifth of the time."""
    path = tmp_path_factory.mktemp("small") / "study.h5"
    run_study([stepbench, "sweep", "--quick", "--quiet", "--problem", "damped_spring", "--problem", "pendulum",
               "--problem", "stiff_spring", "--out", str(path)], stdout=subprocess.DEVNULL)
    return path


@pytest.fixture(scope="session")
def timed_study(bench, tmp_path_factory, request):
    """`stepbench_bench --quick --study_out`: the same sweep with every row timed (a few
    seconds). Returns the path and the finished process, whose output some tests read.
    Under ctest the suite's quick study is made once (fixture quick_study) and read by
    the accuracy gate and here: the process is rebuilt from the output it left beside it."""
    given = request.config.getoption("--timed-study")
    if given:
        path = pathlib.Path(given)
        out, err = path.with_suffix(".out"), path.with_suffix(".err")
        assert path.is_file() and out.is_file() and err.is_file(), f"--timed-study {path}: not made"
        return path, subprocess.CompletedProcess([bench, "--quick", f"--study_out={path}"], 0,
                                                 out.read_text(), err.read_text())
    path = tmp_path_factory.mktemp("timed") / "study.h5"
    start = time.monotonic()
    done = run_study([bench, "--quick", f"--study_out={path}"], capture_output=True, text=True, timeout=300)
    print(f"\nquick timed study: {time.monotonic() - start:.1f} s")  # the figure the README quotes
    return path, done


@pytest.fixture(scope="session")
def reports(plain_study, timed_study, tmp_path_factory):
    """A report of each study, "plain" and "timed" -> (the study, its report folder), drawn
    side by side (one figure process each). A whole report takes some 20 s of CPU time to
    draw, so every test that reads the report of an unchanged study reads these; a test
    that changes a folder works on a copy."""
    d = tmp_path_factory.mktemp("report")
    studies = {"plain": plain_study, "timed": timed_study[0]}
    procs = {shape: subprocess.Popen([PYTHON, REPORT, str(path), "--out", str(d / shape), "--jobs", "1"],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for shape, path in studies.items()}
    out = {}
    for shape, proc in procs.items():
        stdout, stderr = proc.communicate(timeout=120)
        assert proc.returncode == 0, stderr
        assert re.search(r"report written in \d+(\.\d+)? s", stdout), stdout
        assert stderr == "", stderr  # a complete study: no warning
        out[shape] = (studies[shape], d / shape)
    return out
