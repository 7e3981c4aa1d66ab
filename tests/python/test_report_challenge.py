"""The report's pendulum-challenge section (scripts/stepbench_report/challenge.py) on a
study holding /challenge: `stepbench sweep --problem n_pendulum` at a few levels (the
challenge runs with every full sweep of n_pendulum; --quick leaves it out, so
conftest.py's plain_study is the study without it). Every number is checked against the
file read with h5py, independently of the report's code.

The report requires /challenge/entries' `tolerance` (schema.json). A stepbench built
before that column writes none, and no adaptive entry: challenge_study then adds the
column, NaN in every row, to a copy; adaptive_study adds a made-up adaptive entry where
the file has none, so that the tolerance is checked whichever stepbench wrote the file."""
import html
import os
import re
import subprocess
import sys

import h5py
import numpy as np
import pytest
from conftest import run_study

from test_report import PYTHON, REPORT, ROOT, drop_field, edit, md_table, report_text, run_report

TITLE = "## The pendulum challenge (XPBD, 50 substeps) and Small Steps"
FIGURE = "fig/pendulum_challenge.png"


def text(v):
    return v.decode() if isinstance(v, bytes) else v


ENTRIES = "challenge/entries"


def has_tolerance(path):
    with h5py.File(path, "r") as f:
        return "tolerance" in f[ENTRIES].dtype.names


def rewrite(f, path, rows):
    del f[path]
    f.create_dataset(path, data=rows)


def add_tolerance(f):
    """/challenge/entries with `tolerance` after `steps_per_frame`, NaN in every row (a
    fixed step's), as a stepbench built before the column would have written it."""
    rows = f[ENTRIES][()]
    names = list(rows.dtype.names)
    at = names.index("steps_per_frame") + 1
    new = np.empty(len(rows), dtype=[(n, rows.dtype[n]) for n in names[:at]] + [("tolerance", "<f8")]
                   + [(n, rows.dtype[n]) for n in names[at:]])
    for n in names:
        new[n] = rows[n]
    new["tolerance"] = np.nan
    rewrite(f, ENTRIES, new)


def add_adaptive_entry(f):
    """A made-up adaptive entry after rk8, with rk8's numbers: "dop853" at tolerance 1e-07,
    3 steps a frame."""
    rows = f[ENTRIES][()]
    at = [text(m) for m in rows["method"]].index("rk8") + 1
    new = np.insert(rows, at, rows[at - 1])
    new["method"][at] = b"dop853"
    new["tolerance"][at] = 1e-7
    new["steps_per_frame"][at] = 3
    rewrite(f, ENTRIES, new)


@pytest.fixture(scope="module")
def challenge_written(stepbench, tmp_path_factory):
    """n_pendulum alone, 4 levels: the sweep is quick, the challenge (about 5 s) runs whole."""
    path = tmp_path_factory.mktemp("challenge") / "written.h5"
    run_study([stepbench, "sweep", "--problem", "n_pendulum", "--levels", "4", "--max-levels", "4", "--quiet",
               "--out", str(path)], stdout=subprocess.DEVNULL, timeout=300)
    with h5py.File(path, "r") as f:
        assert "challenge" in f, "a full sweep of n_pendulum writes /challenge"
    return path


@pytest.fixture(scope="module")
def challenge_study(challenge_written, tmp_path_factory):
    """stepbench's file; from a stepbench built before /challenge/entries had `tolerance`,
    a copy with the column added (add_tolerance)."""
    if has_tolerance(challenge_written):
        return challenge_written
    path = tmp_path_factory.mktemp("challenge") / "study.h5"
    edit(challenge_written, path, add_tolerance)
    return path


@pytest.fixture(scope="module")
def adaptive_study(challenge_study, tmp_path_factory):
    """challenge_study where it has an adaptive entry (finite tolerance), else a copy with
    a made-up one (add_adaptive_entry)."""
    with h5py.File(challenge_study, "r") as f:
        if np.isfinite(f[ENTRIES]["tolerance"]).any():
            return challenge_study
    path = tmp_path_factory.mktemp("adaptive") / "study.h5"
    edit(challenge_study, path, add_adaptive_entry)
    return path


def made_report(study, tmp_path_factory):
    out = tmp_path_factory.mktemp("challenge_report") / "report"
    p = run_report(study, out, jobs=2)
    assert p.returncode == 0, p.stderr
    assert p.stderr == ""
    return study, out


