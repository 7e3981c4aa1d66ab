"""The "small steps or one implicit step?" section of the report (Macklin et al., Small
Steps in Physics Simulation, SCA 2019): /substeps as stored (docs/study-format.md), its
figure (max position error against cost per frame, one panel per scene) and its tables.
Every number is the study file's: the runs, the artificial damping and the verdict at
equal cost (its one-line summary included) were computed by stepbench
(run/substeps.cpp). The only arithmetic here is a unit: the stored costs are those of
the whole run, and the figure and table divide them by the run's frames (horizon /
frame_dt)."""
from dataclasses import dataclass

import numpy as np

from . import schema
from .formatting import fmt_time_ns

SUBSTEP_ATTRS = ("frame_dt",)
SUBSTEP_METHOD_ATTRS = ("origin", "needs_jacobian")
SUBSTEP_RUN_FIELDS = schema.fields("substeps_runs")
TIMED_RUN_FIELDS = schema.timed_fields("substeps_runs")
VERDICT_FIELDS = schema.fields("substeps_verdict")
COST_KINDS = ("time_ns", "force_evals")
ORIGINS = ("ours", "peer", "baseline", "plugin")
FIGURE = "substeps_equal_cost.png"


@dataclass
class SubstepMethod:
    name: str
    attrs: dict
    runs: np.ndarray  # one row per substep count, strings decoded

    @property
    def implicit(self):
        """One step a frame with a Newton solve (the C++ tells them apart the same way)."""
        return int(self.attrs["needs_jacobian"]) == 1

    @property
    def completed(self):
        r = self.runs
        return schema.completed(r)


@dataclass
class SubstepScene:
    name: str
    attrs: dict
    frames: int  # horizon / frame_dt: the run's frames, by which its costs are divided
    unit: str  # the problem's position unit
    methods: list
    verdict: np.ndarray

    @property
    def frame_dt(self):
        return float(self.attrs["frame_dt"])

    @property
    def cost_kind(self):
        """The cost the verdict compares at (C++'s choice: time when every run has one)."""
        kinds = set(self.verdict["cost_kind"])
        return kinds.pop() if len(kinds) == 1 else "force_evals"

    def cost_per_frame(self, m, kind=None):
        """The runs' cost (`kind`, by default the verdict's) over their frames."""
        col = kind or self.cost_kind
        return np.asarray(m.runs[col], float) / self.frames


@dataclass
class Substeps:
    scenes: list


def read(reader, f):
    """/substeps, checked through the study reader (its need_* raise StudyError naming
    what is missing); None when the file has none."""
    g = f.get("substeps")
    if g is None:
        return None
    timed = int(f.attrs["timing"]) == 1
    problems = reader.need_group(f, "problems")
    scenes = []
    for name, pg in reader.subgroups(g):
        attrs = reader.need_attrs(pg, SUBSTEP_ATTRS)
        pattrs = reader.need_attrs(reader.need_group(problems, name), ("horizon", "position_unit"))
        frames = int(round(float(pattrs["horizon"]) / float(attrs["frame_dt"])))
        methods = []
        for mname, mg in reader.subgroups(reader.need_group(pg, "methods")):
            mattrs = reader.need_attrs(mg, SUBSTEP_METHOD_ATTRS)
            reader.need_value(mg, "origin", mattrs["origin"], ORIGINS)
            runs = reader.need_table(mg, "runs", SUBSTEP_RUN_FIELDS + (TIMED_RUN_FIELDS if timed else ()))
            methods.append(SubstepMethod(mname, mattrs, np.sort(runs, order="substeps")))
        verdict = reader.need_table(pg, "verdict", VERDICT_FIELDS)
        names = {m.name for m in methods}
        reader.need_column(pg, "verdict", verdict, "cost_kind", COST_KINDS)
        for v in verdict:
            for col in ("implicit_method", "explicit_method"):
                if v[col] not in names:
                    raise reader.error(f"{pg.name}/verdict names {v[col]}, which {pg.name}/methods lacks")
        # Implicit methods first, each group in the file's order.
        methods.sort(key=lambda m: not m.implicit)
        scenes.append(SubstepScene(name, attrs, frames, pattrs["position_unit"], methods, verdict))
    return Substeps(scenes)


