"""The report's pendulum-challenge section (scripts/stepbench_report/challenge.py) on a
study holding /challenge: `stepbench sweep --problem n_pendulum` at a few levels (the
challenge runs with every full sweep of n_pendulum; --quick leaves it out, so
conftest.py's plain_study is the study without it). Every number is checked against the
file read with h5py, independently of the report's code."""
import html
import re
import subprocess

import h5py
import numpy as np
import pytest
from conftest import run_study

from test_report import PYTHON, REPORT, drop_field, edit, md_table, report_text, run_report

TITLE = "## The pendulum challenge (XPBD, 50 substeps) and Small Steps"
FIGURE = "fig/pendulum_challenge.png"


def text(v):
    return v.decode() if isinstance(v, bytes) else v


@pytest.fixture(scope="module")
def challenge_study(stepbench, tmp_path_factory):
    """n_pendulum alone, 4 levels: the sweep is quick, the challenge (about 5 s) runs whole."""
    path = tmp_path_factory.mktemp("challenge") / "study.h5"
    run_study([stepbench, "sweep", "--problem", "n_pendulum", "--levels", "4", "--max-levels", "4", "--quiet",
               "--out", str(path)], stdout=subprocess.DEVNULL, timeout=300)
    with h5py.File(path, "r") as f:
        assert "challenge" in f, "a full sweep of n_pendulum writes /challenge"
    return path


@pytest.fixture(scope="module")
def challenge_report(challenge_study, tmp_path_factory):
    out = tmp_path_factory.mktemp("challenge_report") / "report"
    p = run_report(challenge_study, out, jobs=2)
    assert p.returncode == 0, p.stderr
    assert p.stderr == ""
    return challenge_study, out


def section(md):
    start = md.index(f"\n{TITLE}\n")
    return md[start:md.index("\n## ", start + 1)]


def verdicts(study, criterion):
    with h5py.File(study, "r") as f:
        rows = f["challenge/verdicts"][()]
    return [text(v) for c, v in zip(rows["criterion"], rows["verdict"]) if text(c) == criterion]


def test_the_section_opens_on_the_verdicts(challenge_report):
    """The section's first lines are the accuracy, stability and speed lines as stepbench
    wrote them, in index.html too; the Small Steps lines follow under their heading."""
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
    page = html.unescape((folder / "index.html").read_text())
    for line in answer + small:
        assert f">{line}</p>" in page, line
    head = page.index('<h2 id="the-pendulum-challenge-xpbd-50-substeps-and-small-steps">')
    assert head < page.index(answer[0]) < page.index(answer[1]) < page.index(answer[2]) < page.index("<table", head)


def test_the_section_is_placed_and_listed(challenge_report):
    _, folder = challenge_report
    md = report_text(folder)
    assert md.index("\n## Small steps or one implicit step?") < md.index(f"\n{TITLE}\n") < md.index("\n## Energy\n")
    assert '<a href="#the-pendulum-challenge-xpbd-50-substeps-and-small-steps">' in (folder / "index.html").read_text()


def number(cell):
    return float(cell.split(" ")[0])


def test_the_entries_table_is_the_files(challenge_report):
    """A row per entry, xpbd first, in the file's order; each number the file's (times in us)."""
    study, folder = challenge_report
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
        assert int(r["steps a frame"]) == e["steps_per_frame"]
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


def test_the_figure_exists_and_fits(challenge_report):
    from matplotlib import image
    _, folder = challenge_report
    sec = section(report_text(folder))
    assert re.findall(r"!\[[^\]]*\]\((fig/[^)]+\.png)\)", sec) == [FIGURE]
    pixels = image.imread(folder / FIGURE)
    assert pixels.ndim == 3 and 800 <= pixels.shape[1] <= 1400 and pixels.shape[0] > 300, pixels.shape
    assert pixels[..., :3].std() > 0.05  # not blank
    assert f'src="{FIGURE}"' in (folder / "index.html").read_text()


def test_markdown_and_readme_carry_the_verdicts(challenge_study, tmp_path):
    readme, results = tmp_path / "README.md", tmp_path / "results.md"
    readme.write_text("# project\n\n<!-- results:begin -->\nold\n<!-- results:end -->\n")
    p = subprocess.run([PYTHON, REPORT, str(challenge_study), "--markdown", str(results), "--readme", str(readme)],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    answer = [line for c in ("accuracy", "stability", "speed") for line in verdicts(challenge_study, c)]
    small = verdicts(challenge_study, "small_steps")
    md = results.read_text()
    assert md.index("## Findings") < md.index("## Pendulum challenge")
    block = readme.read_text()
    for doc in (md, block):
        at = [doc.index(f"- {line}\n") for line in answer + small]
        assert at == sorted(at)
    assert "**Pendulum challenge**" in block
    assert block.index("Small Steps:") < block.index(f"- {small[0]}") < block.index(f"Study `{challenge_study}`")


def test_a_study_without_challenge_has_no_such_section(plain_study, tmp_path):
    with h5py.File(plain_study, "r") as f:
        assert "challenge" not in f  # --quick leaves it out
    out = tmp_path / "report"
    p = run_report(plain_study, out)
    assert p.returncode == 0, p.stderr
    md = report_text(out)
    assert "pendulum challenge (XPBD" not in md and "Small Steps: substeps against iterations" not in md
    assert not (out / FIGURE).exists()
    assert "pendulum-challenge" not in (out / "index.html").read_text()
    readme = tmp_path / "README.md"
    readme.write_text("<!-- results:begin -->\n<!-- results:end -->\n")
    p = subprocess.run([PYTHON, REPORT, str(plain_study), "--readme", str(readme)], capture_output=True, text=True,
                       timeout=60)
    assert p.returncode == 0, p.stderr
    assert "Pendulum challenge" not in readme.read_text()


@pytest.mark.parametrize("path, field", [("challenge/entries", "err_pos_max"), ("challenge/verdicts", "verdict"),
                                         ("challenge/small_steps", "diverged")])
def test_a_challenge_lacking_a_field_is_refused(challenge_study, tmp_path, path, field):
    bad = tmp_path / "bad.h5"
    edit(challenge_study, bad, drop_field(path, field))
    p = run_report(bad, tmp_path / "report")
    assert p.returncode == 1
    lines = p.stderr.splitlines()
    assert len(lines) == 1 and f"/{path} lacks field {field}" in lines[0], p.stderr
    assert not (tmp_path / "report").exists()