@pytest.fixture(scope="module")
def challenge_report(challenge_study, tmp_path_factory):
    return made_report(challenge_study, tmp_path_factory)


@pytest.fixture(scope="module")
def adaptive_report(adaptive_study, challenge_study, challenge_report, tmp_path_factory):
    return challenge_report if adaptive_study == challenge_study else made_report(adaptive_study, tmp_path_factory)


def section(md):
    start = md.index(f"\n{TITLE}\n")
    return md[start:md.index("\n## ", start + 1)]


def verdicts(study, criterion):
    with h5py.File(study, "r") as f:
        rows = f["challenge/verdicts"][()]
    return [text(v) for c, v in zip(rows["criterion"], rows["verdict"]) if text(c) == criterion]


def test_the_section_opens_on_the_verdicts(challenge_report):
    """The section's first lines are the accuracy, stability and speed lines as stepbench
    wrote them, on its page too (challenge.html, the section's heading its title); the Small
    Steps lines follow under their heading."""
    study, folder = challenge_report
    md = report_text(folder)
    answer = [line for c in ("accuracy", "stability", "speed") for line in verdicts(study, c)]
    assert [a.split(" ")[0] for a in answer] == ["accuracy", "stability", "speed"]
    lines = [x for x in section(md).splitlines()[2:] if x.strip()]
    assert lines[:3] == answer
    small = verdicts(study, "small_steps")
    assert [s.split(":")[0] for s in small] == ["n_pendulum", "spring_chain"]
    sub = section(md)[section(md).index("\n### Small Steps: substeps against iterations\n"):]
    assert [x for x in sub.splitlines()[2:] if x.strip()][:2] == small
    page = html.unescape((folder / "challenge.html").read_text())
    for line in answer + small:
        assert f">{line}</p>" in page, line
    head = page.index('<h1 id="the-pendulum-challenge-xpbd-50-substeps-and-small-steps">')
    assert head < page.index(answer[0]) < page.index(answer[1]) < page.index(answer[2]) < page.index("<table", head)


def test_the_section_is_placed_and_listed(challenge_report):
    _, folder = challenge_report
    md = report_text(folder)
    assert md.index("\n## Small steps or one implicit step?") < md.index(f"\n{TITLE}\n") < md.index("\n## Energy\n")
    assert '<a href="challenge.html">' in (folder / "index.html").read_text()  # the index's list of pages


def number(cell):
    return float(cell.split(" ")[0])


def steps_cell(e):
    """An entry's "steps a frame": its steps, or an adaptive one's tolerance (a power of
    ten, written as the accuracy verdict writes it) and its steps."""
    k = int(e["steps_per_frame"])
    return f"tol {e['tolerance']:.0e} ({k})" if np.isfinite(e["tolerance"]) else str(k)


@pytest.mark.parametrize("shape", ["challenge_report", "adaptive_report"])
def test_the_entries_table_is_the_files(request, shape):
    """A row per entry, xpbd first, in the file's order; each number the file's (times in
    us); an adaptive entry's steps a frame: "tol 1e-07 (3)", its tolerance and its steps."""
    study, folder = request.getfixturevalue(shape)
    head, rows = md_table(section(report_text(folder)), "| method | steps a frame | time a frame [us] | bobs' max "
                          "error over 2 s [m] | energy drift over 1000 s [of 18 J] | largest energy error | link error"
                          " | time a frame at xpbd's error [us] | stable | note |")
    with h5py.File(study, "r") as f:
        entries = f["challenge/entries"][()]
        a = dict(f["challenge"].attrs)
        assert (float(a["horizon"]), float(a["energy_horizon"]), float(a["energy_scale"])) == (2.0, 1000.0, 18.0)
    assert [r[0] for r in rows] == [text(m) for m in entries["method"]]
    assert rows[0][0] == "xpbd" and rows[0][1] == str(int(a["xpbd_substeps"])) == "50"
    for cells, e in zip(rows, entries):
        r = dict(zip(head, cells))
        assert r["steps a frame"] == steps_cell(e)
        assert number(r["time a frame [us]"]) == pytest.approx(e["ns_per_frame"] / 1e3, rel=5e-3)
        assert number(r["bobs' max error over 2 s [m]"]) == pytest.approx(e["err_pos_max"], rel=5e-3)
        assert number(r["energy drift over 1000 s [of 18 J]"]) == pytest.approx(e["energy_drift"], rel=5e-3)
        assert number(r["largest energy error"]) == pytest.approx(e["energy_err_max"], rel=5e-3)
        assert number(r["link error"]) == pytest.approx(e["link_err_max"], rel=5e-3, abs=0)
        t = e["ns_per_frame_at_xpbd_error"]
        shown = r["time a frame at xpbd's error [us]"]
        assert shown == "n/a" if not np.isfinite(t) else number(shown) == pytest.approx(t / 1e3, rel=5e-3)
        assert r["stable"] == ("yes" if e["stable"] else "NO") and r["note"] == text(e["note"])
    # xpbd's own time at its own error is its time, and its links are the only ones not exact.
    assert rows[0][2] == rows[0][7]
    assert float(rows[0][6]) > 0 and all(float(r[6]) == 0 for r in rows[1:])
    if shape == "adaptive_report":
        assert any(re.fullmatch(r"tol 1e-\d\d \(\d+\)", r[1]) for r in rows), rows