# --- formatting ----------------------------------------------------------------------------------

def _cost_text(kind, c):
    if not np.isfinite(c):
        return "n/a"
    return fmt_time_ns(c) if kind == "time_ns" else f"{c:.4g} force eval{'' if c == 1 else 's'}"


def _error_text(m, row):
    if row["diverged"]:
        return "diverged"
    if row["failed"] or row["skipped"]:
        return f"{'failed' if row['failed'] else 'skipped'}: {row['note']}"
    v = float(row["err_pos_max"])
    return f"{v:.3g}" if np.isfinite(v) else "n/a"


def _damping_text(v):
    v = float(v)
    return f"{v:+.3g}" if np.isfinite(v) else "n/a"


TABLE_HEAD = ["scene", "method", "substeps a frame", "cost per frame", "max position error", "artificial damping"]


def table_head(scene):
    """By time, the force evaluations per frame follow the measured cost."""
    if scene.cost_kind != "time_ns":
        return TABLE_HEAD
    return TABLE_HEAD[:4] + ["force evals per frame"] + TABLE_HEAD[4:]


def table_rows(scene):
    rows = []
    for m in scene.methods:
        cost = scene.cost_per_frame(m)
        evals = scene.cost_per_frame(m, "force_evals")
        for r, c, e in zip(m.runs, cost, evals):
            row = [scene.name, m.name + (" (one implicit step)" if m.implicit else ""), str(int(r["substeps"])),
                   _cost_text(scene.cost_kind, c)]
            if scene.cost_kind == "time_ns":
                row.append(f"{e:.4g}")
            rows.append(row + [_error_text(m, r), _damping_text(r["extra_damping"])])
    return rows


# --- the figure --------------------------------------------------------------------------------

def _style(styles, name):
    try:
        return styles(name)
    except KeyError:  # a method the study's problems do not list: still drawn
        return dict(color="grey", marker="o", linestyle="-")


