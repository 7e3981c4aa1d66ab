"""The parameter-scan section of the report: /scan/<name> as stored (docs/study-format.md,
"/scan/<name>"), its figures and two small tables.

Every number is the study file's. The runs, the cheapest run at each point and rate
(`best`) and the range answer were computed by stepbench (study/scan.cpp; `stepbench
advise --scan FILE --tol X` prints the range answer); nothing here ranks or chooses. The
report reads the runs at one step a frame (substeps == 1) for the map of each method, and
`best` as it is for the map of the cheapest method. The one piece of arithmetic is the
stiff spring's theory overlay: the k_s at which omega dt equals each method's oscillator
limit from /stability/limits (`theory`), k_s = mass_kg (limit * hz)^2.

The study reader (study.py) predates the scans and does not hold them; load() reads
/scan through the same checked reader (study._Reader: need_attrs, need_table)."""
import math
from dataclasses import dataclass

import numpy as np

from . import schema

SCAN_ATTRS = ("problem", "unit", "tol", "axes", "axis_lo", "axis_hi", "axis_count", "axis_log", "hz", "substeps",
              "fixed_params", "fixed_values")
POINT_FIELDS = schema.fields("scan_points")
RUN_FIELDS = schema.fields("scan_runs")
BEST_FIELDS = schema.fields("scan_best")
# The stiff spring's parameters the theory overlay needs: the axis, and the mass (the
# scan's fixed value when set, else the problem's declared default, else 1 kg).
SPRING = "stiff_spring"
SPRING_AXIS = "k_s"
SPRING_MASS = "mass_kg"
SPRING_DEFAULT_MASS = 1.0


@dataclass
class Scan:
    name: str
    attrs: dict
    axes: list  # the scanned parameters, in the file's order (the first varies slowest)
    values: list  # per axis, its values (1-D), from values/<param>
    points: np.ndarray
    runs: np.ndarray
    best: np.ndarray

    @property
    def problem(self):
        return str(self.attrs["problem"])

    @property
    def unit(self):
        return str(self.attrs["unit"])

    @property
    def tol(self):
        return float(self.attrs["tol"])

    @property
    def rates(self):
        return [float(x) for x in np.atleast_1d(self.attrs["hz"])]

    @property
    def log(self):
        return [int(x) == 1 for x in np.atleast_1d(self.attrs["axis_log"])]

    @property
    def shape(self):
        return tuple(len(v) for v in self.values)

    @property
    def fixed(self):
        """The parameters set with --set: name -> value."""
        names = [n for n in str(self.attrs["fixed_params"]).split(",") if n]
        values = np.atleast_1d(self.attrs["fixed_values"])
        return {n: float(v) for n, v in zip(names, values)}

    @property
    def methods(self):
        """The methods of the runs, in the file's order."""
        return list(dict.fromkeys(self.runs["method"].tolist()))

    def index(self, point):
        """The grid cell (i, j) of a point (the first axis varies slowest); j is 0 for one axis."""
        if len(self.axes) == 1:
            return int(point), 0
        return divmod(int(point), self.shape[1])

    def axis_label(self, k):
        return self.axes[k]

    def value_text(self, k, v):
        return f"{self.axes[k]} = {float(v):.3g}"


# --- reading ------------------------------------------------------------------------------------

