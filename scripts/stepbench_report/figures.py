"""The report's figures (matplotlib, Agg backend, PNG)."""
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import LogLocator  # noqa: E402
from matplotlib.transforms import blended_transform_factory  # noqa: E402
from PIL import Image  # noqa: E402  (matplotlib's own PNG writer)

from . import formatting  # noqa: E402

DPI = 100
plt.rcParams.update({
    "font.size": 10, "axes.titlesize": 11, "axes.labelsize": 10, "legend.fontsize": 8.5,
    "axes.grid": True, "grid.alpha": 0.3, "grid.linewidth": 0.6, "savefig.dpi": DPI,
})

# The lecture's methods (build/stepbench list): drawn and labelled in every
# work-precision figure, each with a colour no other method of the report has.
LECTURE = ("euler", "semi_implicit_euler", "midpoint", "rk4", "momentum")
LECTURE_COLORS = ("#d62728", "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd")
# The other methods' colours and everyone's markers: a method takes the next colour and
# the next marker, so that no two methods share both (13 x 7 pairs before one repeats).
COLORS = ("#8c564b", "#e377c2", "#17becf", "#bcbd22", "#393b79", "#843c39", "#637939", "#c51b7d", "#7b4173",
          "#000000", "#01665e", "#6b6ecf", "#e7ba52")
MARKERS = ("o", "s", "^", "D", "v", "P", "X")
LINESTYLES = {"ours": "-", "peer": "--", "baseline": ":", "plugin": "-."}
# Methods drawn behind the labelled ones, without a legend entry.
GREY = "#c4c4c4"


def method_names(study):
    """(name, origin) of every method the study names, ours first, each group sorted by
    name: what Styles is built from, before a report is cut to one problem."""
    origins = {}
    for p in study.problems:
        for m in p.methods:
            origins.setdefault(m.name, m.origin)
    others = set()
    if study.stability is not None:
        others.update(study.stability.regions)
    if study.energy_runs is not None:
        others.update(n for p in study.energy_runs.problems for n in p.series)
    if study.loop is not None:
        others.update(m.name for p in study.loop.problems for m in p.methods)
    if study.substeps is not None:
        others.update(m.name for s in study.substeps.scenes for m in s.methods)
    for n in others:
        origins.setdefault(n, "ours")
    rank = {"ours": 0, "peer": 1, "baseline": 2, "plugin": 3}
    return sorted(origins.items(), key=lambda item: (rank.get(item[1], 3), item[0]))


class Styles:
    """One colour and marker per method, the same in every figure of the report: the
    lecture's methods their own colours, every other method the next colour and marker
    of the palette in the order of method_names; ours solid with filled markers, peers
    dashed with hollow ones, the baseline dotted."""

    def __init__(self, names):
        """`names`: method_names of a study, or the study itself."""
        if hasattr(names, "problems"):
            names = method_names(names)
        self.style = {}
        k = 0
        for name, origin in names:
            st = dict(linestyle=LINESTYLES.get(origin, "-"))
            if name in LECTURE:
                st.update(color=LECTURE_COLORS[LECTURE.index(name)], marker=MARKERS[LECTURE.index(name)])
            else:
                st.update(color=COLORS[k % len(COLORS)], marker=MARKERS[k % len(MARKERS)])
                k += 1
            if origin != "ours":
                st["markerfacecolor"] = "white"
            self.style[name] = st

    def __call__(self, name):
        return self.style[name]


SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")


def _power_of_ten(value, _pos=None):
    """A log axis's major tick as 10⁻⁴ in plain text: what matplotlib's default writes in
    mathtext, whose parser (per figure, uncached across them) took a tenth of the report's
    drawing time."""
    exponent = math.log10(value) if value > 0 else float("nan")
    if not math.isfinite(exponent) or abs(exponent - round(exponent)) > 1e-9:
        return f"{value:g}"
    return "10" + str(round(exponent)).translate(SUPERSCRIPT)


