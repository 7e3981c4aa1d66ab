"""The report: figures into <dir>/fig, one document written as REPORT.md and as a small
site (index.html, a page per problem, a page per study-wide section, about.html), and
the verdict as summary.json. The index opens on the answer: per frame at the chosen rate
and tolerances (verdict.frame_answer), then at equal error (verdict.opening), a line per
problem linking to its page; the study's metadata last."""
import json
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace

import numpy as np

from . import figures, render, tables
from . import challenge as challenge_section
from . import energy_runs as energy_section
from . import loop as loop_section
from . import scan as scan_section
from . import substeps as substeps_section
from . import verdict as verdict_section
from .formatting import fmt_num

TITLE = "stepbench: which integrator for which need"
META_KEYS = ["version", "git_commit", "compiler", "build_type", "dependencies", "created_utc", "cpu", "cores",
             "format_version", "levels", "base_steps", "tolerances", "sample_count", "reference_rtol",
             "reference_atol", "fit_metric", "divergence_factor", "equal_error_targets", "wall_seconds", "timing"]
BENCH_KEYS = ["benchmark_mode", "benchmark_min_time_s", "benchmark_repetitions", "benchmark_case_budget_s",
              "benchmark_wall_seconds", "cpu_scaling_enabled", "num_cpus", "mhz_per_cpu"]


def _parameter(q):
    """One declared parameter as `name = value unit` (a named value by its name)."""
    value = q["value_name"] or f"{float(q['value']):.6g}"
    unit = "" if q["unit"] in ("", "1") or q["value_name"] else f" {q['unit']}"
    return f"{q['name']} = {value}{unit}"


def _value(v):
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.6g}"
    if isinstance(v, np.ndarray):
        return ", ".join(_value(x) for x in v.tolist())
    return str(v)


def _figure_jobs(study, figdir, whole, scans=None):
    """(kind, argument, path) for every figure; they are independent, so they can be
    drawn in parallel processes. `whole`: the study-wide figures too (not for a report
    of one problem); `scans`: the study's /scan (scan.load), None when it has none."""
    jobs = []
    for p in study.problems:
        jobs += [("wp", p.name, os.path.join(figdir, f"work_precision_{p.name}.png")),
                 ("convergence", p.name, os.path.join(figdir, f"convergence_{p.name}.png"))]
        if figures.energy_drifts(p):
            jobs.append(("energy", p.name, os.path.join(figdir, f"energy_drift_{p.name}.png")))
    if not whole:
        return jobs
    if study.energy_runs is not None:
        jobs.append(("energy_runs", None, os.path.join(figdir, "energy_long_runs.png")))
    if study.stability is not None and not study.scan_only:
        jobs.append(("stability", None, os.path.join(figdir, "stability_regions.png")))
    if study.substeps is not None:
        jobs.append(("substeps", None, os.path.join(figdir, substeps_section.FIGURE)))
    if study.challenge is not None:
        jobs.append(("challenge", None, os.path.join(figdir, challenge_section.FIGURE)))
    if study.loop is not None:
        jobs.append(("loop", None, os.path.join(figdir, "loop_shown_error.png")))
    for k, s in enumerate(scans or ()):
        for which, name in scan_section.figure_names(s).items():
            jobs.append((f"scan_{which}", k, os.path.join(figdir, name)))
    # The slowest first, so that the workers finish together.
    slow = {"loop": 0, "substeps": 1, "energy_runs": 2, "stability": 3}
    return sorted(jobs, key=lambda j: slow.get(j[0], 9))


_STUDY = _NAMES = _SCANS = None


def _init_worker(study, names, scans=None):
    global _STUDY, _NAMES, _SCANS
    _STUDY, _NAMES, _SCANS = study, names, scans


def _draw(job):
    kind, arg, path = job
    study = _STUDY
    styles = figures.Styles(_NAMES)
    problem = next((p for p in study.problems if p.name == arg), None)
    if kind == "convergence":
        figures.convergence(problem, styles, path)
    elif kind == "wp":
        figures.work_precision(problem, styles, path, "time" if study.timed else "force_evals", study.timed)
    elif kind == "energy":
        if not figures.energy(problem, styles, path):
            return None
    elif kind == "stability":
        figures.stability(study.stability, styles, path)
    elif kind == "loop":
        loop_section.figure(study.loop, styles, path)
    elif kind == "energy_runs":
        energy_section.figure(study.energy_runs, styles, path)
    elif kind == "substeps":
        substeps_section.figure(study.substeps, styles, path)
    elif kind == "challenge":
        challenge_section.figure(study.challenge, styles, path)
    elif kind.startswith("scan_"):
        scan_section.draw(_SCANS[arg], kind[len("scan_"):], study, styles, path)
    return path