def read(reader, f):
    """Every /scan/<name>, checked through the study reader (its need_* raise StudyError
    naming what is missing); None when the file has no /scan (an older study)."""
    g = f.get("scan")
    if g is None:
        return None
    scans = []
    for name, sg in reader.subgroups(g):
        attrs = reader.need_attrs(sg, SCAN_ATTRS)
        axes = [a for a in str(attrs["axes"]).split(",") if a]
        counts = [int(c) for c in np.atleast_1d(attrs["axis_count"])]
        if not axes or len(axes) > 2 or len(counts) != len(axes) or len(np.atleast_1d(attrs["axis_log"])) != len(axes):
            raise reader.error(f"{sg.name}: axes '{attrs['axes']}' do not match axis_count and axis_log "
                               "(a scan has one or two axes)")
        # values/<param>: the parameter at each grid point, the first axis varying
        # slowest; an axis's own values are read along it.
        vg = reader.need_group(sg, "values")
        values = []
        for k, a in enumerate(axes):
            v = reader.need_array(vg, a, 1)
            if len(v) != math.prod(counts):
                raise reader.error(f"{vg.name}/{a} has {len(v)} values, not the grid's {math.prod(counts)}")
            grid = v.reshape(counts)
            values.append(grid[:, 0] if (len(axes) == 2 and k == 0) else grid[0, :] if len(axes) == 2 else grid)
        points = reader.need_table(sg, "points", POINT_FIELDS)
        runs = reader.need_table(sg, "runs", RUN_FIELDS)
        best = reader.need_table(sg, "best", BEST_FIELDS)
        npoints = math.prod(counts)
        rates = [float(x) for x in np.atleast_1d(attrs["hz"])]
        for table, rows in (("points", points), ("runs", runs), ("best", best)):
            if len(rows) and (rows["point"].min() < 0 or rows["point"].max() >= npoints):
                raise reader.error(f"{sg.name}/{table} names a point beyond the grid's {npoints}")
        for table, rows in (("runs", runs), ("best", best)):
            reader.need_column(sg, table, rows, "hz", rates)
        reader.need_column(sg, "best", best, "method", [""] + list(dict.fromkeys(runs["method"].tolist())))
        scans.append(Scan(name, attrs, axes, values, points, runs, best))
    return scans


def load(path):
    """The scans of the study at `path` (read after study.load accepted the file), or None."""
    from . import study  # the reader; imported here, as study.py imports the sections
    f = study._open(path)
    try:
        with f:
            return read(study._Reader(path, f), f)
    except study.StudyError:
        raise
    except (OSError, KeyError, ValueError, RuntimeError, TypeError, MemoryError) as e:
        raise study._error(path, f"damaged or truncated HDF5 file: {study._first_line(e)}") from None


# --- what the figures and tables show -------------------------------------------------------------

def one_step_grid(scan, hz, methods=None):
    """The map of one rate at one step a frame, one axis only: (log10 err_pos_max,
    unstable, present), each methods x points. `unstable`: the run did not complete
    (diverged, failed or skipped); `present`: there is a run at all."""
    methods = scan.methods if methods is None else methods
    n = scan.shape[0]
    err = np.full((len(methods), n), np.nan)
    unstable = np.zeros((len(methods), n), bool)
    present = np.zeros((len(methods), n), bool)
    rows = scan.runs[(scan.runs["hz"] == hz) & (scan.runs["substeps"] == 1)]
    done = schema.completed(rows)
    row_of = {m: k for k, m in enumerate(methods)}
    for r, ok in zip(rows, done):
        k = row_of.get(r["method"])
        if k is None:
            continue
        i = int(r["point"])
        present[k, i] = True
        if not ok:
            unstable[k, i] = True
        else:
            e = float(r["err_pos_max"])
            err[k, i] = math.log10(max(e, 1e-300)) if np.isfinite(e) else np.nan
    return err, unstable, present


def first_unstable(scan, hz, method):
    """The first axis value at which `method`'s run at one step a frame did not complete
    (None: every run completed)."""
    _, unstable, _ = one_step_grid(scan, hz, [method])
    hits = np.flatnonzero(unstable[0])
    return float(scan.values[0][hits[0]]) if len(hits) else None


def spring_mass(scan, problem=None):
    """The stiff spring's mass in the scan: its fixed value, else the declared default."""
    if SPRING_MASS in scan.fixed:
        return scan.fixed[SPRING_MASS]
    if problem is not None:
        rows = problem.parameters[problem.parameters["name"] == SPRING_MASS]
        if len(rows):
            return float(rows[0]["default"])
    return SPRING_DEFAULT_MASS