def log_scale(ax, which):
    """The axis `which` ("x" or "y") of `ax` logarithmic, its decades labelled in plain
    text (_power_of_ten), minor ticks at 2 and 5 times a power of ten: matplotlib's eight a
    decade, each an object of its own, took a quarter of the report's drawing time."""
    (ax.set_xscale if which == "x" else ax.set_yscale)("log")
    axis = ax.xaxis if which == "x" else ax.yaxis
    axis.set_major_formatter(_power_of_ten)
    axis.set_minor_locator(LogLocator(subs=(2.0, 5.0)))


def _log_axes(ax):
    log_scale(ax, "x")
    log_scale(ax, "y")


def error_label(metric, unit):
    what = {"err_pos_max": "max position error over the run", "err_pos_final": "final position error",
            "energy_drift": "|energy drift| at the horizon (relative)"}[metric]
    return f"{what} [{unit}]" if unit else what


PAD_INCHES = 0.12


def _save_cropped(fig, path):
    """The figure drawn once and cropped to its drawn (not white) pixels with PAD_INCHES
    around them: what bbox_inches="tight" writes, without its second layout and draw, which
    made the report half as slow again. False, with nothing written, where the drawing
    touches the canvas's edge: something may lie beyond it, and only a second layout takes
    it in."""
    fig.set_dpi(DPI)
    fig.canvas.draw()
    pixels = np.asarray(fig.canvas.buffer_rgba())
    drawn = (pixels[:, :, :3] != 255).any(axis=2)
    rows, cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
    height, width = drawn.shape
    if not len(rows) or rows[0] == 0 or cols[0] == 0 or rows[-1] == height - 1 or cols[-1] == width - 1:
        return False
    pad = round(PAD_INCHES * DPI)
    crop = pixels[max(0, rows[0] - pad):rows[-1] + 1 + pad, max(0, cols[0] - pad):cols[-1] + 1 + pad]
    Image.fromarray(crop).save(path, compress_level=3)  # faster than the default 6, and as small
    return True


def _save(fig, path, tight=True):
    """tight: crop to what was drawn (a legend outside the axes). The panel figures are
    laid out in inches by _panels and skip it."""
    if not tight:
        fig.savefig(path, dpi=DPI)
    elif not _save_cropped(fig, path):
        fig.savefig(path, dpi=DPI, bbox_inches="tight", pad_inches=PAD_INCHES)
    plt.close(fig)


def coincident(curves):
    """{name: earlier name} for curves (name, x, y) identical to one drawn before (the
    momentum form is semi-implicit Euler up to rounding, and would hide under it)."""
    out, seen = {}, []
    for name, x, y in curves:
        for n0, x0, y0 in seen:
            if len(x0) == len(x) and np.allclose(x0, x) and np.allclose(np.nan_to_num(y0), np.nan_to_num(y),
                                                                         rtol=1e-3, atol=0):
                out[name] = out.get(n0, n0)
                break
        seen.append((name, x, y))
    return out


def _log_limits(values, pad=3.0):
    v = np.asarray([x for x in values if np.isfinite(x) and x > 0])
    if len(v) == 0:
        return 1e-16, 1.0
    return v.min() / pad, v.max() * pad


def _edge_markers(ax, xs, where, style, size=8):
    """Markers pinned to the top (where=1) or bottom (where=0) edge of the axes, for
    values a log axis cannot show (diverged runs, errors exactly zero)."""
    if len(xs) == 0:
        return
    tr = blended_transform_factory(ax.transData, ax.transAxes)
    ax.plot(xs, [where] * len(xs), transform=tr, clip_on=False, linestyle="none", zorder=5,
            markersize=size, **style)


def _fit_label(m):
    """The legend's account of a fixed-step method's fit, from its attributes."""
    status = m.attrs["fit_status"]
    declared = f"{m.declared_order:g}" if np.isfinite(m.declared_order) else "none"
    if status == "exact":
        return f"{formatting.label(m)}: exact for this problem"
    word = "order" if m.origin == "ours" else "declares"
    if status == "fitted":
        return f"{formatting.label(m)}: slope {m.attrs['fit_slope']:.2f} ({word} {declared})"
    return f"{formatting.label(m)}: not fitted ({word} {declared})"


