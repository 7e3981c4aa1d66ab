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
def scan_report(plain_study, tmp_path_factory):
    out = tmp_path_factory.mktemp("scan_report") / "report"
    p = subprocess.run([PYTHON, REPORT, str(plain_study), "--out", str(out), "--jobs", "2"], capture_output=True,
                       text=True, timeout=180)
    assert p.returncode == 0, p.stderr
    return plain_study, out


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
    assert '<a href="#parameter-scans">' in html  # the contents' entry
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
    err, unstable, present = scan_section.one_step_grid(s, 60.0)
    with h5py.File(study) as f:
        for k, method in enumerate(s.methods):
            runs = one_step_runs(f, method)
            assert present[k].all()
            np.testing.assert_array_equal(unstable[k], runs["completed"] == 0)
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


def test_a_study_without_scan_has_no_section(plain_study, tmp_path, scan_report):
    """An older study (no /scan): the report is the one it was before, with no scan section."""
    old = tmp_path / "old.h5"
    import shutil
    shutil.copyfile(plain_study, old)
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
    with_scan = report_text(scan_report[1])
    cut = with_scan[:with_scan.index("\n## Parameter scans\n")] + \
        with_scan[with_scan.index("\n## Appendix: how the problem sections are made"):]
    assert cut.replace(str(plain_study), "S").replace(os.path.basename(str(plain_study)), "S") == \
        md.replace(str(old), "S").replace("old.h5", "S")