def has_theory(scan, stability):
    """The overlay applies to a one-axis scan of the stiff spring over k_s."""
    return (stability is not None and scan.problem == SPRING and len(scan.axes) == 1
            and scan.axes[0] == SPRING_AXIS and SPRING_MASS not in scan.axes)


def theory_limits(scan, stability, mass):
    """method -> (omega dt limit, {hz: k_s at that limit}) for each method with a finite
    oscillator limit in /stability/limits (`theory`); the unconditionally stable and the
    always unstable have none."""
    out = {}
    for m in scan.methods:
        row = stability.limit(m, "oscillator")
        if row is None or row["unstable_for_all_dt"] or row["unconditionally_stable"]:
            continue
        y = float(row["theory"])
        if np.isfinite(y):
            out[m] = (y, {hz: mass * (y * hz) ** 2 for hz in scan.rates})
    return out


def limit_flags(scan, stability):
    """method -> "unstable for every dt" / "stable for every dt", from /stability/limits."""
    out = {}
    if stability is None:
        return out
    for m in scan.methods:
        row = stability.limit(m, "oscillator")
        if row is None:
            continue
        if row["unstable_for_all_dt"]:
            out[m] = "unstable for every dt"
        elif row["unconditionally_stable"]:
            out[m] = "stable for every dt"
    return out


def best_grid(scan, hz):
    """`best` at one rate on the grid: (method, substeps) per cell, shape of the grid
    ((n, 1) for one axis); method "" where none meets the tolerance."""
    shape = scan.shape if len(scan.axes) == 2 else (scan.shape[0], 1)
    method = np.full(shape, "", dtype=object)
    substeps = np.zeros(shape, int)
    for r in scan.best[scan.best["hz"] == hz]:
        i, j = scan.index(r["point"])
        method[i, j] = r["method"]
        substeps[i, j] = int(r["substeps"])
    return method, substeps


def choice_text(method, n):
    return f"{method} x{int(n)}" if method else ""


def _span_text(values, lo, hi):
    a, b = float(values[lo]), float(values[hi])
    return f"{a:.3g}" if lo == hi else f"{a:.3g} .. {b:.3g}"


def best_summary(scan, hz):
    """Per choice (method x substeps) at one rate, in the order it first appears, where
    `best` names it: one axis, its runs of consecutive points; two axes, the span of each
    axis and the count of points. "" is where no run meets the tolerance."""
    method, substeps = best_grid(scan, hz)
    order = {}
    for i in range(method.shape[0]):
        for j in range(method.shape[1]):
            order.setdefault(choice_text(method[i, j], substeps[i, j]), []).append((i, j))
    out = []
    for choice, cells in order.items():
        if len(scan.axes) == 1:
            idx = [i for i, _ in cells]
            runs, start = [], idx[0]
            for a, b in zip(idx, idx[1:] + [None]):
                if b != a + 1:
                    runs.append(_span_text(scan.values[0], start, a))
                    start = b
            where = f"{scan.axes[0]} " + ", ".join(runs)
        else:
            i = [c[0] for c in cells]
            j = [c[1] for c in cells]
            where = (f"{scan.axes[0]} {_span_text(scan.values[0], min(i), max(i))}, "
                     f"{scan.axes[1]} {_span_text(scan.values[1], min(j), max(j))}")
        out.append((choice, where, len(cells)))
    return out


# --- the figures --------------------------------------------------------------------------------

def figure_names(scan):
    """The figure files of a scan: the map per method (one axis only) and the cheapest map."""
    names = {"best": f"scan_{scan.name}_cheapest.png"}
    if len(scan.axes) == 1:
        names["one_step"] = f"scan_{scan.name}_one_step.png"
    return names