def convergence(problem, styles, path):
    """Log-log max position error against dt: our fixed-step methods in full (fitted
    slope in the legend, fit levels filled, others hollow, diverged rows as x marks in a
    top band), the fixed-step peers and the baseline drawn faintly behind them, guide
    lines of orders 1, 2, 4. Adaptive methods run over tolerances, not timesteps: they
    are on the work-precision figures."""
    fig, ax = plt.subplots(figsize=(10.5, 6.0))
    ours = [m for m in problem.by_origin("ours", adaptive=False)]
    faint = [m for m in problem.methods if m.origin != "ours" and not m.adaptive]
    all_err, all_dt = [], []
    for m in ours + faint:
        err = m.col("err_pos_max")
        all_dt += list(m.param)
        # Diverged rows may carry huge finite errors (over divergence_factor x the scale):
        # they are drawn as x marks, so they must not stretch the axis.
        all_err += list(err[m.completed & np.isfinite(err) & (err > 0)])
    diverging = [m.name for m in ours if m.diverged.any()]
    lo, hi = _log_limits(all_err)
    # Room at the top for one row of x marks per diverging method.
    band = 0.05 * len(diverging)
    if band:
        hi = hi * (hi / lo) ** (band / (1 - band))
    _log_axes(ax)
    ax.set_ylim(lo, hi)
    if all_dt:
        ax.set_xlim(min(all_dt) / 1.5, max(all_dt) * 1.5)
    any_div = any_zero = False
    handles, labels = [], []
    same_as = coincident([(m.name, m.param, m.col("err_pos_max")) for m in ours + faint])
    for k, m in enumerate(ours):
        st = styles(m.name)
        dt, err = m.param, m.col("err_pos_max")
        ok = m.completed & np.isfinite(err) & (err > 0)
        zero = m.completed & (err == 0)
        label = _fit_label(m)
        # Identical curves would hide each other: say so, and draw later ones with smaller
        # markers so the earlier ones show around them.
        if m.name in same_as:
            label += f" (= {same_as[m.name]})"
        group = [n for n in same_as if same_as[n] == same_as.get(m.name)]  # later copies of the same curve
        size = 8.5 - 2.0 * (group.index(m.name) + 1) if m.name in same_as else 8.5
        ax.plot(dt[ok], err[ok], color=st["color"], linestyle="-", linewidth=1.4, zorder=3 + k * 0.01)
        fit = np.isin(np.arange(len(dt)), m.fit_levels)
        ax.plot(dt[ok & fit], err[ok & fit], linestyle="none", marker=st["marker"], color=st["color"],
                markersize=size, zorder=4 + k * 0.01)
        ax.plot(dt[ok & ~fit], err[ok & ~fit], linestyle="none", marker=st["marker"], markerfacecolor="white",
                color=st["color"], markersize=size, zorder=4 + k * 0.01)
        if zero.any():
            any_zero = True
            _edge_markers(ax, dt[zero], 0, dict(marker=st["marker"], color=st["color"], markerfacecolor="white"),
                          size=size + 1)
        if m.diverged.any():
            any_div = True
            row = 0.985 - 0.05 * diverging.index(m.name)  # axes fraction: its own row in the top band
            _edge_markers(ax, dt[m.diverged], row, dict(marker="x", color=st["color"], markeredgewidth=2), size=7)
        handles.append(Line2D([], [], color=st["color"], marker=st["marker"], markersize=6, linewidth=1.4))
        labels.append(label)
    for m in faint:
        st = styles(m.name)
        err = m.col("err_pos_max")
        ok = m.completed & np.isfinite(err) & (err > 0)
        ax.plot(m.param[ok], err[ok], linewidth=1.0, markersize=4.5, alpha=0.45, zorder=2, **st)
        handles.append(Line2D([], [], linewidth=1.0, markersize=4.5, alpha=0.6, **st))
        labels.append(_fit_label(m) + (f" (= {same_as[m.name]})" if m.name in same_as else ""))
    _guides(ax, (1, 2, 4), [(m.param[m.completed], m.col("err_pos_max")[m.completed]) for m in ours], top=1 - band)
    if band:
        edge = lo * (hi / lo) ** (1 - band)
        ax.axhline(edge, color="0.6", linewidth=0.8)
        ax.text(0.01, 1 - band / 2, "diverged", transform=ax.transAxes, rotation=90, va="center", ha="left",
                fontsize=8, color="0.35")
    ax.set_xlabel("timestep dt [s]")
    ax.set_ylabel(error_label("err_pos_max", problem.unit))
    ax.set_title(f"{problem.name}: convergence (horizon {problem.attrs['horizon']:.4g} s)")
    handles.append(Line2D([], [], color="grey", marker="o", linestyle="none"))
    labels.append("filled: levels used by the fit")
    handles.append(Line2D([], [], color="grey", marker="o", markerfacecolor="white", linestyle="none"))
    labels.append("hollow: not used (round-off, pre-asymptotic)")
    if faint:
        handles.append(Line2D([], [], color="grey", linestyle="--", alpha=0.6))
        labels.append("faint: " + " and ".join(w for w, o in (("the peers", "peer"), ("the baseline", "baseline"))
                                               if any(m.origin == o for m in faint)) + " (fixed step)")
    if any_zero:
        handles.append(Line2D([], [], color="grey", marker="o", markerfacecolor="white", linestyle="none"))
        labels.append("on the bottom edge: error exactly 0")
    if any_div:
        handles.append(Line2D([], [], color="grey", marker="x", linestyle="none", markeredgewidth=2))
        labels.append("x in the top band: diverged (a row per method)")
    ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0, frameon=False)
    fig.subplots_adjust(left=0.09, right=0.58, top=0.93, bottom=0.1)
    _save(fig, path)


