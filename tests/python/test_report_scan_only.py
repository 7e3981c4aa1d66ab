"""The report of a scan file: what `stepbench scan --out` and `stepbench merge [--partial]`
write, /scan/<name> and no problem (docs/study-format.md, /scan). The report is the scan
section alone (scan.py, the same code as in a study's report), under a title that says it
is a scan file. Real files by the stepbench under test: the stiff spring over k_s (9
points, log) at 60 Hz with 1 and 4 substeps, whole; the same grid in three shards, two
merged with --partial; and the second shard as it is. Every number checked is read from
the file with h5py."""
import json
import os
import re
import shutil
import subprocess

import h5py
import numpy as np
import pytest

from test_report import PYTHON, REPORT, md_table, report_text

SPRING = ["--problem", "stiff_spring", "--param", "stiff_spring.k_s=1e1:1e7:9:log", "--hz", "60", "--substeps", "1,4"]
FIGURES = ["fig/scan_stiff_spring_one_step.png", "fig/scan_stiff_spring_cheapest.png"]
OVERLAY_NOTE = ("No stability-limit overlay: it needs /stability/limits, which this file does not hold (a scan file "
                "never does); the report of a study file with /stability draws it, and `stepbench stability --json` "
                "prints the limits.")


def run(args, timeout=120):
    return subprocess.run(args, capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def scan_files(stepbench, tmp_path_factory):
    d = tmp_path_factory.mktemp("scan_only")
    p = run([stepbench, "scan", *SPRING, "--out", str(d / "whole.h5"), "--quiet"])
    assert p.returncode == 0, p.stderr
    for k in (1, 2, 3):
        p = run([stepbench, "scan", *SPRING, "--shard", f"{k}/3", "--out", str(d / f"shard{k}.h5"), "--quiet"])
        assert p.returncode == 0, p.stderr
    p = run([stepbench, "merge", "--partial", "-o", str(d / "partial.h5"), str(d / "shard1.h5"), str(d / "shard3.h5")])
    assert p.returncode == 0, p.stderr
    return {"whole": d / "whole.h5", "partial": d / "partial.h5", "shard": d / "shard2.h5"}


@pytest.fixture(scope="module")
def scan_reports(scan_files, tmp_path_factory):
    d = tmp_path_factory.mktemp("scan_only_reports")
    out = {}
    for kind, path in scan_files.items():
        p = run([PYTHON, REPORT, str(path), "--out", str(d / kind), "--jobs", "2"], timeout=180)
        assert p.returncode == 0, p.stderr
        assert p.stderr == "", p.stderr  # a scan file is not an incomplete study: no warning
        assert re.search(r"report written in \d+(\.\d+)? s", p.stdout), p.stdout
        out[kind] = (path, d / kind)
    return out


def the_scan(path):
    """(attrs, points) of the file's one scan, read with h5py; and the root attributes."""
    with h5py.File(path) as f:
        assert len(f["problems"]) == 0  # a scan file, as stepbench wrote it
        (name,) = f["scan"].keys()
        g = f[f"scan/{name}"]
        return name, dict(g.attrs), g["points"][()], dict(f.attrs)


def text(v):
    return v.decode() if isinstance(v, bytes) else v


@pytest.mark.parametrize("kind", ["whole", "partial", "shard"])
def test_the_page_is_the_scan_alone(scan_reports, kind):
    path, folder = scan_reports[kind]
    name, attrs, points, root = the_scan(path)
    assert name == "stiff_spring"
    md = report_text(folder)
    html = (folder / "index.html").read_text()
    assert md.startswith("# stepbench scan file: stiff_spring over k_s\n")
    assert "<title>stepbench scan file: stiff_spring over k_s</title>" in html
    # The line under the title: the file, the build and commit from its root attributes.
    first = md.split("\n\n")[1]
    assert first.startswith(f"Scan file `{os.path.basename(str(path))}` ")
    for key in ("version", "git_commit", "build_type", "compiler", "cpu", "created_utc"):
        assert text(root[key]) in first, key
    # The scans it holds, and how much of the grid: the file's points against grid_points.
    held, grid = len(points), int(attrs["grid_points"])
    how = {"whole": "the whole grid", "partial": f"a partial merge: {grid - held} missing",
           "shard": f"shard {int(attrs['shard_index']) + 1} of {int(attrs['shard_count'])}"}[kind]
    assert f"- Scan stiff_spring: stiff_spring over k_s at 60 Hz; holds {held} of its {grid} grid points ({how})." in md
    assert (held == grid) == (kind == "whole")
    # The scan section as a study's report has it, and nothing that needs /problems.
    headings = re.findall(r"^## (.+)$", md, re.M)
    assert headings == ["Parameter scans", "Appendix: the scan file"]
    assert "### Scan stiff_spring: stiff_spring over k_s" in md
    assert '<a href="#parameter-scans">' in html
    for absent in ("Fastest at equal error", "## Stability", "work_precision_", "convergence_"):
        assert absent not in md, absent
    imgs = re.findall(r"!\[[^\]]*\]\((fig/[^)]+\.png)\)", md)
    assert imgs == FIGURES
    assert sorted(os.listdir(folder / "fig")) == sorted(os.path.basename(i) for i in FIGURES)
    from matplotlib import image
    for img in imgs:
        pixels = image.imread(folder / img)
        assert pixels.ndim == 3 and pixels.shape[1] <= 1400 and pixels.shape[0] > 150, (img, pixels.shape)
        assert pixels[..., :3].std() > 0.05, img  # not blank
    # The appendix: build and machine, and the scan's coverage, from the file.
    head, rows = md_table(md, "Build and machine (the file's root attributes):")
    shown = dict(rows)
    assert shown["git_commit"] == text(root["git_commit"]) and shown["version"] == text(root["version"])
    head, rows = md_table(md, "Scans (the attributes of /scan/<name>):")
    row = dict(zip(head, rows[0]))
    assert (row["grid points"], row["points held"], row["coverage"]) == (str(grid), str(held), how)
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["verdict"] is None and summary["git_commit"] == text(root["git_commit"])
    (s,) = summary["scans"]
    assert (s["name"], s["grid_points"], s["points"]) == ("stiff_spring", grid, held)


@pytest.mark.parametrize("kind", ["whole", "partial", "shard"])
def test_the_overlay_is_named_not_drawn(scan_reports, kind):
    """A scan file's /stability is empty: no red bars, no limit column, and one sentence
    saying what the overlay needs."""
    path, folder = scan_reports[kind]
    with h5py.File(path) as f:
        assert "stability" not in f or len(f["stability/limits"]) == 0
    md = report_text(folder)
    assert md.count(OVERLAY_NOTE) == 1
    head, _ = md_table(md, next(x for x in md.splitlines() if x.startswith("Where each method stops completing")))
    assert head == ["method", "60 Hz: first k_s not completed"]
    assert "Red bars" not in md


def test_the_partial_merge_and_the_shard_say_what_they_lack(scan_reports):
    _, attrs, points, _ = the_scan(scan_reports["partial"][0])
    md = report_text(scan_reports["partial"][1])
    grid = int(attrs["grid_points"])
    assert (f"A partial merge (`stepbench merge --partial`): {grid - len(points)} of the grid's {grid} points are "
            f"missing") in md
    _, attrs, points, _ = the_scan(scan_reports["shard"][0])
    md = report_text(scan_reports["shard"][1])
    assert (f"This file is shard {int(attrs['shard_index']) + 1} of {int(attrs['shard_count'])} of the scan "
            f"(`stepbench scan --shard 2/3`): it holds {len(points)} of the grid's {grid} points") in md


def test_the_first_failure_is_the_files(scan_reports):
    """The table under the map of the whole scan: the first k_s whose run at one step a
    frame did not complete, per method, as the file's runs say."""
    path, folder = scan_reports["whole"]
    md = report_text(folder)
    head, rows = md_table(md, next(x for x in md.splitlines() if x.startswith("Where each method stops completing")))
    shown = {r[0]: r[1] for r in rows}
    with h5py.File(path) as f:
        ks = f["scan/stiff_spring/values/k_s"][()]
        runs = f["scan/stiff_spring/runs"][()]
    methods = np.char.decode(runs["method"].astype(bytes))
    assert set(shown) == set(methods)
    for m in set(methods):
        sel = np.sort(runs[(methods == m) & (runs["substeps"] == 1)], order="point")
        bad = sel["point"][(sel["diverged"] != 0) | (sel["failed"] != 0)]
        assert shown[m] == (f"{ks[bad[0]]:.3g}" if len(bad) else "none"), m
    assert shown["rk4"] != "none" and shown["implicit_euler"] == "none"


@pytest.mark.parametrize("readme_too", [False, True])
def test_markdown_is_refused(scan_files, tmp_path, readme_too):
    """--markdown writes the main study's verdict tables: on a scan file, one line on
    stderr, a non-zero exit, and nothing written (not the Markdown file, not the README
    whose block --readme would render from a summary, not the --out folder)."""
    readme = tmp_path / "README.md"
    before = "# project\n\n<!-- results:begin -->\nold table\n<!-- results:end -->\n"
    readme.write_text(before)
    summary = tmp_path / "summary.json"
    summary.write_text('{"study": {"path": "s.h5", "git_commit": "c", "cpu": "x", "created_utc": "t", '
                       '"cost_kind": "force_evals"}, "hz": 60, "targets": [0.001], "problems": []}')
    args = ["--markdown", str(tmp_path / "results.md")]
    if readme_too:
        args += ["--readme", str(readme), "--summary", str(summary)]
    p = run([PYTHON, REPORT, str(scan_files["partial"]), *args, "--out", str(tmp_path / "report")], timeout=60)
    assert p.returncode == 1 and p.stdout == "", p.stdout
    assert p.stderr.splitlines() == [
        f"report: error: '{scan_files['partial']}' is a scan file (only /scan, no problems): --markdown writes the "
        "verdict tables of a study file; nothing written"]
    assert readme.read_text() == before
    assert sorted(os.listdir(tmp_path)) == ["README.md", "summary.json"]


def test_problem_is_refused(scan_files, tmp_path):
    p = run([PYTHON, REPORT, str(scan_files["whole"]), "--problem", "stiff_spring", "--out", str(tmp_path / "r")])
    assert p.returncode == 2 and len(p.stderr.splitlines()) == 1, p.stderr
    assert "is a scan file" in p.stderr and not (tmp_path / "r").exists()


def test_neither_problems_nor_scan_is_refused(scan_files, tmp_path):
    """The scan file with its scan taken out: neither a study nor a scan file."""
    empty = tmp_path / "empty.h5"
    shutil.copyfile(scan_files["whole"], empty)
    with h5py.File(empty, "r+") as f:
        del f["scan/stiff_spring"]
    p = run([PYTHON, REPORT, str(empty), "--out", str(tmp_path / "r")])
    assert p.returncode == 1 and p.stdout == ""
    assert p.stderr.splitlines() == [f"report: error: cannot read study file '{empty}': /problems holds no problem "
                                     "and the file has no /scan (neither a study nor a scan file)"]
    assert not (tmp_path / "r").exists()


def test_a_scan_file_with_limits_gets_the_overlay(scan_files, plain_study, tmp_path):
    """The overlay is the scan section's own: a scan file given the study's /stability
    (stepbench never writes one, but the reader takes it) draws it, with the file's limits."""
    path = tmp_path / "with_limits.h5"
    shutil.copyfile(scan_files["whole"], path)
    with h5py.File(path, "r+") as f, h5py.File(plain_study) as study:
        if "stability" in f:
            del f["stability"]
        study.copy(study["stability"], f, name="stability")
        lim = f["stability/limits"][()]
    out = tmp_path / "report"
    p = run([PYTHON, REPORT, str(path), "--out", str(out), "--jobs", "2"], timeout=180)
    assert p.returncode == 0, p.stderr
    md = report_text(out)
    assert OVERLAY_NOTE not in md and "Red bars" in md and "## Stability" not in md
    head, rows = md_table(md, next(x for x in md.splitlines() if x.startswith("Where each method stops completing")))
    shown = {r[0]: dict(zip(head, r)) for r in rows}
    row = lim[(np.char.decode(lim["integrator"].astype(bytes)) == "rk4")
              & (np.char.decode(lim["test"].astype(bytes)) == "oscillator")][0]
    assert shown["rk4"]["oscillator limit omega dt"] == f"{row['theory']:.4g}"
    assert shown["rk4"]["60 Hz: k_s at the limit"] == f"{1.0 * (row['theory'] * 60.0) ** 2:.3g}"
    assert sorted(os.listdir(out / "fig")) == sorted(os.path.basename(i) for i in FIGURES)  # no stability figure


CHAIN = ["--problem", "spring_chain", "--param", "spring_chain.masses=8:16:2:log", "--param",
         "spring_chain.k_s=1e2:1e3:2:log", "--hz", "60,120", "--substeps", "1,2", "--method", "rk4", "--method",
         "semi_implicit_euler", "--method", "implicit_euler"]


def test_a_two_axis_scan_has_a_map_per_method(stepbench, tmp_path):
    """A scan of two axes (the rope over masses x k_s): a figure per rate with a map per
    method at one step a frame, whose cells are the file's runs; with a reference budget
    that leaves some points without references (where this stepbench has the option),
    their completed runs are stable with no error and their diverged ones not completed,
    and the page says why those points have no truth."""
    import sys
    from test_report import ROOT
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    from stepbench_report import scan as scan_section
    from stepbench_report import study as study_reader
    budget = "--reference-budget" in run([stepbench, "scan", "--help"]).stdout
    path = tmp_path / "chain.h5"
    p = run([stepbench, "scan", *CHAIN, *(["--reference-budget", "2e3"] if budget else []), "--out", str(path),
             "--quiet"], timeout=300)
    assert p.returncode == 0, p.stderr
    out = tmp_path / "report"
    p = run([PYTHON, REPORT, str(path), "--out", str(out), "--jobs", "2"], timeout=180)
    assert p.returncode == 0, p.stderr
    md = report_text(out)
    figs = re.findall(r"!\[[^\]]*\]\((fig/[^)]+\.png)\)", md)
    assert figs == ["fig/scan_spring_chain_one_step_60hz.png", "fig/scan_spring_chain_one_step_120hz.png",
                    "fig/scan_spring_chain_cheapest.png"]
    from matplotlib import image
    for img in figs:
        pixels = image.imread(out / img)
        assert pixels.shape[1] <= 1400 and pixels[..., :3].std() > 0.05, img
    assert "A figure per frame rate, a map per method: x masses, y k_s" in md and "not be readable" not in md
    with h5py.File(path) as f:
        s = next(iter(scan_section.read(study_reader._Reader(str(path), f), f)))
        g = f["scan/spring_chain"]
        points, runs = g["points"][()], g["runs"][()]
        has_budget = "reference_budget" in g.attrs
    trusted = dict(zip(points["point"].tolist(), points["trusted"].tolist()))
    for hz in (60.0, 120.0):
        err, state = scan_section.one_step_grid(s, hz)
        assert state.shape == (3, 4)
        for r in runs[(runs["hz"] == hz) & (runs["substeps"] == 1)]:
            k, i = s.methods.index(text(r["method"])), int(r["point"])
            if r["diverged"] or r["failed"]:
                assert state[k, i] == scan_section.UNSTABLE
            elif not trusted[i]:
                assert state[k, i] == scan_section.STABLE_NO_TRUTH and np.isnan(err[k, i])
            else:
                assert state[k, i] == scan_section.OK and err[k, i] == pytest.approx(np.log10(r["err_pos_max"]))
    untrusted = [text(n) for n in points["note"][points["trusted"] == 0]]
    if budget and untrusted:
        assert has_budget and all(n.startswith("references not run") for n in untrusted)
        assert "the references were not run, their predicted work over the scan's reference budget of 2e+03" in md
        assert "Stability is judged there" in md


def test_the_range_answer_is_stored_and_quoted(scan_files, scan_reports, stepbench):
    """The range answer is computed by stepbench when it writes the scan (`range_answer`),
    equal to what `advise --scan` prints at the scan's tolerance, and the report opens the
    scan's section with it, verbatim."""
    import sys
    sys.path.insert(0, os.path.join(os.path.dirname(REPORT)))
    from stepbench_report import range_answer as scan_mod
    path, out = scan_reports["whole"]
    with h5py.File(path) as f:
        stored = f["scan/stiff_spring"].attrs["range_answer"]
        stored = stored.decode() if isinstance(stored, bytes) else stored
        tol = float(f["scan/stiff_spring"].attrs["tol"])
    advised = run([stepbench, "advise", "--scan", str(path), "--tol", repr(tol)])
    # Exit 3: no method holds over the whole range at some rate (docs/commands.md).
    assert advised.returncode in (0, 3), advised.stderr
    assert advised.stdout == stored
    assert "rk4" in stored and "60 Hz" in stored
    text = report_text(out)
    for line in stored.strip().split("\n"):
        assert line.strip() in text, line
    assert scan_mod.range_answers(str(path)) == [("stiff_spring", stored)]