def _edges(values, log):
    """Cell edges around the grid values: midpoints (geometric on a log axis)."""
    v = np.log10(values) if log else np.asarray(values, float)
    if len(v) == 1:
        e = np.array([v[0] - 0.5, v[0] + 0.5])
    else:
        mid = (v[1:] + v[:-1]) / 2
        e = np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])
    return 10 ** e if log else e


def _style(styles, name, fallback):
    try:
        return styles(name)
    except (KeyError, TypeError):  # a method the study's problems do not list: a colour of its own
        if name not in fallback:
            fallback[name] = dict(color=f"C{len(fallback) % 10}", marker="o")
        return fallback[name]


def _cells(ax, x_edges, y_edges, colours):
    """Filled rectangles, colours[i][j] the cell between x_edges[i:i+2] and y_edges[j:j+2]
    (None: not drawn); pcolormesh takes no RGBA grid in the matplotlib Debian ships."""
    from matplotlib.patches import Rectangle
    for i in range(len(x_edges) - 1):
        for j in range(len(y_edges) - 1):
            c = colours[i][j]
            if c is not None:
                ax.add_patch(Rectangle((x_edges[i], y_edges[j]), x_edges[i + 1] - x_edges[i],
                                       y_edges[j + 1] - y_edges[j], facecolor=c, edgecolor="white", linewidth=0.6))


def _text_colour(colour):
    from matplotlib.colors import to_rgb
    r, g, b = to_rgb(colour)
    return "black" if 0.299 * r + 0.587 * g + 0.114 * b > 0.55 else "white"


MAX_WIDTH_IN = 13.8  # 1380 px at the report's 100 dpi