def _guides(ax, orders, data, top=1.0):
    """Dashed grey lines err ~ dt^p from the upper right corner of the data area (below
    `top`, an axes fraction). Each label goes where the line is farthest from the data
    (`data`: list of (x, y) arrays of the plotted curves) and from the other labels, so
    no text sits on a curve."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    lx, ly_full = math.log10(x1 / x0), math.log10(y1 / y0)
    ly = ly_full * top
    ya = y0 * 10 ** (0.92 * ly)  # anchor just below the top right corner
    xs = np.logspace(math.log10(x0), math.log10(x1), 50)

    def frac(x, y):  # data -> axes fraction on the log axes
        return np.log10(np.asarray(x) / x0) / lx, np.log10(np.asarray(y) / y0) / ly_full

    # The curves, densified along their segments, in axes fractions.
    pts = []
    for x, y in data:
        ok = np.isfinite(x) & np.isfinite(y) & (np.asarray(x) > 0) & (np.asarray(y) > 0)
        fx, fy = frac(np.asarray(x)[ok], np.asarray(y)[ok])
        for i in range(len(fx)):
            pts.append((fx[i], fy[i]))
            if i + 1 < len(fx):
                for t in np.linspace(0.1, 0.9, 9):
                    pts.append((fx[i] + t * (fx[i + 1] - fx[i]), fy[i] + t * (fy[i + 1] - fy[i])))
    pts = np.array(pts) if pts else np.zeros((0, 2))
    placed = []
    for p in orders:
        ax.plot(xs, ya * (xs / x1) ** p, color="0.55", linestyle="--", linewidth=0.9, zorder=1)
        best, best_score = None, -1.0
        for xc in np.logspace(math.log10(x0), math.log10(x1), 80)[3:-3]:
            yc = ya * (xc / x1) ** p
            fx, fy = frac(xc, yc)
            if not (0.06 < fy < top - 0.06):
                continue
            # Label box ~ 0.1 wide, 0.05 high (axes fractions): distance in box units.
            near = [np.min(np.hypot((pts[:, 0] - fx) / 0.1, (pts[:, 1] - fy) / 0.05))] if len(pts) else [9.0]
            near += [np.hypot((q[0] - fx) / 0.1, (q[1] - fy) / 0.05) for q in placed]
            score = min(near)
            if score > best_score:
                best, best_score = (xc, yc, fx, fy), score
        if best is None:
            continue
        placed.append(best[2:])
        ax.text(best[0], best[1], f"order {p}", color="0.3", fontsize=8, ha="center", va="center", zorder=6,
                bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="0.8", linewidth=0.5))


# Where each work-precision figure takes its cost from: the rows' field, the factor to
# the plotted unit, the axis label.
WORK_AXES = {
    "force_evals": ("force_evals", 1.0, "force evaluations per run"),
    "time": ("time_ns", 1e-9, "median wall time per run [s]"),
}


def _legend_beside(ax, handles, labels):
    ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0, frameon=False,
              fontsize=9)


def work_curves(problem, front_key, timed):
    """(method, cost, error) of every method with a row to draw: completed, with a cost
    and an error, and in a timed study not cut by the time budget (the rows the front was
    taken over)."""
    field, to_unit, _ = WORK_AXES[front_key]
    curves = []
    for m in problem.methods:
        x, e = m.col(field) * to_unit, m.col("err_pos_max")
        ok = m.completed & np.isfinite(x) & (x > 0) & np.isfinite(e) & ~(timed & m.cut)
        if ok.any():
            curves.append((m, x[ok], e[ok]))
    return curves


def labelled(problem, front_key):
    """The methods a work-precision figure draws in colour and names: those on the
    study's Pareto front (in the front's order), then the lecture's."""
    front = list(dict.fromkeys(problem.fronts[front_key]["method"].tolist()))
    names = {m.name for m in problem.methods}
    return front + [n for n in LECTURE if n in names and n not in front]