def draw_figures(study, figdir, workers, names, whole=True, scans=None, meanwhile=lambda figures: None):
    """Draws every figure (_figure_jobs) in `workers` processes; returns the paths drawn and
    what meanwhile(the names of the figures asked for) returned: it runs while the workers
    draw, where the main process would wait."""
    jobs = _figure_jobs(study, figdir, whole, scans)
    asked = {os.path.basename(job[2]) for job in jobs}
    if workers <= 1:
        _init_worker(study, names, scans)
        return [p for p in map(_draw, jobs) if p], meanwhile(asked)
    ex = ProcessPoolExecutor(max_workers=workers, initializer=_init_worker, initargs=(study, names, scans))
    try:
        drawing = ex.map(_draw, jobs)
        early = meanwhile(asked)
        drawn = [p for p in drawing if p]
    except BaseException:
        # An interruption (SIGINT, or SIGTERM as cli.py raises it) can come before the
        # executor's manager thread has started, and then nothing tells the workers to stop:
        # shutdown(wait=True) and the interpreter's exit would wait for them forever (seen
        # in tests/interrupt_test.sh). The workers are ended here, and the error goes on.
        ex.shutdown(wait=False, cancel_futures=True)
        for worker in multiprocessing.active_children():
            worker.kill()  # not SIGTERM: the handler they inherited from cli.py would run in them
        raise
    ex.shutdown()
    return drawn, early


def in_verdict_order(study):
    """The problems in the order the verdict lists them (the registry's, from the simple
    scenes to the contacts), where the study has one; else as /problems holds them."""
    if study.verdict is None:
        return study
    order = {name: k for k, name in enumerate(study.verdict.problems)}
    return replace(study, problems=sorted(study.problems, key=lambda p: order.get(p.name, len(order))))


def one_problem(study, name):
    """The study cut to the problem `name` (which it has), for a report of one problem."""
    p = next(p for p in study.problems if p.name == name)
    return replace(study, problems=[p], verdict=study.verdict.only(name) if study.verdict is not None else None,
                   gaps=[g for g in study.gaps if g.startswith(f"{name}:")])


