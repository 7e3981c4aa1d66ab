"""The report as a small site (issue 32): index.html opens on the per-frame answer at the
chosen rate and tolerances (1e-3 among them by default), then the equal-error verdict,
each problem's name linking to its page; --hz and --tol set the first table, and a value
the study does not hold is one line naming what it holds, exit 2, nothing written. The
reports are conftest.py's (drawn once a session) where the flags are the defaults; the
others are of one problem (three figures)."""
import re
import subprocess
from html.parser import HTMLParser

import h5py
import numpy as np
import pytest
from conftest import PYTHON, REPORT


class Outline(HTMLParser):
    """A page's headings and tables in order (("h2", text) and ("table", class)), its
    links, and the text of its first table's header and first column."""

    def __init__(self):
        super().__init__()
        self.order, self.links, self.head, self.first_column = [], [], [], []
        self._in, self._tables, self._text, self._cell = None, 0, "", 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag in ("h1", "h2", "h3"):
            self._in, self._text = tag, ""
        elif tag == "table":
            self._tables += 1
            self.order.append(("table", a.get("class", "")))
        elif tag == "a" and "href" in a:
            self.links.append(a["href"])
        elif tag in ("th", "td") and self._tables == 1:
            self._in, self._text = tag, ""
        elif tag == "tr":
            self._cell = 0

    def handle_data(self, data):
        if self._in:
            self._text += data

    def handle_endtag(self, tag):
        if tag != self._in:
            return
        if tag in ("h1", "h2", "h3"):
            self.order.append((tag, self._text.strip()))
        elif tag == "th":
            self.head.append(self._text.strip())
        elif tag == "td":
            if self._cell == 0:
                self.first_column.append(self._text.strip())
            self._cell += 1
        self._in = None


def outline(path):
    o = Outline()
    o.feed(path.read_text())
    return o


def answers(study):
    with h5py.File(study, "r") as f:
        return f["verdict/frame_answer"][()], f["verdict"].attrs["frame_hz"], f["verdict"].attrs["targets"]


def run(study, out, *args):
    return subprocess.run([PYTHON, REPORT, str(study), "--out", str(out), *args], capture_output=True, text=True,
                          timeout=120)


@pytest.mark.parametrize("shape", ["plain", "timed"])
def test_the_index_opens_on_the_answer_a_frame(reports, shape):
    """Title, then the per-frame answer (a 1e-3 column by default), then the equal-error
    verdict, before anything else; no figure on the index."""
    _, folder = reports[shape]
    o = outline(folder / "index.html")
    assert o.order[0][0] == "h1"
    assert o.order[1] == ("h2", "At 60 Hz: which method, how many substeps, what a frame costs")
    assert o.order[2] == ("table", "answer")
    assert o.order[3] == ("h2", "Fastest at equal error") and o.order[4] == ("table", "verdict")
    assert [h.split(" ")[0] for h in o.head[1:4]] == ["1e-2", "1e-3", "1e-4"]
    assert "<img" not in (folder / "index.html").read_text()


@pytest.mark.parametrize("shape", ["plain", "timed"])
def test_the_answer_is_the_files(reports, shape):
    """Each cell is /verdict/frame_answer's row at 60 Hz: method, substeps, error."""
    study, folder = reports[shape]
    fa, _, _ = answers(study)
    page = (folder / "index.html").read_text()
    table = page[page.index('<table class="answer">'):]
    table = table[:table.index("</table>")]
    rows = re.findall(r"<tr>(.*?)</tr>", table, re.S)[1:]
    names = [re.search(r'<a href="problems/(\w+)\.html">', r).group(1) for r in rows]
    assert names and len(names) == len(set(fa["problem"]))
    for name, row in zip(names, rows):
        cells = re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)[1:4]
        for t, cell in zip((1e-2, 1e-3, 1e-4), cells):
            a = fa[(fa["problem"].astype(str) == name) & (fa["hz"] == 60) & np.isclose(fa["target"], t)][0]
            method = a["method"].decode() if isinstance(a["method"], bytes) else a["method"]
            if method:
                assert cell.startswith(f"<b>{method}</b> x{int(a['substeps'])} "), (name, t, cell)
                error = float(re.search(r"error ([0-9.e+-]+)", cell).group(1))
                assert error == pytest.approx(a["err_pos_max"], rel=0.06), (name, t, cell)
            else:
                assert "none within 64 substeps" in cell, (name, t, cell)


def test_every_link_resolves(reports):
    """The index's problem names link to their pages, and every page's links and images
    resolve inside the folder."""
    study, folder = reports["timed"]
    with h5py.File(study, "r") as f:
        problems = set(f["problems"])
    index = outline(folder / "index.html")
    assert {f"problems/{p}.html" for p in problems} <= set(index.links)
    for page in folder.rglob("*.html"):
        text = page.read_text()
        for target in re.findall(r'(?:href|src)="([^"#]+)"', text):
            assert (page.parent / target).resolve().is_file(), (page.name, target)
    pendulum = outline(folder / "problems" / "pendulum.html")
    assert pendulum.order[0] == ("h1", "pendulum")
    # The work-precision figure first, then the tables.
    text = (folder / "problems" / "pendulum.html").read_text()
    assert text.index('src="../fig/work_precision_pendulum.png"') < text.index("<table")


def test_hz_and_tol_set_the_first_table(plain_study, tmp_path):
    out = tmp_path / "r"
    _, rates, targets = answers(plain_study)
    hz = next(h for h in rates if h != 60)
    p = run(plain_study, out, "--problem", "pendulum", "--hz", f"{hz:g}", "--tol", "1e-5,1e-3", "--tol", "1e-7")
    assert p.returncode == 0, p.stderr
    o = outline(out / "index.html")
    assert o.order[1] == ("h2", f"At {hz:g} Hz: which method, how many substeps, what a frame costs")
    assert [h.split(" ")[0] for h in o.head[1:4]] == ["1e-5", "1e-3", "1e-7"]
    assert o.first_column[0].startswith("pendulum [rad]")


@pytest.mark.parametrize("args, needle", [
    (["--hz", "144"], "--hz 144: the study holds per-frame answers at the rates 30, 60, 120, 240 only"),
    (["--tol", "3e-3"], "--tol 3e-3: the study holds per-frame answers at the targets 1e-2, 1e-3, 1e-4,"),
    (["--tol", "1e-3,abc"], "--tol: must be positive numbers"),
    (["--hz", "-60"], "--hz: must be a positive rate")])
def test_a_bad_hz_or_tol_is_one_line(plain_study, tmp_path, args, needle):
    out = tmp_path / "r"
    out.mkdir()
    (out / ".stepbench-report").write_text("")
    (out / "index.html").write_text("old")
    p = run(plain_study, out, *args)
    assert p.returncode == 2, p.stderr
    assert needle in p.stderr.splitlines()[-1]
    if "study holds" in needle:
        assert len(p.stderr.splitlines()) == 1 and p.stdout == ""
    assert sorted(x.name for x in out.iterdir()) == [".stepbench-report", "index.html"]
    assert (out / "index.html").read_text() == "old"
    assert [x for x in tmp_path.iterdir() if x.name != "r"] == []