def test_dop853_is_the_adaptive_entry(challenge_written):
    """From a stepbench that writes `tolerance`: dop853 is an entry, at one of the
    tolerances 1e-1, 1e-2, ..., every other entry at a fixed step (NaN), rk8 too; the
    accuracy verdict names it "dop853 tol 1e-07 (3 steps a frame)", the file's numbers."""
    if not has_tolerance(challenge_written):
        pytest.skip("stepbench was built before /challenge/entries had `tolerance`")
    with h5py.File(challenge_written, "r") as f:
        entries = f[ENTRIES][()]
    methods = [text(m) for m in entries["method"]]
    assert methods == ["xpbd", "rk4", "rk8", "dop853", "implicit_midpoint", "semi_implicit_euler"]
    tol = dict(zip(methods, entries["tolerance"]))
    assert [m for m in methods if np.isfinite(tol[m])] == ["dop853"]
    exponent = -np.log10(tol["dop853"])
    assert exponent == round(exponent) and 1 <= exponent <= 13, tol["dop853"]
    e = entries[methods.index("dop853")]
    assert e["steps_per_frame"] >= 1
    accuracy = verdicts(challenge_written, "accuracy")[0]
    assert f" dop853 tol {tol['dop853']:.0e} ({e['steps_per_frame']} steps a frame) " in accuracy, accuracy


def test_the_small_steps_table_is_the_files(challenge_report):
    study, folder = challenge_report
    sec = section(report_text(folder))
    head, rows = md_table(sec, "Position error [m] at t = 1 s for each n; then, at the largest n, the link error "
                               "(relative), the work a frame (force evaluations or constraint passes) and the "
                               "measured time a frame:")
    with h5py.File(study, "r") as f:
        small = f["challenge/small_steps"][()]
    problem = np.array([text(p) for p in small["problem"]])
    design = np.array([text(d) for d in small["design"]])
    pairs = list(dict.fromkeys(zip(problem, design)))
    assert sorted((r[0], r[1]) for r in rows) == sorted(pairs)
    ns = sorted(set(int(n) for n in small["n"]))
    assert head[2:2 + len(ns)] == [f"n = {n}" for n in ns]
    for cells in rows:
        r = dict(zip(head, cells))
        sel = small[(problem == r["problem"]) & (design == r["design"])]
        for row in sel:
            cell = r[f"n = {int(row['n'])}"]
            if row["diverged"]:
                assert cell == "diverged"
            else:
                assert float(cell) == pytest.approx(row["err_pos"], rel=5e-3)
        last = sel[np.argmax(sel["n"])]
        assert int(r["at n"]) == last["n"]
        assert number(r["time a frame [us]"]) == pytest.approx(last["ns_per_frame"] / 1e3, rel=5e-3)
        assert float(r["work a frame"]) == pytest.approx(last["work_per_frame"], rel=5e-3)
    # The implicit step is one step a frame: one n, no other cell.
    implicit = [r for r in rows if r[1] == "implicit_euler"]
    assert implicit and all(r[2] and not any(r[3:2 + len(ns)]) for r in implicit)