def work_precision(problem, styles, path, front_key, timed):
    """Error against cost on one problem, log-log: the methods of `labelled` in their
    colours with a legend beside the axes, every other method light grey behind them
    (the table under the figure lists them all), and the Pareto front the study computed
    (`front_<key>`) as a thin black step line."""
    _, to_unit, xlabel = WORK_AXES[front_key]
    fig, ax = plt.subplots(figsize=(11.2, 5.6))
    curves = work_curves(problem, front_key, timed)
    shown = labelled(problem, front_key)
    front_names = set(problem.fronts[front_key]["method"].tolist())
    lo, hi = _log_limits([v for _, _, e in curves for v in e])
    _log_axes(ax)
    ax.set_ylim(lo, hi)
    same_as = coincident([(m.name, x, e) for m, x, e in curves if m.name in shown])
    greys = 0
    for m, xs, es in curves:
        if m.name in shown:
            continue
        greys += 1
        pos = es > 0
        ax.plot(xs[pos], es[pos], color=GREY, marker="o", markersize=3, linewidth=0.8, zorder=1)
    handles, labels = [], []
    any_zero = False
    by_name = {m.name: (m, xs, es) for m, xs, es in curves}
    for k, name in enumerate(shown):
        if name not in by_name:
            continue
        m, xs, es = by_name[name]
        st = styles(name)
        pos = es > 0
        size = 4.5 if name in same_as else 6.5
        ax.plot(xs[pos], es[pos], markersize=size, linewidth=1.3, zorder=3 + 0.01 * k, **st)
        if (~pos).any():
            any_zero = True
            _edge_markers(ax, xs[~pos], 0, dict(marker=st["marker"], color=st["color"], markerfacecolor="white"),
                          size=6)
        tags = [t for t, yes in (("front", name in front_names), ("lecture", name in LECTURE)) if yes]
        text = formatting.label(m) + (f" [{', '.join(tags)}]" if tags else "")
        if name in same_as:
            text += f" (= {same_as[name]})"
        handles.append(Line2D([], [], markersize=6, linewidth=1.3, **st))
        labels.append(text)
    front = problem.fronts[front_key]
    if len(front):
        ax.step(front["cost"] * to_unit, np.maximum(front["err_pos_max"], lo), where="post", color="black",
                linewidth=1.0, alpha=0.8, zorder=5)
        handles.append(Line2D([], [], color="black", linewidth=1.0, alpha=0.8))
        labels.append("Pareto front: no run beats it in both\ncost and error (baseline excluded)")
    if greys:
        handles.append(Line2D([], [], color=GREY, marker="o", markersize=3, linewidth=0.8))
        labels.append(f"{greys} other methods (listed below)")
    if any_zero:
        handles.append(Line2D([], [], color="grey", marker="o", markerfacecolor="white", linestyle="none"))
        labels.append("on the bottom edge: error exactly 0")
    _legend_beside(ax, handles, labels)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(error_label("err_pos_max", problem.unit))
    ax.set_title(f"{problem.name}: error against {'time' if front_key == 'time' else 'force evaluations'}")
    fig.subplots_adjust(left=0.08, right=0.64, top=0.93, bottom=0.1)
    _save(fig, path)


