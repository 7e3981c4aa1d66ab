"""The report's parameter-scan section (scripts/stepbench_report/scan.py) on the quick
study (conftest.py's plain_study: `stepbench sweep --quick`, which holds the stiff
spring's scan over k_s at 60 Hz). Every number is checked against the file read with
h5py, independently of the report's code."""
import os
import re
import subprocess
import sys

import h5py
import numpy as np
import pytest

from test_report import PYTHON, REPORT, md_table, report_text

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))


def text(v):
    return v.decode() if isinstance(v, bytes) else v


@pytest.fixture(scope="module")
def scan_report(reports):
    """(the quick study, its report): conftest.py's, drawn once a session."""
    return reports["plain"]


def section(md):
    start = md.index("\n## Parameter scans\n")
    return md[start:md.index("\n## ", start + 1)]


def one_step_runs(f, method, hz=60.0):
    r = f["scan/stiff_spring/runs"][()]
    sel = r[(np.char.decode(r["method"].astype(bytes)) == method) & (r["hz"] == hz) & (r["substeps"] == 1)]
    return np.sort(sel, order="point")


def test_the_scan_section_is_placed_and_listed(scan_report):
    study, folder = scan_report
    md = report_text(folder)
    html = (folder / "index.html").read_text()
    assert md.index("\n## Small steps or one implicit step?") < md.index("\n## Parameter scans\n") \
        < md.index("\n## Appendix: how the problem sections are made") < md.index("\n## Appendix: the study")
    assert '<a href="scans.html">' in html  # the index's list of pages
    assert (folder / "scans.html").is_file()
    assert "### Scan stiff_spring: stiff_spring over k_s" in section(md)


def test_the_scan_figures_exist_and_load(scan_report):
    from matplotlib import image
    _, folder = scan_report
    sec = section(report_text(folder))
    imgs = re.findall(r"!\[[^\]]*\]\((fig/[^)]+\.png)\)", sec)
    assert imgs == ["fig/scan_stiff_spring_one_step.png", "fig/scan_stiff_spring_cheapest.png"]
    for img in imgs:
        pixels = image.imread(folder / img)
        assert pixels.ndim == 3 and pixels.shape[1] <= 1400 and pixels.shape[0] > 150, (img, pixels.shape)
        assert pixels[..., :3].std() > 0.05, img  # not blank


def test_first_unstable_and_limits_are_the_files(scan_report):
    """The table under the map: the first k_s whose run at one step a frame did not
    complete is the file's, and the k_s at the oscillator limit is m (y hz)^2 from
    /stability/limits; the two agree within one grid cell."""
    study, folder = scan_report
    head, rows = md_table(section(report_text(folder)), "Where each method stops completing at one step a frame "
                                                        "(k_s; none: it completed at every point):")
    shown = {r[0]: dict(zip(head, r)) for r in rows}
    with h5py.File(study) as f:
        ks = f["scan/stiff_spring/values/k_s"][()]
        assert list(f["scan/stiff_spring"].attrs["hz"]) == [60.0]
        lim = f["stability/limits"][()]
        for method in ("rk4", "semi_implicit_euler", "velocity_verlet"):
            runs = one_step_runs(f, method)
            assert len(runs) == len(ks)
            bad = np.flatnonzero(runs["completed"] == 0)
            assert len(bad), method
            first = ks[runs["point"][bad[0]]]
            assert shown[method]["60 Hz: first k_s not completed"] == f"{first:.3g}", method
            row = lim[(np.char.decode(lim["integrator"].astype(bytes)) == method)
                      & (np.char.decode(lim["test"].astype(bytes)) == "oscillator")][0]
            at_limit = 1.0 * (row["theory"] * 60.0) ** 2
            assert shown[method]["oscillator limit omega dt"] == f"{row['theory']:.4g}"
            assert shown[method]["60 Hz: k_s at the limit"] == f"{at_limit:.3g}"
            # Map and theory agree: the first unstable cell is the limit's cell or the next.
            cell = np.argmin(np.abs(np.log10(ks) - np.log10(at_limit)))
            assert bad[0] - cell in (0, 1), (method, ks[cell], first)
    assert shown["implicit_euler"]["60 Hz: first k_s not completed"] == "none"