def test_the_figure_names_its_entries_and_letters_its_panels(adaptive_study, monkeypatch):
    """Drawn from the file: each entry named "rk4 x7", an adaptive one "dop853 tol 1e-07";
    the panels (a) the challenge, then (b), (c) Small Steps a problem each, and the
    legend's Small Steps entries "(b, c) ..."."""
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    try:
        from stepbench_report import challenge, figures, study as study_module
    finally:
        sys.path.pop(0)
    drawn = []
    monkeypatch.setattr(figures, "_save", lambda fig, path, tight=True: drawn.append(fig))
    s = study_module.load(str(adaptive_study))
    challenge.figure(s.challenge, figures.Styles(figures.method_names(s)), "unused.png")
    fig = drawn[0]
    with h5py.File(adaptive_study, "r") as f:
        entries = f[ENTRIES][()]
        problems = list(dict.fromkeys(text(p) for p in f["challenge/small_steps"]["problem"]))
    assert problems == ["n_pendulum", "spring_chain"]
    titles = [ax.get_title() for ax in fig.axes]
    assert titles[0].startswith("(a) the challenge")
    assert titles[1:] == ["(b) Small Steps: n_pendulum", "(c) Small Steps: spring_chain"]
    names = [t.get_text() for t in fig.axes[0].texts]
    want = []
    for e in entries:
        if not (np.isfinite(e["ns_per_frame"]) and np.isfinite(e["err_pos_max"]) and e["err_pos_max"] > 0):
            continue
        name = text(e["method"]) + (f" tol {e['tolerance']:.0e}" if np.isfinite(e["tolerance"])
                                    else f" x{e['steps_per_frame']}")
        want.append(name + ("" if e["stable"] else " (unstable)"))
    assert names == want
    assert any(re.fullmatch(r"dop853 tol 1e-\d\d", n) for n in names), names
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert [x for x in legend if not x.startswith("(a) ")] and all(
        x.startswith("(b, c) ") for x in legend if not x.startswith("(a) ")), legend


def test_the_figure_exists_and_fits(challenge_report):
    from matplotlib import image
    _, folder = challenge_report
    sec = section(report_text(folder))
    assert re.findall(r"!\[[^\]]*\]\((fig/[^)]+\.png)\)", sec) == [FIGURE]
    pixels = image.imread(folder / FIGURE)
    assert pixels.ndim == 3 and 800 <= pixels.shape[1] <= 1400 and pixels.shape[0] > 300, pixels.shape
    assert pixels[..., :3].std() > 0.05  # not blank
    assert f'src="{FIGURE}"' in (folder / "challenge.html").read_text()
    # The caption letters the Small Steps panels as the figure does.
    assert "(b, c) Small Steps (Macklin et al., SCA 2019), (b) on n_pendulum and (c) on spring_chain: " in sec
    assert "(b) Small Steps (" not in sec


@pytest.fixture(scope="module")
def challenge_answers(challenge_study, stepbench, tmp_path_factory):
    """`scripts/report --markdown results.md --readme README.md` of challenge_study (the
    block from its `stepbench summary`), once: (the finished process, README.md, results.md)."""
    d = tmp_path_factory.mktemp("challenge_answers")
    readme, results, summary = d / "README.md", d / "results.md", d / "summary.json"
    readme.write_text("# project\n\n<!-- results:begin -->\nold\n<!-- results:end -->\n")
    subprocess.run([stepbench, "summary", "--study", str(challenge_study), "--out", str(summary)], check=True,
                   timeout=60)
    p = subprocess.run([PYTHON, REPORT, str(challenge_study), "--markdown", str(results), "--readme", str(readme),
                        "--summary", str(summary)], capture_output=True, text=True, timeout=60)
    return p, readme, results


def test_markdown_and_readme_carry_the_verdicts(challenge_study, challenge_answers):
    p, readme, results = challenge_answers
    assert p.returncode == 0, p.stderr
    answer = [line for c in ("accuracy", "stability", "speed") for line in verdicts(challenge_study, c)]
    small = verdicts(challenge_study, "small_steps")
    md = results.read_text()
    assert md.index("## Findings") < md.index("## Pendulum challenge")
    at = [md.index(f"- {line}\n") for line in answer + small]
    assert at == sorted(at)
    assert md.index("Small Steps:") < md.index(f"- {small[0]}")
    # The README's block is a front page: it names docs/results.md for the challenge.
    block = readme.read_text()
    assert "Pendulum challenge" not in block and "[docs/results.md](docs/results.md)" in block


DESIGN_COLUMNS = {"XPBD: n substeps of one pass": "xpbd_substeps", "XPBD: one step of n passes": "xpbd_iterations",
                  "semi-implicit Euler: n substeps": "semi_implicit_euler_substeps",
                  "implicit Euler: one step": "implicit_euler"}