def energy_drifts(problem):
    """The |energy drift| values the energy figure draws (our fixed-step methods' completed
    runs with a drift); none where the problem has no energy, and then no figure."""
    if int(problem.attrs["has_energy"]) != 1:
        return []
    vals = []
    for m in problem.by_origin("ours", adaptive=False):
        d = m.col("energy_drift")
        ok = m.completed & np.isfinite(d) & (np.abs(d) > 0)
        vals += list(np.abs(d[ok]))
    return vals


def energy(problem, styles, path):
    """|energy drift| at the horizon against dt on one problem with an energy, our
    fixed-step methods (filled: gained energy, hollow: lost it); False when there is
    nothing to draw."""
    vals = energy_drifts(problem)
    if not vals:
        return False
    ours = problem.by_origin("ours", adaptive=False)
    fig, ax = plt.subplots(figsize=(11.2, 5.0))
    lo, hi = _log_limits(vals)
    _log_axes(ax)
    ax.set_ylim(lo, hi)
    same_as = coincident([(m.name, m.param, np.abs(m.col("energy_drift"))) for m in ours])
    handles, labels = [], []
    for m in ours:
        st = styles(m.name)
        dt, d = m.param, m.col("energy_drift")
        ok = m.completed & np.isfinite(d) & (np.abs(d) > 0)
        if not ok.any():
            continue
        size = 3.5 if m.name in same_as else 5.5  # coinciding curves nest instead of hiding
        ax.plot(dt[ok], np.abs(d[ok]), color=st["color"], linewidth=1.1, zorder=2)
        gain, loss = ok & (d > 0), ok & (d < 0)
        ax.plot(dt[gain], d[gain], linestyle="none", marker=st["marker"], color=st["color"], markersize=size,
                zorder=3)
        ax.plot(dt[loss], -d[loss], linestyle="none", marker=st["marker"], color=st["color"],
                markerfacecolor="white", markersize=size, zorder=3)
        handles.append(Line2D([], [], color=st["color"], marker=st["marker"]))
        labels.append(m.name + (f" (= {same_as[m.name]})" if m.name in same_as else ""))
    handles += [Line2D([], [], color="grey", marker="o", linestyle="none"),
                Line2D([], [], color="grey", marker="o", markerfacecolor="white", linestyle="none")]
    labels += ["filled: gained energy", "hollow: lost energy"]
    _legend_beside(ax, handles, labels)
    ax.set_xlabel("timestep dt [s]")
    ax.set_ylabel("|energy drift| / energy scale [-]")
    ax.set_title(f"{problem.name}: energy error at the horizon")
    fig.subplots_adjust(left=0.08, right=0.64, top=0.92, bottom=0.11)
    _save(fig, path)
    return True


def _same_regions(stab):
    """The integrators grouped by identical |R| grids (to 1e-12): on the damper several
    methods share a stability function (semi-implicit Euler's velocity update is explicit
    Euler's), and their curves would hide under each other."""
    groups = []
    for name in stab.regions:
        grid = stab.regions[name]
        for g in groups:
            if np.allclose(stab.regions[g[0]], grid, rtol=1e-12, atol=0, equal_nan=True):
                g.append(name)
                break
        else:
            groups.append([name])
    return groups