def test_the_drawn_grid_is_the_files(scan_report):
    """What the map draws (scan.one_step_grid, as read by the report's reader) is the
    file's runs at one step a frame."""
    from stepbench_report import scan as scan_section
    study, _ = scan_report
    scans = scan_section.load(str(study))
    s = next(x for x in scans if x.name == "stiff_spring")
    err, state = scan_section.one_step_grid(s, 60.0)
    with h5py.File(study) as f:
        for k, method in enumerate(s.methods):
            runs = one_step_runs(f, method)
            assert len(runs) == s.grid_points and not runs["skipped"].any()  # a whole scan, every run taken
            np.testing.assert_array_equal(state[k] == scan_section.UNSTABLE, runs["completed"] == 0)
            np.testing.assert_array_equal(state[k] == scan_section.OK, runs["completed"] == 1)
            ok = runs["completed"] == 1
            np.testing.assert_allclose(err[k][ok], np.log10(runs["err_pos_max"][ok]))
        assert scan_section.first_unstable(s, 60.0, "rk4") == \
            f["scan/stiff_spring/values/k_s"][()][np.flatnonzero(one_step_runs(f, "rk4")["completed"] == 0)[0]]


def test_the_cheapest_table_is_the_files_best(scan_report):
    study, folder = scan_report
    head, rows = md_table(section(report_text(folder)), next(
        line for line in report_text(folder).splitlines() if line.startswith("The scan's `best` table by rate")))
    assert len(rows) == 1 and rows[0][0] == "60 Hz"
    with h5py.File(study) as f:
        best = np.sort(f["scan/stiff_spring/best"][()], order="point")
        ks = f["scan/stiff_spring/values/k_s"][()]
    cheapest = rows[0][1]
    shown_points = 0
    for m, n in {(text(b["method"]), int(b["substeps"])) for b in best if text(b["method"])}:
        assert f"{m} x{n}: k_s " in cheapest, (m, n)
    for part in cheapest.split("; "):
        shown_points += int(re.search(r"\((\d+) points?\)$", part).group(1))
    none = [b for b in best if not text(b["method"])]
    if none:
        shown_points += int(re.search(r"\((\d+) points?\)$", rows[0][2]).group(1))
        assert f"{ks[none[0]['point']]:.3g}" in rows[0][2]
    else:
        assert rows[0][2] == "-"
    assert shown_points == len(best) == len(ks)
    # Each choice's first point is where `best` first names it.
    for b in best:
        if text(b["method"]):
            assert f"{text(b['method'])} x{int(b['substeps'])}: k_s" in cheapest


def test_a_study_without_scan_has_no_section(gaps_report, tmp_path):
    """An older study (no /scan): the report is the one it was before, with no scan section.
    The study is gaps_report's (three problems and five scans), whose report draws in a
    third of the time of the quick study's."""
    study, folder, _ = gaps_report
    old = tmp_path / "old.h5"
    import shutil
    shutil.copyfile(study, old)
    with h5py.File(old, "r+") as f:
        del f["scan"]
    out = tmp_path / "report"
    p = subprocess.run([PYTHON, REPORT, str(old), "--out", str(out), "--jobs", "2"], capture_output=True, text=True,
                       timeout=180)
    assert p.returncode == 0, p.stderr
    md = report_text(out)
    assert "## Parameter scans" not in md and "fig/scan_" not in md
    assert not [n for n in os.listdir(out / "fig") if n.startswith("scan_")]
    # Apart from the study's name and the scan section, the documents are the same.
    with_scan = report_text(folder)
    cut = with_scan[:with_scan.index("\n## Parameter scans\n")] + \
        with_scan[with_scan.index("\n## Appendix: how the problem sections are made"):]
    cut = cut.replace(", [Parameter scans](scans.html)", "")  # the index's list of pages
    assert cut.replace(str(study), "S").replace(os.path.basename(str(study)), "S") == \
        md.replace(str(old), "S").replace("old.h5", "S")


# --- scans that do not speak for every grid point --------------------------------------------------
# Real scans by the stepbench under test: the stiff spring over k_s (9 points, log) at 30
# and 60 Hz in three shards, two of them merged with `merge --partial` (the third's 3 points
# missing) and one shard as it is; the sliding block over its 34 friction pairs, lubricated,
# where the lecture's table lacks most coefficients (those points are not run: their truth
# is not trusted); and rk8 on the stiff spring at 60 Hz and 7864320 Hz with 1 and 524288
# substeps, whose runs over the work budget are skipped. Each is copied under /scan/<name>
# of a copy of the quick study, and the report drawn from it once.

SPRING_AXIS = "stiff_spring.k_s=1e1:1e7:9:log"
GRAFTED = {"partial": "partial.h5", "shard2": "s2.h5", "lub": "lub.h5", "budget": "budget.h5"}