def _panel(ax, s, kind, styles, handles, figures):
    """One scene against one cost; returns whether it drew a diverged run."""
    Line2D = figures.Line2D
    explicit = [m for m in s.methods if not m.implicit]
    implicit = [m for m in s.methods if m.implicit]
    errs, costs = [], []
    for m in s.methods:
        e = np.asarray(m.runs["err_pos_max"], float)
        c = s.cost_per_frame(m, kind)
        errs += list(e[m.completed & np.isfinite(e) & (e > 0)])
        costs += list(c[np.isfinite(c) & (c > 0)])
    # Diverged runs carry no usable error (and, timed, often no time): x marks in a band.
    diverging = [m.name for m in explicit if (~m.completed & np.isfinite(s.cost_per_frame(m, kind))).any()]
    lo, hi = figures._log_limits(errs)
    band = 0.07 * len(diverging)
    if band:
        hi = hi * (hi / lo) ** (band / (1 - band))
    figures.log_scale(ax, "x")
    figures.log_scale(ax, "y")
    ax.set_ylim(lo, hi)
    if costs:
        ax.set_xlim(min(costs) / 1.6, max(costs) * 1.6)
    any_div = False
    for m in explicit:
        st = _style(styles, m.name)
        e = np.asarray(m.runs["err_pos_max"], float)
        c = s.cost_per_frame(m, kind)
        n = m.runs["substeps"]
        ok = m.completed & np.isfinite(e) & (e > 0) & np.isfinite(c)
        ax.plot(c[ok], e[ok], color=st["color"], marker=st["marker"], linestyle="-", linewidth=1.4, markersize=6,
                zorder=3)
        for x, y, k in zip(c[ok], e[ok], n[ok]):
            ax.annotate(str(int(k)), (x, y), textcoords="offset points", xytext=(4, -10), fontsize=7,
                        color=st["color"])
        bad = ~m.completed & np.isfinite(c)
        if bad.any():
            any_div = True
            row = 0.975 - 0.07 * diverging.index(m.name)
            figures._edge_markers(ax, c[bad], row, dict(marker="x", color=st["color"], markeredgewidth=2), size=7)
            tr = figures.blended_transform_factory(ax.transData, ax.transAxes)
            for x, k in zip(c[bad], n[bad]):
                ax.annotate(str(int(k)), (x, row), xycoords=tr, textcoords="offset points", xytext=(5, 0),
                            fontsize=7, color=st["color"], va="center", annotation_clip=False)
        handles.setdefault(f"{m.name}: n substeps a frame (n beside the points)",
                           Line2D([], [], color=st["color"], marker=st["marker"], linewidth=1.4))
    for m in implicit:
        st = _style(styles, m.name)
        e = np.asarray(m.runs["err_pos_max"], float)
        c = s.cost_per_frame(m, kind)
        for x, y, done in zip(c, e, m.completed):
            if not np.isfinite(x):
                continue
            ax.axvline(x, color=st["color"], linestyle=":", linewidth=1.0, alpha=0.8, zorder=1)
            if done and np.isfinite(y) and y > 0:
                ax.plot([x], [y], linestyle="none", marker=st["marker"], markersize=13, color=st["color"],
                        markeredgecolor="black", markeredgewidth=0.8, zorder=6)
            else:
                any_div = True
                figures._edge_markers(ax, [x], 0.975, dict(marker="x", color=st["color"], markeredgewidth=2), size=9)
        handles.setdefault(f"{m.name}: one step a frame (dotted: its cost)",
                           Line2D([], [], color=st["color"], marker=st["marker"], markersize=11,
                                  markeredgecolor="black", markeredgewidth=0.8, linestyle="none"))
    if band:
        ax.axhline(lo * (hi / lo) ** (1 - band), color="0.6", linewidth=0.8)
        ax.text(0.01, 1 - band / 2, "diverged", transform=ax.transAxes, rotation=90, va="center", ha="left",
                fontsize=8, color="0.35")
    ax.set_xlabel("measured time per frame [ns]" if kind == "time_ns" else "force evaluations per frame")
    ax.set_ylabel(f"max position error over the run [{s.unit}]")
    ax.set_title(f"{s.name}: {s.frames} frames of {s.frame_dt * 1e3:.3g} ms"
                 + (", by measured time" if kind == "time_ns" else ", by force evaluations"))
    return any_div


def figure(data, styles, path):
    """Max position error over the run against cost per frame (log-log), one panel per
    scene: a line per explicit method through its substep counts (n written beside each
    point; diverged counts as x marks in a band at the top), each implicit method's one
    step a frame as a large marker, with a dotted vertical line at its cost: the substeps
    left of that line cost no more. Against counted force evaluations, and in a study
    whose verdict is by measured time a second row against that time."""
    from . import figures  # matplotlib, only when drawing
    plt, Line2D = figures.plt, figures.Line2D
    scenes = data.scenes
    kinds = ["force_evals"] + (["time_ns"] if any(s.cost_kind == "time_ns" for s in scenes) else [])
    fig, axes = plt.subplots(len(kinds), len(scenes), figsize=(7.2 * len(scenes), 5.0 * len(kinds) + 0.9),
                             squeeze=False)
    handles = {}
    any_div = False
    for row, kind in zip(axes, kinds):
        for ax, s in zip(row, scenes):
            if kind == "time_ns" and s.cost_kind != "time_ns":
                ax.set_axis_off()
                ax.text(0.5, 0.5, f"{s.name}: no measured time for every run", ha="center", transform=ax.transAxes)
                continue
            any_div |= _panel(ax, s, kind, styles, handles, figures)
    labels = list(handles)
    hs = list(handles.values())
    if any_div:
        hs.append(Line2D([], [], color="grey", marker="x", linestyle="none", markeredgewidth=2))
        labels.append("x in the top band: diverged (n beside it)")
    fig.legend(hs, labels, loc="lower center", ncol=min(3, len(labels)), frameon=False)
    fig.suptitle("Small steps or one implicit step? Max position error against cost per frame", fontsize=12)
    fig.tight_layout(rect=(0, 0.9 / (5.0 * len(kinds) + 0.9), 1, 0.96))
    figures._save(fig, path)


