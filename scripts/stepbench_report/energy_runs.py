"""The long-run energy section of the report: /energy as stored (docs/study-format.md),
its figure (relative energy error against time on a log time axis, one panel per
problem) and its table. Every number is the study file's: the largest error, the drift
per period, the verdict and its sign were computed by stepbench (run/energy.cpp)."""
from dataclasses import dataclass

import numpy as np

from . import schema

ENERGY_ATTRS = ("periods", "samples_per_period", "series_points", "bounded_growth", "lost", "rule", "wall_seconds")
ENERGY_PROBLEM_ATTRS = ("period", "dt", "steps_per_period", "horizon", "energy0", "angular_momentum0")
SUMMARY_FIELDS = schema.fields("energy_summary")
VERDICTS = ("bounded", "drifting", "")


@dataclass
class EnergyProblem:
    name: str
    attrs: dict
    summary: np.ndarray
    series: dict  # method -> (time, signed relative energy error)


@dataclass
class EnergyRuns:
    attrs: dict
    problems: list


def read(reader, f):
    """/energy, checked through the study reader; None when the file has none."""
    g = f.get("energy")
    if g is None:
        return None
    attrs = reader.need_attrs(g, ENERGY_ATTRS)
    problems = []
    for name, pg in reader.subgroups(g):
        pattrs = reader.need_attrs(pg, ENERGY_PROBLEM_ATTRS)
        summary = reader.need_table(pg, "summary", SUMMARY_FIELDS)
        reader.need_column(pg, "summary", summary, "verdict", VERDICTS)
        series = {}
        sg = reader.need_group(pg, "series")
        for method, mg in sg.items():
            series[method] = (reader.need_array(mg, "time", 1), reader.need_array(mg, "energy_error", 1))
        problems.append(EnergyProblem(name, pattrs, summary, series))
    return EnergyRuns(attrs, problems)


def verdict_text(row):
    if not row["completed"]:
        return f"failed: {row['note']}"
    if row["verdict"] == "drifting":
        return "drifting, gains" if int(row["drift_sign"]) > 0 else "drifting, loses"
    return str(row["verdict"])


def _sci(v, signed=False):
    v = float(v)
    if not np.isfinite(v):
        return ""
    return f"{v:+.2e}" if signed else f"{v:.2e}"


def rows(p):
    out = []
    for r in p.summary:
        out.append([r["method"], "yes" if r["symplectic"] else "", f"{float(r['dt']):.4g}", _sci(r["max_rel_err"]),
                    _sci(r["final_rel_err"], True), _sci(r["drift_per_period"], True), verdict_text(r),
                    _sci(r["angmom_max_rel_err"]), _sci(r["angmom_drift_per_period"], True)])
    return out


HEAD = ["method", "symplectic", "dt [s]", "max abs(dE)/E0", "final dE/E0", "drift per period", "verdict",
        "max abs(dL)/L0", "dL drift per period"]


def figure(energy, styles, path):
    """|E - E0| / |E0| against time (log-log), one panel per problem: each point the
    largest error in its log-spaced bin (filled: gained energy, hollow: lost it)."""
    from . import figures  # matplotlib, only when drawing
    plt, Line2D = figures.plt, figures.Line2D
    probs = energy.problems
    fig, axes = plt.subplots(1, len(probs), figsize=(7.5 * len(probs), 5.5), squeeze=False)
    seen = {}
    for ax, p in zip(axes[0], probs):
        period = float(p.attrs["period"])
        values = [abs(v) for t, e in p.series.values() for v in e if np.isfinite(v) and v != 0]
        lo, hi = figures._log_limits(values)
        for method, (t, e) in p.series.items():
            st = styles(method)
            ok = np.isfinite(e) & (e != 0)
            ax.plot(t[ok] / period, np.abs(e[ok]), color=st["color"], linewidth=1.1)
            gain, loss = ok & (e > 0), ok & (e < 0)
            step = max(1, len(t) // 16)  # a marker every few points, to tell the curves apart
            idx = np.arange(len(t)) % step == 0
            ax.plot(t[gain & idx] / period, e[gain & idx], linestyle="none", marker=st["marker"], color=st["color"],
                    markersize=4.5)
            ax.plot(t[loss & idx] / period, -e[loss & idx], linestyle="none", marker=st["marker"], color=st["color"],
                    markerfacecolor="white", markersize=4.5)
            seen.setdefault(method, Line2D([], [], color=st["color"], marker=st["marker"]))
        figures.log_scale(ax, "x")
        figures.log_scale(ax, "y")
        ax.set_ylim(lo, hi)
        ax.set_xlabel("time [periods]")
        ax.set_ylabel("|E - E0| / |E0|")
        ax.set_title(f"{p.name}: dt = {float(p.attrs['dt']):.4g} s ({int(p.attrs['steps_per_period'])} steps a period)")
    handles = list(seen.values()) + [Line2D([], [], color="grey", marker="o", linestyle="none"),
                                     Line2D([], [], color="grey", marker="o", markerfacecolor="white",
                                            linestyle="none")]
    labels = list(seen) + ["filled: gained energy", "hollow: lost energy"]
    fig.legend(handles, labels, loc="lower center", ncol=min(6, len(labels)), fontsize=8, frameon=False)
    fig.suptitle("Energy error over 10^4 periods, log time axis")
    fig.tight_layout(rect=(0, 0.1, 1, 0.95))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def section(doc, study, figs):
    e = study.energy_runs
    if e is None:
        doc.note("Long-run energy: absent (this study file has no /energy group).")
        return
    a = e.attrs
    doc.h(3, "Energy over 10^4 periods")
    doc.p(f"Every fixed-step integrator of ours for {float(a['periods']):g} periods at the stated dt, the energy "
          f"error sampled {int(a['samples_per_period'])} times a period; the drift per period is the least-squares "
          f"slope of each period's peak (E - E0) / |E0| (signed) against the period count. Computed by stepbench in {float(a['wall_seconds']):.1f} s. "
          f"Rule: {a['rule']}.")
    if "energy_long_runs.png" in figs:
        doc.img("fig/energy_long_runs.png", "energy error against time")
    for p in e.problems:
        doc.h(4, f"{p.name}: energy over {float(a['periods']):g} periods")
        doc.table(HEAD, rows(p))