def one_step_figure(scan, stability, mass, path):
    """A panel per frame rate: x the scan's axis, a row per method, each cell coloured by
    log10 of the max position error of the run at one step a frame, grey with a black x
    where it did not complete; for the stiff spring over k_s, a red bar in each method's
    row at the k_s where omega dt is its oscillator limit (theory)."""
    from . import figures  # matplotlib, only when drawing
    plt, Line2D = figures.plt, figures.Line2D
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch
    methods = scan.methods
    rates = scan.rates
    grids = [one_step_grid(scan, hz, methods) for hz in rates]
    finite = np.concatenate([g[0][np.isfinite(g[0])] for g in grids]) if grids else np.array([])
    vmin, vmax = (math.floor(finite.min()), math.ceil(finite.max())) if len(finite) else (-16, 0)
    if vmin == vmax:
        vmin -= 1
    limits = theory_limits(scan, stability, mass) if has_theory(scan, stability) else {}
    ncols = min(2, len(rates))
    nrows = math.ceil(len(rates) / ncols)
    row_h = 0.32
    panel_h = max(2.6, row_h * len(methods) + 1.3)
    width = min(MAX_WIDTH_IN - 1.0, 1.8 + 5.6 * ncols + (1.6 if ncols == 1 else 0))
    fig, axes = plt.subplots(nrows, ncols, figsize=(width, panel_h * nrows + 0.6), squeeze=False)
    x_edges = _edges(scan.values[0], scan.log[0])
    y_edges = np.arange(len(methods) + 1) - 0.5
    grey = ListedColormap(["0.72"])
    mesh = None
    for ax, hz, (err, unstable, present) in zip(axes.flat, rates, grids):
        mesh = ax.pcolormesh(x_edges, y_edges, np.ma.masked_invalid(err), cmap="viridis", vmin=vmin, vmax=vmax,
                             shading="flat")
        ax.pcolormesh(x_edges, y_edges, np.ma.masked_where(~unstable, np.ones_like(err)), cmap=grey, shading="flat")
        ys, xs = np.nonzero(unstable)
        ax.plot(scan.values[0][xs], ys, linestyle="none", marker="x", color="black", markersize=6,
                markeredgewidth=1.4)
        for k, m in enumerate(methods):
            if m in limits:
                ks = limits[m][1][hz]
                if x_edges[0] <= ks <= x_edges[-1]:
                    ax.plot([ks, ks], [k - 0.48, k + 0.48], color="#e8003a", linewidth=3.0, solid_capstyle="butt",
                            zorder=5)
                else:
                    right = ks > x_edges[-1]
                    ax.plot([x_edges[-1] if right else x_edges[0]], [k], marker=">" if right else "<",
                            color="#e8003a", markersize=7, clip_on=False, zorder=5)
        if scan.log[0]:
            ax.set_xscale("log")
        ax.set_xlim(x_edges[0], x_edges[-1])
        ax.set_ylim(len(methods) - 0.5, -0.5)
        ax.set_yticks(range(len(methods)))
        ax.set_yticklabels(methods, fontsize=8.5)
        ax.grid(False)
        ax.set_xlabel(scan.axes[0])
        ax.set_title(f"{hz:g} Hz, one step a frame (dt = {1e3 / hz:.3g} ms)")
    for ax in list(axes.flat)[len(rates):]:
        ax.set_axis_off()
    fig.suptitle(f"Scan {scan.name} ({scan.problem}): max position error at one step a frame", fontsize=12)
    fig.tight_layout(rect=(0, 0, 0.8 if ncols > 1 else 0.74, 0.96))
    cax = fig.add_axes([0.83 if ncols > 1 else 0.77, 0.55, 0.015, 0.35])
    cb = fig.colorbar(mesh, cax=cax)
    cb.set_label(f"log10 max position error [{scan.unit}]")
    handles = [Patch(facecolor="0.72", edgecolor="none")]
    labels = ["grey with x: did not complete\n(diverged, failed)"]
    if limits:
        handles.append(Line2D([], [], color="#e8003a", linewidth=3.0))
        labels.append("oscillator limit (theory,\n/stability): k_s = m (y_max hz)^2")
    if any(not present.all() for _, _, present in grids):
        handles.append(Patch(facecolor="white", edgecolor="0.5"))
        labels.append("white: no run")
    fig.legend(handles, labels, loc="upper left", bbox_to_anchor=(0.81 if ncols > 1 else 0.75, 0.45),
               frameon=False, fontsize=8.5)
    figures._save(fig, path)
    return grids