def scan_cmd(stepbench, out, *args):
    p = subprocess.run([stepbench, "scan", *args, "--out", str(out), "--quiet"], capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 0, p.stderr


@pytest.fixture(scope="module")
def scan_files(stepbench, tmp_path_factory):
    d = tmp_path_factory.mktemp("scan_files")
    for k in (1, 2, 3):
        scan_cmd(stepbench, d / f"s{k}.h5", "--problem", "stiff_spring", "--param", SPRING_AXIS, "--hz", "30,60",
                 "--shard", f"{k}/3")
    p = subprocess.run([stepbench, "merge", "--partial", "-o", str(d / "partial.h5"), str(d / "s1.h5"),
                        str(d / "s3.h5")], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    scan_cmd(stepbench, d / "lub.h5", "--problem", "sliding_block", "--param", "sliding_block.material=0:33:34",
             "--set", "sliding_block.lubricated=1", "--hz", "60", "--substeps", "1,4")
    scan_cmd(stepbench, d / "budget.h5", "--problem", "stiff_spring", "--param", "stiff_spring.k_s=1e1:1e7:3:log",
             "--hz", "60,7864320", "--substeps", "1,524288", "--method", "rk8")
    return d


def grafted(study, out, files):
    """A copy of `study` with each scan file's one scan under /scan/<name>."""
    import shutil
    shutil.copyfile(study, out)
    with h5py.File(out, "r+") as f:
        for name, path in files.items():
            with h5py.File(path) as g:
                (only,) = g["scan"].keys()
                g.copy(g[f"scan/{only}"], f["scan"], name=name)
    return out


@pytest.fixture(scope="module")
def gaps_report(small_study, scan_files, tmp_path_factory):
    d = tmp_path_factory.mktemp("gaps_report")
    study = grafted(small_study, d / "study.h5", {n: scan_files / f for n, f in GRAFTED.items()})
    p = subprocess.run([PYTHON, REPORT, str(study), "--out", str(d / "report"), "--jobs", "2"], capture_output=True,
                       text=True, timeout=180)
    assert p.returncode == 0, p.stderr
    return study, d / "report", scan_files


def scan_part(md, name):
    """The subsection of one scan in the section."""
    sec = section(md)
    start = sec.index(f"\n### Scan {name}: ")
    end = sec.find("\n### ", start + 1)
    return sec[start:end if end >= 0 else None]


def scan_group(path):
    """(attrs, points, runs, best) of a file's one scan, read with h5py."""
    with h5py.File(path) as f:
        (g,) = f["scan"].values()
        return dict(g.attrs), g["points"][()], g["runs"][()], g["best"][()]


def load_scan(study, name):
    from stepbench_report import scan as scan_section
    return next(s for s in scan_section.load(str(study)) if s.name == name)


def table_after(part, caption_start):
    line = next(x for x in part.splitlines() if x.startswith(caption_start))
    return md_table(part, line)


def test_a_partial_merge_says_how_many_points_are_missing(gaps_report):
    study, folder, files = gaps_report
    attrs, points, _, _ = scan_group(files / "partial.h5")
    assert attrs["shard_count"] == 1 and len(points) < attrs["grid_points"]  # a partial merge, as stepbench wrote it
    part = scan_part(report_text(folder), "partial")
    m = re.search(r"A partial merge \(`stepbench merge --partial`\): (\d+) of the grid's (\d+) points are "
                  r"missing", part)
    assert m, part[:800]
    assert int(m.group(1)) == attrs["grid_points"] - len(points) == 3
    assert int(m.group(2)) == attrs["grid_points"] == 9
    assert f"the scan holds {len(points)}." in part
    imgs = re.findall(r"!\[[^\]]*\]\((fig/[^)]+\.png)\)", part)
    assert imgs == ["fig/scan_partial_one_step.png", "fig/scan_partial_cheapest.png"]
    from matplotlib import image
    for img in imgs:
        pixels = image.imread(folder / img)
        assert pixels.shape[1] <= 1400 and pixels[..., :3].std() > 0.05, img


def test_missing_cells_are_neither_stable_nor_unstable(gaps_report, monkeypatch):
    """The map at one step a frame: each missing point's column is MISSING for every method
    and rate, neither coloured by an error nor grey, but hatched across the column; the
    first point not completed is the file's first diverged or failed run among the points
    it holds, with the missing points below it counted."""
    from stepbench_report import figures
    from stepbench_report import scan as scan_section
    study, folder, files = gaps_report
    _, points, runs, _ = scan_group(files / "partial.h5")
    s = load_scan(study, "partial")
    missing = sorted(set(range(s.grid_points)) - set(points["point"].tolist()))
    assert missing == [1, 4, 7]
    kept = []
    monkeypatch.setattr(figures, "_save", lambda fig, path, tight=True: kept.append(fig))
    grids = scan_section.one_step_figure(s, None, 1.0, "unused.png")
    (fig,) = kept
    x_edges = scan_section._edges(s.values[0], s.log[0])
    for ax, (err, state) in zip(fig.axes, grids):
        assert (state[:, missing] == scan_section.MISSING).all()
        assert np.isnan(err[:, missing]).all()
        colour, grey = ax.collections[0], ax.collections[1]  # the error colours, the grey of not completed
        assert colour.get_array().mask.reshape(state.shape)[:, missing].all()
        assert grey.get_array().mask.reshape(state.shape)[:, missing].all()
        hatched = [(p.get_x(), p.get_height()) for p in ax.patches if p.get_hatch() == "////"]
        for i in missing:
            assert (x_edges[i], len(s.methods)) in hatched, i  # the whole column
    part = scan_part(report_text(folder), "partial")
    head, rows = table_after(part, "Where each method stops completing at one step a frame")
    shown = {r[0]: dict(zip(head, r)) for r in rows}
    values = s.values[0]
    for method in s.methods:
        for hz in (30.0, 60.0):
            sel = np.sort(runs[(np.char.decode(runs["method"].astype(bytes)) == method) & (runs["hz"] == hz)
                               & (runs["substeps"] == 1)], order="point")
            bad = sel["point"][(sel["diverged"] != 0) | (sel["failed"] != 0)]
            cell = shown[method][f"{hz:g} Hz: first k_s not completed"]
            if len(bad):
                below = sum(1 for i in missing if i < bad[0])
                assert cell == f"{values[bad[0]]:.3g}" + (f" ({below} point{'s' if below != 1 else ''} below it not "
                                                          "measured)" if below else ""), (method, hz)
            else:
                assert cell == f"none of the {len(points)} measured ({len(missing)} not measured)", (method, hz)
            assert cell != "none"  # never "stable everywhere" with points missing


def test_the_cheapest_map_leaves_the_missing_points_out(gaps_report):
    from stepbench_report import scan as scan_section
    study, folder, files = gaps_report
    _, points, _, best = scan_group(files / "partial.h5")
    s = load_scan(study, "partial")
    missing = sorted(set(range(s.grid_points)) - set(points["point"].tolist()))
    held_values = {f"{s.values[0][i]:.3g}" for i in points["point"]}
    part = scan_part(report_text(folder), "partial")
    head, rows = table_after(part, "The scan's `best` table by rate")
    assert head[-1] == "not judged" and len(rows) == 2
    for row, hz in zip(rows, (30.0, 60.0)):
        method, substeps, state, _ = scan_section.best_grid(s, hz)
        assert (state[missing, 0] == scan_section.MISSING).all() and not any(method[missing, 0])
        counted = 0
        for cell in (row[1], row[2]):
            if cell in ("-", "none"):
                continue
            for part_text in cell.split("; "):
                counted += int(re.search(r"\((\d+) points?\)$", part_text).group(1))
                spans = re.search(r"k_s ([^(]+) \(", part_text).group(1)
                for v in re.split(r", | \.\. ", spans):
                    assert v in held_values, (v, part_text)  # never a missing point's k_s
        mine = best[best["hz"] == hz]
        assert counted == len(mine) == len(points)  # the points held, not the grid's
        assert row[3] == f"{len(missing)} points not run (missing shard)"
        for b in mine:  # each point held: the file's choice, where the figure draws it
            i = int(b["point"])
            assert method[i, 0] == text(b["method"]) and (not method[i, 0] or substeps[i, 0] == b["substeps"])


def test_a_shard_file_says_which_share_it_holds(gaps_report):
    from stepbench_report import scan as scan_section
    study, folder, files = gaps_report
    attrs, points, _, best = scan_group(files / "s2.h5")
    assert (attrs["shard_index"], attrs["shard_count"]) == (1, 3)
    part = scan_part(report_text(folder), "shard2")
    assert (f"This file is shard {attrs['shard_index'] + 1} of {attrs['shard_count']} of the scan (`stepbench scan "
            f"--shard 2/3`): it holds {len(points)} of the grid's {attrs['grid_points']} points. The other "
            f"{attrs['grid_points'] - len(points)} are in the other shards") in part
    s = load_scan(study, "shard2")
    others = sorted(set(range(s.grid_points)) - set(points["point"].tolist()))
    for hz in s.rates:
        _, state = scan_section.one_step_grid(s, hz)
        assert (state[:, others] == scan_section.MISSING).all()
        assert scan_section.unjudged_text(s, hz) == f"{len(others)} points not in this shard"
        assert sum(c for _, _, c, _ in scan_section.best_summary(s, hz)) == len(best[best["hz"] == hz]) == len(points)
    assert s.missing_label == "not in this shard"


def test_untrusted_points_are_not_judged(gaps_report):
    """The sliding block lubricated: where the lecture's table lacks the pair's
    coefficient, stepbench records the point untrusted and runs nothing there. The report
    says how many, judges none of them (no run: not even stability), and counts no method
    stable over them."""
    from stepbench_report import scan as scan_section
    study, folder, files = gaps_report
    _, points, runs, best = scan_group(files / "lub.h5")
    untrusted = points["point"][points["trusted"] == 0]
    assert 0 < len(untrusted) < len(points)
    part = scan_part(report_text(folder), "lub")
    assert f"{len(untrusted)} of the {len(points)} points have no trusted truth" in part
    assert "None of them has a run (hatched as \"no truth and no run here\"): nothing is judged there." in part
    s = load_scan(study, "lub")
    _, state = scan_section.one_step_grid(s, 60.0)
    assert (state[:, untrusted] == scan_section.UNTRUSTED).all()
    trusted = len(points) - len(untrusted)
    head, rows = table_after(part, "Where each method stops completing at one step a frame")
    for r in rows:
        m = r[0]
        sel = runs[(np.char.decode(runs["method"].astype(bytes)) == m) & (runs["substeps"] == 1)]
        if not ((sel["diverged"] != 0) | (sel["failed"] != 0)).any():
            assert r[1] == f"none of the {trusted} measured ({len(untrusted)} not measured)", r
    head, rows = table_after(part, "The scan's `best` table by rate")
    assert rows[0][3] == f"{len(untrusted)} points without a trusted truth"
    method, _, bstate, _ = scan_section.best_grid(s, 60.0)
    assert (bstate[untrusted, 0] == scan_section.UNTRUSTED).all() and not any(method[untrusted, 0])


def test_an_untrusted_point_with_runs_is_judged_on_stability(scan_files, tmp_path):
    """A point without a trusted truth (references that disagree, or not run over the
    reference budget) still has runs: here the merged scan's point 5 marked so (trusted 0,
    its completed runs' errors NaN, as stepbench writes them). Its diverged runs did not
    complete, its completed ones are stable with no error shown, and `best` there is not
    shown: no error, so no tolerance."""
    from stepbench_report import scan as scan_section
    import shutil
    path = tmp_path / "untrusted.h5"
    shutil.copyfile(scan_files / "partial.h5", path)
    with h5py.File(path, "r+") as f:
        p = f["scan/stiff_spring/points"][()]
        p["trusted"][p["point"] == 5] = 0
        f["scan/stiff_spring/points"][...] = p
        runs = f["scan/stiff_spring/runs"][()]
        runs["err_pos_max"][(runs["point"] == 5)] = np.nan
        f["scan/stiff_spring/runs"][...] = runs
    at5 = runs[(runs["point"] == 5) & (runs["substeps"] == 1)]
    assert (at5["diverged"] != 0).any() and (at5["completed"] != 0).any()  # both kinds
    from stepbench_report import study as study_reader
    with h5py.File(path) as f:
        s = next(x for x in scan_section.read(study_reader._Reader(str(path), f), f) if x.name == "stiff_spring")
    for hz in s.rates:
        err, state = scan_section.one_step_grid(s, hz)
        mine = at5[at5["hz"] == hz]
        for r in mine:
            k = s.methods.index(text(r["method"]))
            assert state[k, 5] == (scan_section.STABLE_NO_TRUTH if r["completed"] else scan_section.UNSTABLE), r
        assert np.isnan(err[:, 5]).all()
        method, _, bstate, _ = scan_section.best_grid(s, hz)
        assert bstate[5, 0] == scan_section.UNTRUSTED and method[5, 0] == ""
        assert sum(c for _, _, c, _ in scan_section.best_summary(s, hz)) == len(s.points) - 1
        for r in mine:  # a run that diverged at 5 and nowhere before it: the boundary is point 5's value
            m = text(r["method"])
            k = s.methods.index(m)
            first, _, judged = scan_section.boundary(s, hz, m)
            earlier = np.flatnonzero(state[k, :5] == scan_section.UNSTABLE)
            if r["diverged"] and not len(earlier):
                assert first == s.values[0][5], m
            assert judged == int(np.isin(state[k], scan_section.JUDGED).sum()) == len(s.points), m


# --- scans made here, row by row: the states of the maps, without stepbench ------------------------

def made_scan(axes, values, trusted, runs, notes=None, attrs=None):
    """A Scan as scan.read() returns it: `axes` and per axis its `values` (log axes); points
    0 .. N-1 with `trusted` (0/1 each) and `notes`; `runs` (point, hz, method, state, err),
    state one of "ok", "diverged", "failed", "skipped", "old" (what a stepbench before the
    stability-only points wrote for a run that completed without a truth: failed, with the
    note "no trusted truth: ..."). `best` names no run."""
    from stepbench_report import scan as scan_section
    shape = [len(v) for v in values]
    n = int(np.prod(shape))
    notes = notes or [""] * n
    points = np.zeros(n, dtype=[("point", "i8"), ("trusted", "i1"), ("truth_source", "O"), ("horizon", "f8"),
                                ("pos_scale", "f8"), ("note", "O")])
    points["point"] = np.arange(n)
    points["trusted"] = trusted
    points["truth_source"] = ["closed_form" if t else "none" for t in trusted]
    points["horizon"] = 60
    points["pos_scale"] = 1.0
    points["note"] = notes
    rows = np.zeros(len(runs), dtype=[(f, "O" if f in ("method", "note") else "f8" if f in ("hz", "dt", "err_pos_max")
                                       else "i8" if f in ("point", "substeps", "steps", "force_evals",
                                                          "newton_iterations") else "i1")
                                      for f in scan_section.RUN_FIELDS])
    for row, (point, hz, method, kind, err) in zip(rows, runs):
        row["point"], row["hz"], row["method"], row["substeps"], row["dt"] = point, hz, method, 1, 1 / hz
        row["diverged"] = kind == "diverged"
        row["failed"] = kind in ("failed", "old")
        row["skipped"] = kind == "skipped"
        row["completed"] = kind == "ok"
        row["err_pos_max"] = err if kind == "ok" else np.nan
        row["note"] = {"old": "no trusted truth: the references disagree", "diverged": "non-finite state"}.get(kind, "")
    best = np.zeros(len({(r[0], r[1]) for r in runs}), dtype=[("point", "i8"), ("hz", "f8"), ("method", "O"),
                                                                ("substeps", "i8"), ("err_pos_max", "f8"),
                                                                ("force_evals_per_frame", "f8")])
    for b, (point, hz) in zip(best, sorted({(r[0], r[1]) for r in runs})):
        b["point"], b["hz"], b["method"] = point, hz, ""
    a = {"problem": "spring_chain", "unit": "m", "tol": 1e-3, "axes": ",".join(axes),
         "axis_lo": [v[0] for v in values], "axis_hi": [v[-1] for v in values], "axis_count": shape,
         "axis_log": [1] * len(axes), "hz": sorted({r[1] for r in runs}), "substeps": [1], "fixed_params": "",
         "fixed_values": np.zeros(0), "methods": ",".join(dict.fromkeys(r[2] for r in runs)), "grid_points": n,
         **(attrs or {})}
    return scan_section.Scan("made", a, list(axes), [np.asarray(v, float) for v in values], points, rows, best)


BUDGET_NOTE = ("references not run: their predicted work, 4.1e+05 (128 coordinates x w_max T = 3.2e3 rad), is over "
               "the reference budget of 2e+05")


def test_an_untrusted_points_runs_say_whether_they_completed():
    """At a point without a trusted truth, a run that diverged or failed is UNSTABLE, one
    that completed is STABLE_NO_TRUTH (also as an older stepbench wrote it: failed for the
    truth alone), a skipped one SKIPPED; no error is shown there, the boundary counts them
    as judged, and `best` stays UNTRUSTED."""
    from stepbench_report import scan as scan_section
    s = made_scan(["masses"], [[8, 64, 512, 4096]], [1, 1, 0, 0], [
        (0, 60.0, "a", "ok", 1e-4), (1, 60.0, "a", "ok", 2e-3), (2, 60.0, "a", "ok", 0.5),  # an error: not shown
        (3, 60.0, "a", "diverged", 0),
        (0, 60.0, "b", "ok", 1e-5), (1, 60.0, "b", "ok", 1e-5), (2, 60.0, "b", "old", 0), (3, 60.0, "b", "failed", 0),
        (0, 60.0, "c", "ok", 1e-5), (1, 60.0, "c", "diverged", 0), (2, 60.0, "c", "skipped", 0)],
        notes=["", "", BUDGET_NOTE, BUDGET_NOTE], attrs={"reference_budget": 2e5})
    err, state = scan_section.one_step_grid(s, 60.0)
    S, U, OK = scan_section.STABLE_NO_TRUTH, scan_section.UNSTABLE, scan_section.OK
    np.testing.assert_array_equal(state, [[OK, OK, S, U], [OK, OK, S, U],
                                          [OK, U, scan_section.SKIPPED, scan_section.UNTRUSTED]])
    assert np.isnan(err[:, 2:]).all() and np.isfinite(err[:, :2][state[:, :2] == OK]).all()
    assert scan_section.boundary(s, 60.0, "a") == (4096.0, 0, 4)  # judged at the untrusted points too
    assert scan_section.boundary(s, 60.0, "c") == (64.0, 0, 2)
    assert scan_section.boundary_text(s, 60.0, "a") == "4.1e+03"
    _, _, bstate, _ = scan_section.best_grid(s, 60.0)
    assert (bstate[2:, 0] == scan_section.UNTRUSTED).all()  # no error there: no cheapest
    words = scan_section._coverage_paragraph(s)
    assert "2 of the 4 points have no trusted truth (at masses = 512: references not run" in words
    assert "At all of them the references were not run, their predicted work over the scan's reference budget of " \
           "2e+05 (`reference_budget`)." in words
    assert "Stability is judged there" in words and "neither stable nor unstable" not in words
    assert "no run (hatched" not in words  # each untrusted point has runs (c's none at point 3: its cell says so)


def test_a_file_without_reference_budget_is_read_as_before():
    """An older scan (no `reference_budget` attribute): the budget's sentence names no value."""
    from stepbench_report import scan as scan_section
    s = made_scan(["k_s"], [[1e2, 1e3]], [1, 0], [(0, 60.0, "a", "ok", 1e-4), (1, 60.0, "a", "ok", 0.1)],
                  notes=["", BUDGET_NOTE])
    words = scan_section._coverage_paragraph(s)
    assert "At it the references were not run, their predicted work over the scan's reference budget " \
           "(`reference_budget`)." in words
    assert "no run (hatched" not in words


def test_untrusted_points_without_runs_are_not_judged():
    """A point that was not run at all (its parameters invalid: no truth, no run) says
    nothing, and the paragraph says so once."""
    from stepbench_report import scan as scan_section
    s = made_scan(["k_s"], [[1e2, 1e3, 1e4]], [1, 0, 0], [(0, 60.0, "a", "ok", 1e-4), (1, 60.0, "a", "ok", 0.1)],
                  notes=["", BUDGET_NOTE, "not run: k_s is out of range"])
    _, state = scan_section.one_step_grid(s, 60.0)
    assert state.tolist() == [[scan_section.OK, scan_section.STABLE_NO_TRUTH, scan_section.UNTRUSTED]]
    words = scan_section._coverage_paragraph(s)
    assert "At 1 of them the references were not run" in words and "Stability is judged there" in words
    assert "1 of them has no run (hatched as \"no truth and no run here\")" in words
    s = made_scan(["k_s"], [[1e2, 1e3, 1e4]], [1, 0, 0], [(0, 60.0, "a", "ok", 1e-4)],
                  notes=["", "not run: bad", "not run: bad"])
    words = scan_section._coverage_paragraph(s)
    assert "None of them has a run" in words and "Stability is judged there" not in words


def test_a_two_axis_scan_has_a_map_per_method_and_rate(monkeypatch):
    """Two axes: a figure per rate of small maps, one per method, x the first axis and y
    the second; a cell per grid point, coloured by the run's error where it completed at
    a trusted point, grey with an x where it diverged or failed, hatched green where it
    completed without a truth; one colour scale for every rate."""
    from stepbench_report import figures
    from stepbench_report import scan as scan_section
    masses, ks = [8, 64, 512], [1e2, 1e3]
    runs = []
    for hz in (60.0, 120.0):
        for p in range(6):
            i, j = divmod(p, 2)
            runs.append((p, hz, "a", "diverged" if (i, j) == (2, 1) else "ok", 10.0 ** -(p + 1) * (hz / 60) ** 2))
            runs.append((p, hz, "b", "ok", 1e-3))
    s = made_scan(["masses", "k_s"], [masses, ks], [1, 1, 1, 1, 0, 0], runs, notes=[""] * 4 + [BUDGET_NOTE] * 2)
    names = scan_section.figure_names(s)
    assert names == {"one_step_0": "scan_made_one_step_60hz.png", "one_step_1": "scan_made_one_step_120hz.png",
                     "best": "scan_made_cheapest.png"}
    kept = []
    monkeypatch.setattr(figures, "_save", lambda fig, path, tight=True: kept.append(fig))
    err, state = scan_section.maps_figure(s, 120.0, "unused.png")
    (fig,) = kept
    panels = [ax for ax in fig.axes if ax.get_title()]
    assert [ax.get_title() for ax in panels] == ["a", "b"]
    a = state[0].reshape(s.shape)
    assert a[2, 1] == scan_section.UNSTABLE and a[2, 0] == scan_section.STABLE_NO_TRUTH
    assert (a[:2] == scan_section.OK).all()
    x_edges, y_edges = scan_section._edges(s.values[0], True), scan_section._edges(s.values[1], True)
    for ax, st in zip(panels, state):
        colour = ax.collections[0]  # the errors, (ks x masses)
        mask = colour.get_array().mask.reshape(len(ks), len(masses))
        np.testing.assert_array_equal(~mask, (st.reshape(s.shape) == scan_section.OK).T)
        hatched = {(p.get_x(), p.get_y()) for p in ax.patches if p.get_hatch() == "---"}
        assert hatched == {(x_edges[2], y_edges[0])} | ({(x_edges[2], y_edges[1])} if ax.get_title() == "b" else set())
    assert "masses" in panels[0].get_xlabel() and panels[0].get_ylabel() == "k_s"
    # One colour scale for both rates: the 60 Hz errors are in it.
    lo, hi = panels[0].collections[0].get_clim()
    assert lo <= np.log10(1e-4) and hi >= np.log10(1e-3 * 4)
    # The section: the figures, and no word that per-method maps are left out.
    from stepbench_report import render
    doc = render.Doc("t")
    scan_section._maps_part(doc, set(names.values()), s, names)
    md = render.markdown(doc)
    assert "fig/scan_made_one_step_60hz.png" in md and "fig/scan_made_one_step_120hz.png" in md
    assert "Hatched green" in md and "not be readable" not in md


def test_skipped_runs_are_neither_failures_nor_stable(gaps_report):
    """rk8 at 7864320 Hz: every run over the work budget, skipped; at 60 Hz the 524288
    substeps are. A skipped run is not a failure, and no method is stable where none ran."""
    from stepbench_report import scan as scan_section
    study, folder, files = gaps_report
    _, points, runs, best = scan_group(files / "budget.h5")
    fast = runs[runs["hz"] == 7864320.0]
    assert (fast["skipped"] != 0).all() and (runs[(runs["hz"] == 60.0) & (runs["substeps"] == 1)]["skipped"] == 0).all()
    s = load_scan(study, "budget")
    _, state = scan_section.one_step_grid(s, 7864320.0)
    assert (state == scan_section.SKIPPED).all()
    assert scan_section.boundary_text(s, 7864320.0, "rk8") == "not run (over the work budget)"
    part = scan_part(report_text(folder), "budget")
    skipped = int(np.sum(runs["skipped"] != 0))
    assert f"{skipped} of the {len(runs)} runs were not taken: their estimated work exceeds the scan's work budget" \
        in part
    head, rows = table_after(part, "Where each method stops completing at one step a frame")
    shown = dict(zip(head, rows[0]))
    assert shown["7.86432e+06 Hz: first k_s not completed"] == "not run (over the work budget)"
    one = np.sort(runs[(runs["hz"] == 60.0) & (runs["substeps"] == 1)], order="point")
    bad = np.flatnonzero(one["diverged"] != 0)
    assert shown["60 Hz: first k_s not completed"] == (f"{s.values[0][bad[0]]:.3g}" if len(bad) else "none")
    head, rows = table_after(part, "The scan's `best` table by rate")
    by_rate = {r[0]: dict(zip(head, r)) for r in rows}
    assert by_rate["7.86432e+06 Hz"]["cheapest (method x substeps a frame): where"] == "none"
    assert by_rate["7.86432e+06 Hz"]["no run within tolerance"] == "-"  # not "none within tolerance": none ran
    assert by_rate["7.86432e+06 Hz"]["not judged"] == f"{len(points)} points with every run over the work budget " \
                                                       "(skipped)"
    none60 = best[(best["hz"] == 60.0) & (np.char.decode(best["method"].astype(bytes)) == "")]
    if len(none60):  # there, the 524288 substeps were not taken: said so
        assert by_rate["60 Hz"]["not judged"] == (f"of the points with none within tolerance, {len(none60)} had runs "
                                                  "not taken (over the work budget)")