SHOWN_COUNTS = (1, 4, 16, 64)


def small_steps_table(doc):
    """The Small Steps table of --readme and --markdown: (caption, head, rows)."""
    caption = next(x for x in doc.splitlines() if x.startswith("Small Steps at t = "))
    head, rows = md_table(doc, caption)
    return caption, head, rows


def test_readme_and_markdown_carry_the_small_steps_table(challenge_study, challenge_answers):
    """--markdown carries Small Steps as one table (the README's block names it): a row per problem
    and n (1, 4, 16, 64 of the study's n), a column per design, each cell the file's error
    and time a frame ("0.0144 m, 6.74 us", three digits) or "diverged"; implicit Euler's
    one step at n = 1 only."""
    p, readme, results = challenge_answers
    assert p.returncode == 0, p.stderr
    block = readme.read_text()
    with h5py.File(challenge_study, "r") as f:
        small = f["challenge/small_steps"][()]
        t = float(f["challenge"].attrs["small_steps_time"])
    problem = np.array([text(x) for x in small["problem"]])
    design = np.array([text(x) for x in small["design"]])
    ns = sorted({int(n) for n in small["n"]})
    assert ns == [1, 2, 4, 8, 16, 32, 64]
    shown = [n for n in ns if n in SHOWN_COUNTS]
    assert "Small Steps at t = " not in block
    caption, head, rows = small_steps_table(results.read_text())
    assert caption.startswith(f"Small Steps at t = {t:g} s: ")
    assert "(n = 1, 4, 16, 64 of the study's 1 to 64; every n in the report)" in caption
    assert head == ["problem", "n"] + list(DESIGN_COLUMNS)
    assert [(r[0], int(r[1])) for r in rows] == [(p, n) for p in ("n_pendulum", "spring_chain") for n in shown]
    diverged = 0
    for cells in rows:
        r = dict(zip(head, cells))
        for column, d in DESIGN_COLUMNS.items():
            sel = small[(problem == r["problem"]) & (design == d) & (small["n"] == int(r["n"]))]
            assert len(sel) <= 1
            if not len(sel):
                assert r[column] == "", (r, column)
            elif sel[0]["diverged"]:
                assert r[column] == "diverged"
                diverged += 1
            else:
                e = sel[0]
                assert r[column] == f"{e['err_pos']:.3g} m, {e['ns_per_frame'] / 1e3:.3g} us", (r, column)
                m = re.fullmatch(r"(\S+) m, (\S+) us", r[column])
                assert float(m[1]) == pytest.approx(e["err_pos"], rel=5e-3)
                assert float(m[2]) == pytest.approx(e["ns_per_frame"] / 1e3, rel=5e-3)
        assert (r["implicit Euler: one step"] != "") == (r["n"] == "1")
    assert diverged == np.count_nonzero(small["diverged"][np.isin(small["n"], shown)])
    # After the Small Steps lines.
    lines = verdicts(challenge_study, "small_steps")
    md = results.read_text()
    assert md.index(f"- {lines[-1]}\n") < md.index(caption)


def test_a_study_without_challenge_has_no_such_section(plain_study, reports):
    with h5py.File(plain_study, "r") as f:
        assert "challenge" not in f  # --quick leaves it out
    out = reports["plain"][1]  # drawn once a session (conftest.py), exit 0 checked there
    md = report_text(out)
    assert "pendulum challenge (XPBD" not in md and "Small Steps: substeps against iterations" not in md
    assert not (out / FIGURE).exists()
    assert "challenge.html" not in (out / "index.html").read_text() and not (out / "challenge.html").exists()


@pytest.mark.parametrize("path, field", [("challenge/entries", "err_pos_max"), ("challenge/entries", "tolerance"),
                                         ("challenge/verdicts", "verdict"), ("challenge/small_steps", "diverged")])
def test_a_challenge_lacking_a_field_is_refused(challenge_study, tmp_path, path, field):
    bad = tmp_path / "bad.h5"
    edit(challenge_study, bad, drop_field(path, field))
    p = run_report(bad, tmp_path / "report")
    assert p.returncode == 1
    lines = p.stderr.splitlines()
    assert len(lines) == 1 and f"/{path} lacks field {field}" in lines[0], p.stderr
    assert not (tmp_path / "report").exists()