def best_figure(scan, styles, path):
    """The cheapest run that stays within tol at each point and rate (`best`), coloured by
    method (the report's colour for it) and labelled "method xN"; white where none does.
    One axis: one panel, x the axis, a row per rate. Two axes: a panel per rate."""
    from . import figures
    plt = figures.plt
    from matplotlib.colors import to_rgba
    from matplotlib.patches import Patch
    rates = scan.rates
    fallback = {}
    used = list(dict.fromkeys(m for m in scan.best["method"].tolist() if m))
    colour = {m: _style(styles, m, fallback)["color"] for m in used}
    two = len(scan.axes) == 2
    x_edges = _edges(scan.values[0], scan.log[0])
    if not two:
        n = scan.shape[0]
        width = min(MAX_WIDTH_IN - 2.6, max(6.0, 0.55 * n + 1.5))
        fig, ax = plt.subplots(figsize=(width, 1.1 + 1.25 * len(rates)))
        axes = [ax] * len(rates)
    else:
        ncols = min(2, len(rates))
        nrows = math.ceil(len(rates) / ncols)
        fig, grid = plt.subplots(nrows, ncols, figsize=(min(MAX_WIDTH_IN - 2.6, 5.6 * ncols), 4.8 * nrows),
                                 squeeze=False)
        axes = list(grid.flat)
        for ax in axes[len(rates):]:
            ax.set_axis_off()
    small = 7 if (not two and scan.shape[0] <= 16) or (two and max(scan.shape) <= 8) else 6
    for r, (ax, hz) in enumerate(zip(axes, rates)):
        method, substeps = best_grid(scan, hz)
        colours = [[to_rgba(colour[m], 0.85) if m else None for m in col] for col in method]
        if not two:
            _cells(ax, x_edges, [r - 0.5, r + 0.5], colours)
            for i, m in enumerate(method[:, 0]):
                ax.text(scan.values[0][i], r, choice_text(m, substeps[i, 0]) if m else "none", rotation=90,
                        ha="center", va="center", fontsize=small,
                        color=_text_colour(colour[m]) if m else "0.45")
        else:
            y_edges = _edges(scan.values[1], scan.log[1])
            _cells(ax, x_edges, y_edges, colours)
            if max(scan.shape) <= 14:
                for (i, j), m in np.ndenumerate(method):
                    ax.text(scan.values[0][i], scan.values[1][j],
                            f"x{substeps[i, j]}" if m else "none", ha="center", va="center",
                            fontsize=small, color=_text_colour(colour[m]) if m else "0.45")
            if scan.log[1]:
                ax.set_yscale("log")
            ax.set_ylim(y_edges[0], y_edges[-1])
            ax.set_ylabel(scan.axes[1])
            ax.set_title(f"{hz:g} Hz")
        if scan.log[0]:
            ax.set_xscale("log")
        ax.set_xlim(x_edges[0], x_edges[-1])
        ax.set_xlabel(scan.axes[0])
        ax.grid(False)
    if not two:
        ax = axes[0]
        ax.set_ylim(len(rates) - 0.5, -0.5)
        ax.set_yticks(range(len(rates)))
        ax.set_yticklabels([f"{hz:g} Hz" for hz in rates])
        ax.set_ylabel("frame rate")
    handles = [Patch(facecolor=to_rgba(colour[m], 0.85), edgecolor="none") for m in used]
    labels = list(used)
    handles.append(Patch(facecolor="white", edgecolor="0.5"))
    labels.append(f"none within tol {scan.tol:g} {scan.unit}")
    if two:
        labels[-1] += "\n(in a cell: xN, N substeps a frame)"
    fig.suptitle(f"Scan {scan.name} ({scan.problem}): the cheapest run within {scan.tol:g} {scan.unit} "
                 "(method x substeps a frame)", fontsize=12)
    fig.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.0, 0.9), frameon=False, fontsize=8.5)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    figures._save(fig, path)


def draw(scan, which, study, styles, path):
    """One of the scan's figures (figure_names)."""
    if which == "one_step":
        problem = next((p for p in study.problems if p.name == scan.problem), None)
        one_step_figure(scan, study.stability, spring_mass(scan, problem), path)
    else:
        best_figure(scan, styles, path)


# --- the section --------------------------------------------------------------------------------

def _axis_text(scan):
    parts = []
    for a, v, lg in zip(scan.axes, scan.values, scan.log):
        parts.append(f"{a} from {float(v[0]):.3g} to {float(v[-1]):.3g} ({len(v)} points{', log' if lg else ''})")
    return " by ".join(parts)


def _value(v):
    return "none" if v is None else f"{v:.3g}"


def section(doc, study, figs, scans):
    """The section, after the per-problem and study-wide ones; nothing at all for a study
    without /scan."""
    if not scans:
        return
    doc.h(2, "Parameter scans")
    doc.p("Each scan runs one problem over a grid of its parameters at each frame rate, every fixed-step method "
          "of ours with n substeps a frame, each point against its own truth (the max position error over the run "
          "at the frame ends). The map per method shows one step a frame; the map of the cheapest run shows the "
          "scan's `best` table: the run with the fewest force evaluations a frame that completed within the "
          "scan's tolerance. The range answer (the one method and substeps that hold over the whole range at a "
          "rate) is stepbench's: `stepbench advise --scan FILE --tol X`; the tables here only summarise `best`.")
    for scan in scans:
        _one_scan(doc, study, figs, scan)