def _limit_text(row):
    if row is None:
        return "not in the file"
    if row["unstable_for_all_dt"]:
        return "unstable for every dt"
    if row["unconditionally_stable"]:
        return "stable for every dt"
    if not np.isfinite(row["theory"]):
        return "no verdict"
    return f"< {row['theory']:.4f}"


def stability(stab, styles, path):
    """Left: the stability regions |R(z)| <= 1 in the plane of z = dt lambda, as stored in
    /stability (|R| from the compiled steps on the complex damper), the contour |R| = 1 of
    each group of methods with the same R. Right: the limits on the oscillator and on
    decay from /stability/limits: bars from the amplification matrix, crosses from the
    long runs."""
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 6.4), gridspec_kw={"width_ratios": [1.1, 1]})
    zr, zi = np.meshgrid(stab.re, stab.im)
    handles, labels = [], []
    dashes = ["-", "--", "-.", ":"]
    for k, group in enumerate(_same_regions(stab)):
        color = styles(group[0])["color"] if group[0] in styles.style else f"C{k}"
        mag = np.ma.masked_invalid(stab.regions[group[0]])
        ls = dashes[k % len(dashes)]
        ax.contour(zr, zi, mag, levels=[1.0], colors=[color], linewidths=1.8, linestyles=[ls])
        handles.append(Line2D([], [], color=color, linewidth=1.8, linestyle=ls))
        labels.append(" = ".join(group))
    ax.axhline(0, color="black", linewidth=0.7)
    ax.axvline(0, color="black", linewidth=0.7)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlim(stab.re[0], stab.re[-1])
    ax.set_ylim(stab.im[0], stab.im[-1])
    ax.set_xlabel("Re(z),  z = dt * lambda  [-]")
    ax.set_ylabel("Im(z)  [-]")
    ax.set_title("Stability regions: the curves |R(z)| = 1")
    ax.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, -0.12), fontsize=8.5, frameon=False,
              ncol=2)

    names = list(dict.fromkeys(stab.limits["integrator"]))
    tests = (("oscillator", "tab:blue", "oscillator: omega * dt"), ("decay", "tab:orange", "decay: lambda * dt"))
    finite = [r["theory"] for r in stab.limits if np.isfinite(r["theory"])]
    right = 1.5 * max(finite + [1.0])
    height = 0.38
    for j, (test, color, text) in enumerate(tests):
        for i, name in enumerate(names):
            row = stab.limit(name, test)
            yc = i + (j - 0.5) * height
            value = row["theory"] if row is not None else np.nan
            if row is not None and row["unconditionally_stable"]:
                bx.barh(yc, right, height=height, color=color, alpha=0.25, hatch="//", edgecolor=color)
            elif np.isfinite(value):
                bx.barh(yc, value, height=height, color=color)
                if np.isfinite(row["measured"]):
                    bx.plot([row["measured"]], [yc], marker="x", color="black", markersize=6, zorder=4)
            bx.text((value if np.isfinite(value) else 0.0) + 0.04 * right / 1.5, yc, _limit_text(row), va="center",
                    fontsize=8)
        bx.barh([np.nan], [np.nan], color=color, label=text)
    bx.plot([], [], marker="x", color="black", linestyle="none", label="long runs")
    bx.set_yticks(range(len(names)))
    bx.set_yticklabels(names)
    bx.invert_yaxis()
    bx.set_xlim(0, right * 1.35)
    bx.set_xlabel("largest stable y  [-]")
    bx.set_title("Limits: x'' = -omega^2 x and v' = -lambda v")
    bx.grid(axis="y", visible=False)
    bx.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=3, fontsize=8.5, frameon=False)
    fig.subplots_adjust(left=0.06, right=0.98, top=0.93, bottom=0.22, wspace=0.3)
    _save(fig, path)