def build(study, outdir, workers=2, problem=None, self_contained=False, hz=None, targets=None):
    """Writes fig/*.png, REPORT.md, the site (index.html, problems/*.html, a page per
    study-wide section, about.html) and summary.json into outdir (which exists): of the
    whole study, or of the one problem named. `self_contained`: the figures inlined into
    the pages as well; `hz`, `targets`: the index's per-frame answer (verdict.frame_choice)."""
    names = figures.method_names(study)  # of the whole study: the same colours in a report of one problem
    study = in_verdict_order(study)
    whole = problem is None
    if not whole:
        study = one_problem(study, problem)
    # The parameter scans (/scan), read beside the study (study.py does not hold them);
    # in the report of the whole study only, as the other study-wide sections.
    scans = scan_section.load(study.path) if whole else None
    if study.scan_only:  # no problems to name the methods: the scans' (the same colours as a study's lecture methods)
        names = scan_section.method_names(scans)
    figdir = os.path.join(outdir, "fig")
    os.makedirs(figdir, exist_ok=True)

    def pages(figs):
        """The document and its pages, with the figures `figs`."""
        doc = scan_file_document(study, figs, scans) if study.scan_only else document(study, figs, whole, scans, hz,
                                                                                      targets)
        return doc, render.site(doc, figdir if self_contained else None)

    # The pages are made while the figures are drawn (from the names asked for), and made again
    # in the rare case a figure had nothing to draw. --self-contained reads the figures: after.
    early_pages = (lambda asked: None) if self_contained else (lambda asked: (asked, pages(asked)))
    drawn, early = draw_figures(study, figdir, workers, names, whole, scans, meanwhile=early_pages)
    made = set(os.path.basename(p) for p in drawn)
    doc, site = early[1] if early and early[0] == made else pages(made)
    with open(os.path.join(outdir, "REPORT.md"), "w") as f:
        f.write(render.markdown(doc))
    for page, text in site.items():
        path = os.path.join(outdir, page)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as f:
            f.write(text)
    summary = verdict_section.summary(study)
    if study.scan_only:
        summary["scans"] = scan_section.summary(scans)
    with open(os.path.join(outdir, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
        f.write("\n")


def machines(study):
    """Each problem's machine, "<cpu> (<cores> cores)", when the study's problems ran on
    more than one (shards merged by `stepbench merge`); {} when they ran on one. A file
    without per-problem machines ran on the root's."""
    a = study.attrs
    m = {p.name: f"{p.attrs.get('cpu', a['cpu'])} ({p.attrs.get('cores', a['cores'])} cores)"
         for p in study.problems}
    return m if len(set(m.values())) > 1 else {}


def headline(study):
    """The line under the title: the study, where and when it ran (the rest in the appendix)."""
    a = study.attrs
    how = f"timed ({a['benchmark_mode']})" if study.timed else "untimed (costs in force evaluations)"
    n = len(set(machines(study).values()))
    where = (f"{n} machines ({a['cpu']}; each problem's in its section, and no time is compared across them)"
             if n else a["cpu"])
    partial = (f" A partial merge: {len(a['missing_problems'])} selected "
               f"problem{'s' if len(a['missing_problems']) > 1 else ''} ({', '.join(a['missing_problems'])}) "
               f"{'were' if len(a['missing_problems']) > 1 else 'was'} in no shard and {'are' if len(a['missing_problems']) > 1 else 'is'} "
               f"absent from every table." if a.get("missing_problems") else "")
    return (f"Study `{os.path.basename(study.path)}`, {how}, {where}, {a['created_utc']}, commit "
            f"{a['git_commit']}; build and machine in the appendix.{partial}")


def scenes(study):
    """{problem: its parameters as the study ran it}, the scene each answer is for."""
    return {p.name: ", ".join(_parameter(q) for q in p.parameters) for p in study.problems}


def _study_pages(study, figs, scans):
    """[(page, Doc)] of the study-wide sections the file holds, each a page of the site, in the
    order of its parts (a section draws nothing for a part the file lacks: no page)."""
    out = []
    for part in study_section_order(study):
        section = render.Doc(part)
        STUDY_SECTIONS[part](section, study, figs, scans)
        if section.blocks:
            out.append((f"{part}.html", section))
    return out


def _contents(doc, study, study_pages):
    """The index's list of the site's pages: a line per problem (its verdict is the tables' row),
    a line per study-wide section, the appendix."""
    doc.h(2, "Pages")
    doc.p("One page per problem (its work-precision figure first, then its tables): "
          + ", ".join(f"[{p.name}]({verdict_section.page_of(p.name)})" for p in study.problems) + ".")
    if study_pages:
        doc.p("The study-wide sections: " + ", ".join(f"[{_first_heading(section)}]({page})"
                                                        for page, section in study_pages) + ".")
    doc.p(f"How the tables and figures are made, and the study's build and machine: [the appendix]({ABOUT}).")


ABOUT = "about.html"


def _first_heading(doc):
    return next((b[2] for b in doc.blocks if b[0] == "h"), doc.title)


def document(study, figs, whole=True, scans=None, hz=None, targets=None):
    """The report as one document (REPORT.md) and a small site (render.site): the index opens on
    the per-frame answer at `hz` and `targets` (verdict.frame_choice), then the equal-error
    verdict, the frame rates and the findings, a list of the pages and the study's line; then a
    page per problem, a page per study-wide section, and the appendix."""
    doc = render.Doc(TITLE)
    if study.verdict is not None:
        rate, shown = verdict_section.frame_choice(study.verdict, hz, targets)
        verdict_section.frame_answer(doc, study.verdict, rate, shown, scenes(study))
        verdict_section.opening(doc, study.verdict)
    else:
        _absent(doc, study)
    for gap in study.gaps:
        doc.note(f"Incomplete study file: {gap}. The tables rank only what the file holds.")
    if not whole:
        doc.note(f"One problem only ({study.problems[0].name}): the study-wide sections (stability, small steps, "
                 "the pendulum challenge, energy over long runs, game loop) are in the report of the whole study.")
    study_pages = _study_pages(study, figs, scans) if whole else []
    _contents(doc, study, study_pages)
    if whole and study.attrs.get("parts") and (
            skipped := [p for p in STUDY_SECTIONS if p not in study.attrs["parts"]]):
        doc.note(f"Not in this study (it ran the parts {', '.join(study.attrs['parts'])}): "
                 f"{', '.join(skipped)}; `stepbench list` names every part, `--parts` selects them.")
    doc.p(headline(study), cls="small")
    for p in study.problems:
        doc.page(verdict_section.page_of(p.name))
        _problem(doc, study, p, figs)
    for page, section in study_pages:
        doc.page(page)
        doc.blocks += section.blocks
    doc.page(ABOUT, "How the report is made, and the study")
    _how_made(doc, study)
    _metadata(doc, study)
    return doc


# The study-wide sections, by the study part (parts/registry.cpp) whose group each draws.
STUDY_SECTIONS = {
    "stability": lambda doc, study, figs, scans: _stability(doc, study, figs),
    "substeps": lambda doc, study, figs, scans: substeps_section.section(doc, study, figs),
    "loop": lambda doc, study, figs, scans: loop_section.section(doc, study, figs),
    "energy": lambda doc, study, figs, scans: _energy(doc, study, figs),
    "scans": scan_section.section,
    "challenge": lambda doc, study, figs, scans: challenge_section.section(doc, study, figs),
}
# A file written before the root attribute `parts`: the order its report had.
ORDER_BEFORE_PARTS = ("stability", "substeps", "challenge", "energy", "loop", "scans")


def study_section_order(study):
    """The study-wide sections in the order of the file's parts (its root attribute
    `parts`, the study's order); the parts with no section of their own (the sweep, frame
    rates, the verdict) are drawn elsewhere."""
    parts = study.attrs.get("parts") or ORDER_BEFORE_PARTS
    return [p for p in parts if p in STUDY_SECTIONS]


# The root attributes a scan file's appendix lists (those of the study's META_KEYS a scan
# uses), each where the file has it.
SCAN_FILE_KEYS = ["version", "git_commit", "compiler", "build_type", "build_flags", "dependencies", "created_utc",
                  "cpu", "cores", "format_version", "wall_seconds"]
SCAN_ATTR_KEYS = ["work_budget", "reference_budget", "reference_rtol", "reference_atol", "wall_seconds"]


def _scan_title(scan):
    what = f"{scan.problem} over {', '.join(scan.axes)}"
    return what if scan.name == scan.problem else f"{scan.name} ({what})"


def scan_file_document(study, figs, scans):
    """The report of a scan file (Study.scan_only: `stepbench scan --out`, `stepbench
    merge`, a single shard): the title and one line naming the file, its scans and the
    build, then the scan section as a study's report has it (scan.section: the partial
    merges and shards included), and the file's metadata. The sections that need
    /problems, /verdict, /stability and the rest are not there."""
    a = study.attrs
    doc = render.Doc("stepbench scan file: " + "; ".join(_scan_title(s) for s in scans))
    doc.p(f"Scan file `{os.path.basename(study.path)}` (as `stepbench scan --out` and `stepbench merge` write it: "
          f"only /scan, no study), stepbench {a['version']} at commit {a['git_commit']}, {a['build_type']} build "
          f"({a['compiler']}), {a['cpu']}, {a['created_utc']}; build and machine in the appendix.")
    doc.items([f"Scan {s.name}: {s.problem} over {', '.join(s.axes)} at {', '.join(f'{hz:g}' for hz in s.rates)} "
               f"Hz; {scan_section.held_text(s)}." for s in scans])
    doc.note("A scan file holds no problem: the verdict, the per-problem sections and the study-wide ones "
             "(stability, small steps, the pendulum challenge, energy over long runs, game loop) are in the report "
             "of a study file (`stepbench sweep --out`, `stepbench_bench --study_out`).")
    doc.toc()
    scan_section.section(doc, study, figs, scans)
    doc.h(2, "Appendix: the scan file")
    doc.note("Generated by `scripts/report` from the scan file; do not edit, regenerate it. The runs and the `best` "
             "tables were computed by stepbench when it wrote the file; the report draws and formats them.")
    doc.table(["field", "value"], [["scan file", study.path]] + [[k, _value(a[k])] for k in SCAN_FILE_KEYS if k in a],
              caption="Build and machine (the file's root attributes):")
    keys = [k for k in SCAN_ATTR_KEYS if any(k in s.attrs for s in scans)]
    doc.table(["scan", "problem", "axes", "grid points", "points held", "coverage", "tol"] + keys,
              [[s.name, s.problem, ", ".join(s.axes), s.grid_points, len(s.points), scan_section.coverage_kind(s),
                f"{s.tol:g} {s.unit}"] + [_value(s.attrs[k]) if k in s.attrs else "" for k in keys] for s in scans],
              caption="Scans (the attributes of /scan/<name>):")
    return doc


def _absent(doc, study):
    """The opening of a study without /verdict: said at once, then the cheapest measured
    run per target in its place (`equal_error`, by max error over the run)."""
    doc.h(2, "Fastest at equal error")
    doc.note("This study file has no /verdict group (it was written before stepbench computed one): no "
             "comparison with the peers at equal error and no frame-rate answers. Run the study again with this "
             "stepbench for them. In their place: the cheapest measured run reaching each target.")
    targets = tables.SUMMARY_TARGETS
    doc.table(["problem [unit]"] + [verdict_section.target_text(t) for t in targets],
              [[f"{p.name} [{p.unit}]"] + [tables.cheapest_cell(p, t) for t in targets] for p in study.problems],
              cls="verdict")


def _problem(doc, study, p, figs):
    """Everything about one problem (its page): its work-precision figure first (the legend
    beside it), the scene in a line, its verdict, the figure's tables and the other figures."""
    doc.h(2, p.name)
    primary = "time" if study.timed else "force_evals"
    doc.h(3, f"{p.name}: work-precision")
    name = f"work_precision_{p.name}.png"
    if name in figs:
        doc.img(f"fig/{name}", f"work-precision on {p.name}")
    pa = p.attrs
    truth = pa["truth_source"] if int(pa["truth_trusted"]) else f"none trusted: {pa['truth_note']}"
    params = ", ".join(_parameter(q) for q in p.parameters)
    doc.p(f"{pa['description']}. Horizon {fmt_num(pa['horizon'], 4)} s, position unit {p.unit}, truth: {truth}. "
          f"Parameters: {params}.")
    if machine := machines(study).get(p.name):
        doc.note(f"{p.name} ran{' and was timed' if study.timed else ''} on {machine}: this study's shards ran on "
                 f"more than one machine, so its times are compared with one another only, never with another "
                 "problem's.")
    if not int(pa["truth_trusted"]):
        doc.note(f"{p.name} has no trusted truth ({pa['truth_note']}): every error on it is NaN, every run is "
                 "marked failed, and it has no cheapest method or front.")
    methods = tables.front_methods(p, primary)
    text = (f"Methods on the front by {'time' if study.timed else 'force evaluations'}: "
            + (", ".join(methods) if methods else "none") + ".")
    if study.timed:
        by_evals = tables.front_methods(p, "force_evals")
        text += " By force evaluations: " + (", ".join(by_evals) if by_evals else "none") + "."
    doc.p(text)
    if study.verdict is not None:
        verdict_section.problem_section(doc, study.verdict, p.name)
    doc.fold(f"{p.name}: every method of the figure, the front run by run, the adaptive methods")
    doc.h(4, f"{p.name}: every method of the work-precision figure")
    doc.table(*tables.method_rows(p, figures.work_curves(p, primary, study.timed), figures.labelled(p, primary),
                                  primary))
    doc.h(4, f"{p.name}: Pareto front")
    doc.table(*tables.front_rows(p, primary))
    rows = tables.adaptive_rows(p)
    if rows:
        doc.h(4, f"{p.name}: adaptive methods")
        doc.table(tables.ADAPTIVE_HEAD, rows)
    doc.unfold()
    doc.h(3, f"{p.name}: convergence")
    name = f"convergence_{p.name}.png"
    if name in figs:
        doc.img(f"fig/{name}", f"convergence on {p.name}")
    doc.fold(f"{p.name}: observed orders")
    doc.h(4, f"{p.name}: observed order")
    doc.table(tables.ORDER_HEAD, tables.order_rows(p))
    doc.unfold()
    name = f"energy_drift_{p.name}.png"
    if name in figs:
        doc.h(3, f"{p.name}: energy at the horizon")
        doc.img(f"fig/{name}", f"energy drift at the horizon on {p.name}")
    doc.h(3, f"{p.name}: measured runs and references")
    doc.fold(f"{p.name}: the cheapest measured run per target, the reference solutions")
    for metric, title in tables.SUMMARY_METRICS:
        doc.h(4, f"{p.name}: cheapest {title}")
        doc.table(*tables.summary_rows(p, metric))
    doc.h(4, f"{p.name}: references")
    rows = tables.reference_rows(p)
    if rows:
        doc.table(tables.REFERENCE_HEAD, rows)
    else:
        doc.p("No references recorded.")
    doc.unfold()


def _how_made(doc, study):
    """How to read the problem sections' figures and tables: said once, after them."""
    doc.h(2, "Appendix: how the problem sections are made")
    doc.p("Verdict at equal error: stepbench interpolates each method's measured work-precision curve (log-log, "
          "between the two runs that bracket the target, never beyond them) and compares the fastest of ours with "
          "the fastest library peer; the hand-written baselines never count. At a frame rate: our fixed-step "
          "methods at one step a frame, and with n substeps a frame (n = 1, 2, 4, ..., 64).")
    doc.p("Work-precision: error against " + ("measured time (median wall time of one whole run)" if study.timed
                                              else "counted force evaluations (a proxy for cost that ignores "
                                                   "per-step overhead; a timed study shows time)")
          + ". Drawn in colour and named: the methods on the study's Pareto front (runs that no other run beats "
          "in both cost and error, the baseline left out; the thin black line) and the lecture's methods ("
          + ", ".join(figures.LECTURE) + "); every other method light grey. Ours solid, the peers dashed, the "
          "baseline dotted. A method has one colour and marker in every figure of the report. Runs the time budget "
          "cut are not drawn. The table under each figure lists every method.")
    doc.p("Convergence: max position error over the run (`err_pos_max`, the study's fit metric) against the "
          "timestep, log-log, for every fixed-step method: ours in full, the peers and the baseline faint and "
          "dashed behind them. The legend gives the fitted slope (observed order); dashed grey lines are reference "
          "slopes 1, 2 and 4. Filled markers are the ladder levels the fit used; hollow ones were left out "
          "(round-off floor, or errors above 10 % of the motion before the asymptotic range). \"Declared order "
          "holds\" is stepbench's verdict: the observed order within 0.5 of the declared one. The adaptive methods "
          "run over the tolerance ladder (rtol = atol = tol); their slope is fitted to log `err_pos_max` against "
          "log tol: near 1, the error follows the tolerance asked for.")
    doc.p("Cheapest measured run: for each target error, the cheapest method whose run reaches it, from the "
          "study's `equal_error` table: by measured time when the study has a time for every qualifying run, else "
          "by counted force evaluations; diverged or failed runs and runs the time budget cut do not count. The "
          "hand-written baseline is a timing floor, never the answer: where it reaches the target its cost is "
          "shown for scale. One table asks for the final position error (`err_pos_final`, at the horizon), the "
          "other for the max over the run (`err_pos_max`), which a game needs at every frame: a final error can be "
          "small by luck and the note says so. `stepbench advise --problem P --tol X` answers for any target.")
    doc.p("References: the reference solutions every error is measured against (or checked with, where a closed "
          "form exists): status, accepted steps, rejected attempts, right-hand-side calls as the solver reports "
          "them, the extra calls CVODE makes for its difference-quotient Jacobian, and every call counted by a "
          "wrapper; agreement is the max over the sample times of |difference| relative to the motion's scale.")


def _limit_cell(row, column):
    """A limit as the table shows it: the number, or what the flags say instead."""
    if row["unstable_for_all_dt"]:
        return "unstable for every dt"
    if row["unconditionally_stable"]:
        return "stable for every dt"
    v = row[column]
    if np.isfinite(v):
        return f"{v:.6f}"
    return "no verdict: the step fails" if np.isfinite(row["step_failed_at"]) else "none found"


def _stability(doc, study, figs):
    doc.h(2, "Stability")
    st = study.stability
    if st is None:
        doc.note("Stability limits and regions: absent (this study file has no /stability group).")
        return
    a = st.attrs
    doc.p("Computed by stepbench from the compiled steps of our integrators when it wrote the file "
          f"({float(a['limits_seconds']) + float(a['regions_seconds']):.2f} s), on two linear test problems: "
          f"the undamped oscillator ({a['oscillator']}) and pure decay ({a['decay']}). "
          "The adaptive methods are measured by the step they take when every attempt is accepted "
          f"(tolerance {float(a['adaptive_tolerance']):g}): rk45's Dormand-Prince step, adaptive_euler's two "
          "half steps of explicit Euler.")
    doc.p("Each limit is found twice. From the amplification matrix M(y) of one step (its columns: one step from "
          "[x; v] = [1; 0] and [0; 1]): the root of rho(M(y)) - 1 - "
          f"{float(a['rho_tol']):g} (rho the spectral radius, the constant a round-off allowance), bracketed on a "
          f"log grid of y from {float(a['y_min']):g} to {float(a['y_max']):g} and bisected to "
          f"{float(a['root_rtol']):g}; a method already unstable at y = {float(a['y_min']):g} is unstable for "
          f"every dt, one stable on the whole grid and at y = {float(a['y_unconditional']):g} for every dt. From "
          f"long runs of {int(a['run_steps'])} steps: unstable when the largest |state| over the second half of "
          f"the run exceeds {float(a['envelope_growth']):g} x the largest over the first half, bisected to "
          f"{float(a['run_rtol']):g}. The last column is stepbench's verdict on their agreement (within "
          f"{100 * float(a['agreement']):g} %, or the runs confirm the flag).")
    rows = []
    for r in st.limits:
        diff = r["rel_difference"]
        rows.append([r["integrator"], r["test"], _limit_cell(r, "theory"), _limit_cell(r, "measured"),
                     f"{diff:+.1e}" if np.isfinite(diff) else "", "yes" if r["run_confirms"] else "NO",
                     r["note"]])
    doc.h(3, "Stability limits")
    doc.table(["integrator", "test", "largest stable y, from M(y)", "from long runs", "runs / M(y) - 1",
               "agree", "long runs"], rows)
    failed = [r for r in st.limits if np.isfinite(r["step_failed_at"])]
    for r in failed:
        doc.note(f"{r['integrator']} on {r['test']}: the compiled step fails from y = {r['step_failed_at']:.4g}; "
                 "no flag is set where the step does not exist.")
    if "stability_regions.png" in figs:
        doc.img("fig/stability_regions.png", "stability regions and limits")
    doc.p("Regions: |R(z)| from one step of dt = 1 on a damper with the complex rate z (two velocity coordinates, "
          "F = m L v, L = [[a, -b], [b, a]] for z = a + ib), on the grid stored in the file; each curve is "
          "|R| = 1, stable on the side that contains small negative z (outside the circle for implicit Euler, "
          "the left half-plane for implicit midpoint). Methods with the same R share a curve. For "
          "semi-implicit Euler, momentum and velocity Verlet this is the region for a velocity-dependent force; "
          "for springs, where the force depends on position and they are symplectic, their oscillator limit "
          "(omega dt < 2) is the figure that matters.")


def _energy(doc, study, figs):
    doc.h(2, "Energy")
    energy_section.section(doc, study, figs)


def _metadata(doc, study):
    """The appendix: how the study was made, on what, and its problems."""
    a = study.attrs
    doc.h(2, "Appendix: the study")
    doc.note("Generated by `scripts/report` from the study file; do not edit, regenerate it. Every verdict, "
             "ranking, front and fit in this report was computed by stepbench when it wrote the file; the report "
             "draws and formats it.")
    doc.table(["field", "value"], [["study file", study.path]] + [[k, _value(a[k])] for k in META_KEYS],
              caption="Build and machine:")
    if study.timed:
        doc.table(["benchmark setting", "value"], [[k, _value(a[k])] for k in BENCH_KEYS],
                  caption="Timing run (Google Benchmark):")
        if int(a["cpu_scaling_enabled"]) == 1:
            doc.note("CPU frequency scaling was on during the timing run: times may be noisy.")
    else:
        doc.p("Timings: absent (a plain sweep). Costs are counted force evaluations; "
              "`stepbench_bench --study_out` adds measured times.")
    rows = []
    for p in study.problems:
        pa = p.attrs
        params = ", ".join(_parameter(q) for q in p.parameters)
        truth = pa["truth_source"] if int(pa["truth_trusted"]) else f"none trusted: {pa['truth_note']}"
        rows.append([p.name, pa["description"], fmt_num(pa["horizon"], 4) + " s", p.unit, truth, params])
    doc.table(["problem", "scene", "horizon", "position unit", "truth", "parameters"], rows, caption="Problems:")