def _one_scan(doc, study, figs, scan):
    names = figure_names(scan)
    doc.h(3, f"Scan {scan.name}: {scan.problem} over {', '.join(scan.axes)}")
    fixed = ", ".join(f"{k} = {v:g}" for k, v in scan.fixed.items())
    trusted = int(np.sum(scan.points["trusted"] != 0))
    doc.p(f"{_axis_text(scan)}; at {', '.join(f'{hz:g}' for hz in scan.rates)} Hz with "
          f"{', '.join(str(int(n)) for n in np.atleast_1d(scan.attrs['substeps']))} substeps a frame; tolerance "
          f"{scan.tol:g} {scan.unit}" + (f"; set: {fixed}" if fixed else "") + f". {trusted} of "
          f"{len(scan.points)} points have a trusted truth.")
    if len(scan.axes) == 1:
        _one_step_part(doc, study, figs, scan, names["one_step"])
    else:
        doc.p("A scan of two axes: the maps per method at one step a frame are not drawn (a grid per method and "
              "rate would not be readable); the cheapest-run map below has a panel per frame rate.")
    doc.h(4, f"Scan {scan.name}: the cheapest run within tolerance")
    if names["best"] in figs:
        doc.img(f"fig/{names['best']}", f"the cheapest run within tolerance over the scan {scan.name}")
    rows = []
    for hz in scan.rates:
        parts, none = [], ""
        for choice, where, count in best_summary(scan, hz):
            text = f"{where} ({count} point{'s' if count != 1 else ''})"
            if choice:
                parts.append(f"{choice}: {text}")
            else:
                none = text
        rows.append([f"{hz:g} Hz", "; ".join(parts) or "none", none or "-"])
    doc.table(["frame rate", "cheapest (method x substeps a frame): where", "no run within tolerance"], rows,
              caption=f"The scan's `best` table by rate (tolerance {scan.tol:g} {scan.unit}); the range answer: "
                      f"`stepbench advise --scan FILE --tol {scan.tol:g}`.")


def _one_step_part(doc, study, figs, scan, name):
    axis = scan.axes[0]
    theory = has_theory(scan, study.stability)
    problem = next((p for p in study.problems if p.name == scan.problem), None)
    mass = spring_mass(scan, problem)
    limits = theory_limits(scan, study.stability, mass) if theory else {}
    doc.h(4, f"Scan {scan.name}: one step a frame")
    text = ("Cells: log10 of the max position error of the run at one step a frame (substeps = 1); grey with an x "
            "where the run did not complete (diverged or failed).")
    if theory:
        text += (f" Red bars: each explicit method's oscillator stability limit y_max = omega dt from "
                 f"/stability/limits (theory), at k_s = m (y_max hz)^2 with m = {mass:g} kg; the damped spring "
                 "may still complete a little beyond it: the first grey cell is the bar's cell or the next. An "
                 "arrow at the edge: the limit is beyond the scan.")
    doc.p(text)
    if name in figs:
        doc.img(f"fig/{name}", f"max position error at one step a frame over the scan {scan.name}")
    flags = limit_flags(scan, study.stability) if theory else {}
    head = ["method"]
    if theory:
        head.append("oscillator limit omega dt")
    for hz in scan.rates:
        if theory:
            head.append(f"{hz:g} Hz: {axis} at the limit")
        head.append(f"{hz:g} Hz: first {axis} not completed")
    rows = []
    for m in scan.methods:
        row = [m]
        if theory:
            row.append(f"{limits[m][0]:.4g}" if m in limits else flags.get(m, "none"))
        for hz in scan.rates:
            if theory:
                row.append(f"{limits[m][1][hz]:.3g}" if m in limits else "-")
            row.append(_value(first_unstable(scan, hz, m)))
        rows.append(row)
    doc.table(head, rows, caption=f"Where each method stops completing at one step a frame ({axis}; none: it "
                                  "completed at every point):")