# --- the section --------------------------------------------------------------------------------

def verdict_lines(scene):
    """The verdict, one line per (implicit, explicit) pair, exactly as stepbench wrote it."""
    return [str(v) for v in scene.verdict["summary"]]


def _names(data, implicit):
    names = dict.fromkeys(m.name for s in data.scenes for m in s.methods if m.implicit == implicit)
    return " and ".join(f"`{n}`" for n in names) or "none"


def _counts(data):
    return sorted({int(n) for s in data.scenes for m in s.methods if not m.implicit for n in m.runs["substeps"]})


def section(doc, study, figs):
    doc.h(2, "Small steps or one implicit step?")
    data = getattr(study, "substeps", None)
    if data is None:
        doc.note("Small steps or one implicit step: absent (this study file has no /substeps group; the study "
                 "writes one when it runs stiff_spring or spring_chain).")
        return
    kinds = {s.cost_kind for s in data.scenes}
    by_time = kinds == {"time_ns"}
    doc.p("Macklin et al. (Small Steps in Physics Simulation, SCA 2019) found that n small explicit steps a frame "
          "beat one implicit step with n solver iterations on stiff systems. Measured here on springs "
          f"({', '.join(s.name for s in data.scenes)}): one step a frame of {_names(data, True)} (a Newton solve "
          f"a step) against n substeps of the frame, n = {', '.join(str(n) for n in _counts(data))}, of "
          f"{_names(data, False)}, each run measured like every study row (max position error over the run "
          "against the truth at the frame ends). Cost per frame is the run's "
          + ("measured time" if by_time else "counted force evaluations (those of the Newton iterations included; "
                                              "the Jacobian evaluations and linear solves of the implicit step are "
                                              "not counted: a timed study's measured time includes them)")
          + " divided by its frames. Artificial damping is the largest energy the run removed beyond the true "
          "damper's loss, max_j (E_true(t_j) - E(t_j)) / energy_scale, as stored: negative when the method keeps "
          "more energy than the damper leaves. The verdict compares at equal cost "
          + ("(measured time)" if by_time else "(force evaluations)")
          + ": how many substeps the implicit step's cost buys, and how many it takes to match its error; its "
          "lines are stepbench's own, and the costs they quote are those of the whole run, not of a frame.")
    doc.p("The figure: error against force evaluations per frame"
          + (" (top) and against measured time per frame (bottom, the verdict's cost)" if by_time else "")
          + "; a line per explicit method through its substep counts n (written beside the points, diverged "
            "counts as x marks in the top band), each implicit method's one step a frame as a large marker with a "
            "dotted line at its cost: the substeps left of that line cost no more.")
    if FIGURE in figs:
        doc.img(f"fig/{FIGURE}", "max position error against cost per frame: substeps against one implicit step")
    for s in data.scenes:
        doc.h(3, f"{s.name}: substeps against one implicit step")
        doc.table(table_head(s), table_rows(s),
                  caption=f"{s.frames} frames of {s.frame_dt:.6g} s; position unit {s.unit}; cost per frame in "
                          + ("measured time" if s.cost_kind == "time_ns" else "force evaluations") + ":")
        doc.h(4, f"{s.name}: verdict at equal cost")
        for line in verdict_lines(s):
            doc.p(line)
