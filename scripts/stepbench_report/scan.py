"""The parameter-scan section of the report: /scan/<name> as stored (docs/study-format.md,
"/scan/<name>"), its figures and two small tables.

Every number is the study file's. The runs, the cheapest run at each point and rate
(`best`) and the range answer were computed by stepbench (study/scan.cpp; `stepbench
advise --scan FILE --tol X` prints the range answer); nothing here ranks or chooses. The
report reads the runs at one step a frame (substeps == 1) for the map of each method (one
axis: a row per method; two axes: a small map per method, a figure per rate), and `best`
as it is for the map of the cheapest method. The one piece of arithmetic is the stiff
spring's theory overlay: the k_s at which omega dt equals each method's oscillator limit
from /stability/limits (`theory`), k_s = mass_kg (limit * hz)^2.

A scan need not hold every point of its grid: a shard file (`scan --shard K/N`) holds its
share, a `merge --partial` holds the points of the shards merged. Point numbers are the
grid's. A point not in the file and a run skipped for the work budget (runs.skipped) are
drawn as such (hatched) and take no part in any statement here: not stable, not unstable,
never the cheapest. A point whose truth is not trusted (points.trusted 0; its references
may not have been run, over the scan's `reference_budget`) is judged on stability alone,
as stepbench judges it: a run there that diverged or failed did not complete (UNSTABLE), a
run that completed is stable (STABLE_NO_TRUTH, hatched: no error to colour it by); its
error, the tolerance and the cheapest run are not judged there.

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

# What a cell of the maps shows (one_step_grid, best_grid). Only OK, UNSTABLE,
# STABLE_NO_TRUTH, CHOSEN and NONE are statements about a run; the others say why there is
# none to make.
OK = 0  # the run completed: coloured by its error
UNSTABLE = 1  # the run diverged or failed (at a point with a trusted truth or without)
SKIPPED = 2  # the run was not taken: its estimated work exceeds the scan's work budget
NO_RUN = 3  # the point was measured, but the scan has no such run
UNTRUSTED = 4  # the point's truth is not trusted (points.trusted 0) and there is no run to judge; in
#                best_grid: no cheapest there (no error, so no tolerance)
MISSING = 5  # the point is not in the file (another shard's, or a shard not merged)
CHOSEN = 6  # best_grid: `best` names a run
NONE = 7  # best_grid: no run taken at the point and rate is within tol
STABLE_NO_TRUTH = 8  # the run completed at a point without a trusted truth: stable, its error not measured
# A stepbench before the scans judged stability without a truth stored such a completed run
# as failed, with this note (core/measure.cpp, measure); it did complete.
OLD_NO_TRUTH_NOTE = "no trusted truth: "
# The start of a point's note when its references were not run (over `reference_budget`).
NO_REFERENCES_NOTE = "references not run"


@dataclass
class Scan:
    name: str
    attrs: dict
    axes: list  # the scanned parameters, in the file's order (the first varies slowest)
    values: list  # per axis, its values along it (1-D), every grid point's, present or not
    points: np.ndarray
    runs: np.ndarray
    best: np.ndarray

    @property
    def grid_points(self):
        return math.prod(self.shape)

    @property
    def shard_index(self):
        return int(self.attrs.get("shard_index", 0))

    @property
    def shard_count(self):
        return int(self.attrs.get("shard_count", 1))

    @property
    def is_shard(self):
        """A shard file opened as it is (`scan --shard K/N`, N > 1), not a merge."""
        return self.shard_count > 1

    @property
    def held(self):
        """Per grid point: the file holds it (a row of `points`)."""
        out = np.zeros(self.grid_points, bool)
        out[self.points["point"]] = True
        return out

    @property
    def trusted(self):
        """Per grid point: held, with a trusted truth."""
        out = np.zeros(self.grid_points, bool)
        out[self.points["point"][self.points["trusted"] != 0]] = True
        return out

    @property
    def missing(self):
        """The number of grid points the file does not hold."""
        return self.grid_points - len(self.points)

    @property
    def untrusted(self):
        return int(np.sum(self.points["trusted"] == 0))

    @property
    def missing_label(self):
        """What a point the file does not hold is, in a legend."""
        return "not in this shard" if self.is_shard else "not run (missing shard)"

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
        return tuple(int(c) for c in np.atleast_1d(self.attrs["axis_count"]))

    @property
    def fixed(self):
        """The parameters set with --set: name -> value."""
        names = [n for n in str(self.attrs["fixed_params"]).split(",") if n]
        values = np.atleast_1d(self.attrs["fixed_values"])
        return {n: float(v) for n, v in zip(names, values)}

    @property
    def methods(self):
        """The methods of the runs, in the file's order; the scan's `methods` attribute
        (the methods run) where it has one, so that a shard with no point still names them."""
        listed = [m for m in str(self.attrs.get("methods", "")).split(",") if m]
        return list(dict.fromkeys(listed + self.runs["method"].tolist()))

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
        npoints = math.prod(counts)
        if "grid_points" in attrs and int(attrs["grid_points"]) != npoints:
            raise reader.error(f"{sg.name}: grid_points {attrs['grid_points']} is not the product of axis_count, "
                               f"{npoints}")
        points = reader.need_table(sg, "points", POINT_FIELDS)
        runs = reader.need_table(sg, "runs", RUN_FIELDS)
        best = reader.need_table(sg, "best", BEST_FIELDS)
        rates = [float(x) for x in np.atleast_1d(attrs["hz"])]
        for table, rows in (("points", points), ("runs", runs), ("best", best)):
            if len(rows) and (rows["point"].min() < 0 or rows["point"].max() >= npoints):
                raise reader.error(f"{sg.name}/{table} names a point beyond the grid's {npoints}")
        if len(np.unique(points["point"])) != len(points):
            raise reader.error(f"{sg.name}/points names a point twice")
        for table, rows in (("runs", runs), ("best", best)):
            if not np.isin(rows["point"], points["point"]).all():
                raise reader.error(f"{sg.name}/{table} names a point that is not in its points table")
        values = _axis_values(reader, f, sg, attrs, axes, counts, points)
        for table, rows in (("runs", runs), ("best", best)):
            reader.need_column(sg, table, rows, "hz", rates)
        reader.need_column(sg, "best", best, "method", [""] + list(dict.fromkeys(runs["method"].tolist())))
        scans.append(Scan(name, attrs, axes, values, points, runs, best))
    return scans


def _axis_values(reader, f, sg, attrs, axes, counts, points):
    """Each axis's values along it, at every grid point, present or not. values/<param>
    holds the parameter at each row of `points` (every grid point, the first axis varying
    slowest, in a whole scan; a shard's or a partial merge's own points otherwise); a value
    no point in the file holds is made as stepbench makes it (study/scan.cpp,
    scan_axis::values: both ends as given, powers of ten between on a log axis, rounded for
    a whole-numbered parameter)."""
    vg = reader.need_group(sg, "values")
    lo, hi = np.atleast_1d(attrs["axis_lo"]), np.atleast_1d(attrs["axis_hi"])
    log = np.atleast_1d(attrs["axis_log"])
    index = np.unravel_index(points["point"], counts)
    whole = _whole_params(reader, f, str(attrs["problem"]))
    values = []
    for k, a in enumerate(axes):
        stored = reader.need_array(vg, a, 1)
        if len(stored) != len(points):
            raise reader.error(f"{vg.name}/{a} has {len(stored)} values, not one for each of the "
                               f"{len(points)} rows of points")
        n = counts[k]
        made = []
        for i in range(n):
            s = 0.0 if n == 1 else i / (n - 1)
            v = (float(lo[k]) if i == 0 else float(hi[k]) if i == n - 1
                 else 10.0 ** (math.log10(lo[k]) + s * (math.log10(hi[k]) - math.log10(lo[k]))) if int(log[k])
                 else float(lo[k]) + s * (float(hi[k]) - float(lo[k])))
            made.append(float(round(v)) if a in whole else v)
        along = np.array(made)
        along[index[k]] = stored  # the file's own, where it has them
        values.append(along)
    return values


def _whole_params(reader, f, problem):
    """The problem's whole-numbered parameters, from /problems/<problem>/parameters where
    the file has it (`allowed` "a whole number ..."); else none."""
    pg = f.get(f"problems/{problem}")
    if pg is None or not hasattr(pg, "keys") or "parameters" not in pg:  # a scan-only file: no problems
        return set()
    rows = reader.need_table(pg, "parameters", ("name", "allowed"))
    return {str(r["name"]) for r in rows if str(r["allowed"]).startswith("a whole number")}


def load(path):
    """The scans of the study at `path` (read after study.load accepted the file), or None.
    Read in a child process bounded as study.load's are (child_read.py): study.load does
    not read /scan, and a damaged /scan can make HDF5 loop or crash as well."""
    from . import child_read
    return child_read.read_in_child(path, lambda: _read_file(path))


def _read_file(path):
    from . import study  # the reader; imported here, as study.py imports the sections
    f = study._open(path)
    try:
        with f:
            return read(study._Reader(path, f), f)
    except study.StudyError:
        raise
    # h5py's errors on a damaged object; MemoryError is the reading child's to name.
    except (OSError, KeyError, ValueError, RuntimeError, TypeError) as e:
        raise study._error(path, f"damaged or truncated HDF5 file: {study._first_line(e)}") from None


# --- what the figures and tables show -------------------------------------------------------------

def one_step_grid(scan, hz, methods=None):
    """The map of one rate at one step a frame: (log10 err_pos_max, state), each methods x
    grid points (the point number; for two axes, reshape a row to scan.shape). state: OK
    (the run completed at a point with a trusted truth; err its error), UNSTABLE (it
    diverged or failed, truth or not), STABLE_NO_TRUTH (it completed at a point without a
    trusted truth: stable, no error to measure), SKIPPED (not taken: over the work budget),
    NO_RUN (no such run at a trusted point), UNTRUSTED (no such run at a point without a
    trusted truth: nothing to judge), MISSING (the file does not hold the point). err is
    NaN but where OK. A run that an older stepbench stored as failed only for the missing
    truth (note OLD_NO_TRUTH_NOTE; it had completed) is STABLE_NO_TRUTH too."""
    methods = scan.methods if methods is None else methods
    n = scan.grid_points
    err = np.full((len(methods), n), np.nan)
    state = np.full((len(methods), n), NO_RUN)
    state[:, ~scan.held] = MISSING
    trusted = scan.trusted
    state[:, scan.held & ~trusted] = UNTRUSTED
    rows = scan.runs[(scan.runs["hz"] == hz) & (scan.runs["substeps"] == 1)]
    done = schema.completed(rows)
    row_of = {m: k for k, m in enumerate(methods)}
    for r, ok in zip(rows, done):
        k = row_of.get(r["method"])
        i = int(r["point"])
        if k is None:
            continue
        if r["skipped"]:
            state[k, i] = SKIPPED
        elif not trusted[i]:
            old = bool(r["failed"]) and not r["diverged"] and str(r["note"]).startswith(OLD_NO_TRUTH_NOTE)
            state[k, i] = STABLE_NO_TRUTH if ok or old else UNSTABLE
        elif not ok:
            state[k, i] = UNSTABLE
        else:
            state[k, i] = OK
            e = float(r["err_pos_max"])
            err[k, i] = math.log10(max(e, 1e-300)) if np.isfinite(e) else np.nan
    return err, state


JUDGED = (OK, UNSTABLE, STABLE_NO_TRUTH)  # the states that say whether the run completed


def boundary(scan, hz, method):
    """Where `method` stops completing at one step a frame (one axis), judged on the points
    that say: (the first axis value whose run diverged or failed, None if none did; the
    number of points before it (or in all, when None) that say nothing: not in the file,
    run skipped or absent; the number of points judged, OK, STABLE_NO_TRUTH or UNSTABLE: a
    point without a trusted truth says whether the run completed, though not its error)."""
    _, state = one_step_grid(scan, hz, [method])
    state = state[0]
    judged = np.isin(state, JUDGED)
    hits = np.flatnonzero(state == UNSTABLE)
    upto = hits[0] if len(hits) else len(state)
    unknown = int(np.sum(~judged[:upto]))
    return (float(scan.values[0][hits[0]]) if len(hits) else None), unknown, int(np.sum(judged))


def first_unstable(scan, hz, method):
    """The first axis value at which `method`'s run at one step a frame diverged or
    failed, among the points judged (None: none did)."""
    return boundary(scan, hz, method)[0]


def boundary_text(scan, hz, method):
    """The table's cell for boundary(): the value; "none" when every point completed; a
    word on the points that say nothing where they could hide the boundary."""
    first, unknown, judged = boundary(scan, hz, method)
    if judged == 0:
        _, state = one_step_grid(scan, hz, [method])
        return "not run (over the work budget)" if (state == SKIPPED).any() else "no point measured"
    if first is None:
        return "none" if unknown == 0 else f"none of the {judged} measured ({unknown} not measured)"
    if unknown == 0:
        return f"{first:.3g}"
    return f"{first:.3g} ({unknown} point{'s' if unknown != 1 else ''} below it not measured)"


def spring_mass(scan, problem=None):
    """The stiff spring's mass in the scan: its fixed value, else the declared default."""
    if SPRING_MASS in scan.fixed:
        return scan.fixed[SPRING_MASS]
    if problem is not None:
        rows = problem.parameters[problem.parameters["name"] == SPRING_MASS]
        if len(rows):
            return float(rows[0]["default"])
    return SPRING_DEFAULT_MASS


def spring_over_ks(scan):
    """A one-axis scan of the stiff spring over k_s: the scan the overlay is drawn on."""
    return scan.problem == SPRING and len(scan.axes) == 1 and scan.axes[0] == SPRING_AXIS


def has_theory(scan, stability):
    """The overlay applies to a one-axis scan of the stiff spring over k_s, in a file whose
    /stability/limits has rows (a scan file's /stability is empty)."""
    return stability is not None and len(stability.limits) > 0 and spring_over_ks(scan)


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
    """`best` at one rate on the grid, each of the grid's shape ((n, 1) for one axis):
    (method, substeps, state, skipped). method "" but where state is CHOSEN; state NONE
    where no run taken meets the tolerance, SKIPPED where no run was taken (each over the
    work budget), UNTRUSTED where the point's truth is not trusted (no error is measured
    there, so no run is within the tolerance and none is the cheapest; whatever `best` says
    there is not shown), MISSING where the file does not hold the point; skipped: the runs
    at the point and rate not taken for the work budget."""
    shape = scan.shape if len(scan.axes) == 2 else (scan.shape[0], 1)
    method = np.full(shape, "", dtype=object)
    substeps = np.zeros(shape, int)
    state = np.full(shape, MISSING)
    skipped = np.zeros(shape, int)
    trusted = scan.trusted
    for p in scan.points["point"]:
        state[scan.index(p)] = NONE if trusted[p] else UNTRUSTED
    taken = np.zeros(shape, int)
    for r in scan.runs[scan.runs["hz"] == hz]:
        if r["skipped"]:
            skipped[scan.index(r["point"])] += 1
        else:
            taken[scan.index(r["point"])] += 1
    state[(state == NONE) & (skipped > 0) & (taken == 0)] = SKIPPED  # no run taken: nothing to judge
    for r in scan.best[scan.best["hz"] == hz]:
        i, j = scan.index(r["point"])
        if r["method"] and trusted[r["point"]]:
            method[i, j] = r["method"]
            substeps[i, j] = int(r["substeps"])
            state[i, j] = CHOSEN
    return method, substeps, state, skipped


def choice_text(method, n):
    return f"{method} x{int(n)}" if method else ""


def _span_text(values, lo, hi):
    a, b = float(values[lo]), float(values[hi])
    return f"{a:.3g}" if lo == hi else f"{a:.3g} .. {b:.3g}"


def best_summary(scan, hz):
    """Per choice (method x substeps) at one rate, in the order it first appears, where
    `best` names it: one axis, its runs of consecutive points; two axes, the span of each
    axis and the count of points, and a note when the span holds points not judged. ""
    is where no run meets the tolerance. Only the points judged: a point not in the file,
    without a trusted truth or with every run skipped is in none. (choice, where, count,
    note) each."""
    method, substeps, state, _ = best_grid(scan, hz)
    order = {}
    for i in range(method.shape[0]):
        for j in range(method.shape[1]):
            if state[i, j] in (CHOSEN, NONE):
                order.setdefault(choice_text(method[i, j], substeps[i, j]), []).append((i, j))
    out = []
    for choice, cells in order.items():
        note = ""
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
            box = state[min(i):max(i) + 1, min(j):max(j) + 1]
            unjudged = int(np.sum((box != CHOSEN) & (box != NONE)))
            if unjudged:  # the span holds points that say nothing: not the choice's
                note = f"{unjudged} in the span not judged"
        out.append((choice, where, len(cells), note))
    return out


def _count(n, what):
    return f"{n} {what[0] if n == 1 else what[1]}"


def unjudged_text(scan, hz):
    """What `best` at one rate does not speak for, in words ("" when nothing): the points
    not in the file, those without a trusted truth, and the points with no run within
    tolerance where some runs were not taken (over the work budget)."""
    _, _, state, skipped = best_grid(scan, hz)
    parts = []
    if (state == MISSING).any():
        parts.append(f"{_count(int(np.sum(state == MISSING)), ('point', 'points'))} {scan.missing_label}")
    if (state == UNTRUSTED).any():
        parts.append(f"{_count(int(np.sum(state == UNTRUSTED)), ('point', 'points'))} without a trusted truth")
    if (state == SKIPPED).any():
        parts.append(f"{_count(int(np.sum(state == SKIPPED)), ('point', 'points'))} with every run over the work "
                     "budget (skipped)")
    none_skipped = int(np.sum((state == NONE) & (skipped > 0)))
    if none_skipped:
        parts.append(f"of the points with none within tolerance, {none_skipped} had runs not taken (over the "
                     "work budget)")
    return "; ".join(parts)


# --- the figures --------------------------------------------------------------------------------

def figure_names(scan):
    """The figure files of a scan, in the order the section shows them: the map per method
    at one step a frame (one axis: one figure, "one_step"; two axes: a figure per rate,
    "one_step_<k>" for the k-th of scan.rates) and the cheapest map ("best")."""
    if len(scan.axes) == 1:
        names = {"one_step": f"scan_{scan.name}_one_step.png"}
    else:
        names = {f"one_step_{k}": f"scan_{scan.name}_one_step_{hz:g}hz.png" for k, hz in enumerate(scan.rates)}
    names["best"] = f"scan_{scan.name}_cheapest.png"
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

# The cells with no error to colour them by, hatched: (face, hatch colour, hatch). All but
# STABLE_NO_TRUTH (the run completed, its error not measured) say nothing about a run.
HATCHED = {SKIPPED: ("white", "#2f6fb0", "\\\\\\\\"), UNTRUSTED: ("#fff2cc", "#b86e00", "...."),
           MISSING: ("0.9", "0.45", "////"), STABLE_NO_TRUTH: ("#e4f2dc", "#3d7f35", "---")}
# Their legend entries in the maps at one step a frame (one_step_figure, maps_figure).
ONE_STEP_LABELS = {STABLE_NO_TRUTH: "completed; no truth here\n(stable, error not measured)",
                   SKIPPED: "skipped: over the work budget\n(not run, not judged)",
                   UNTRUSTED: "no truth and no run here\n(not judged)"}


def _hatched_cell(ax, x0, x1, y0, y1, state):
    """One cell that says nothing about a run (HATCHED), with the white rule between cells."""
    from matplotlib.patches import Rectangle
    face, ink, hatch = HATCHED[state]
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, facecolor=face, edgecolor=ink, hatch=hatch, linewidth=0))
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, edgecolor="white", linewidth=0.6))


def _hatched_legend(scan, shown, handles, labels):
    """The legend entries of the hatched states `shown` in a map at one step a frame."""
    for state in (STABLE_NO_TRUTH, SKIPPED, UNTRUSTED, MISSING):
        if state in shown:
            handles.append(_hatched_handle(state))
            labels.append(ONE_STEP_LABELS.get(state, f"{scan.missing_label}\n(not judged)"))


def _hatched_handle(state):
    from matplotlib.patches import Patch
    face, ink, hatch = HATCHED[state]
    return Patch(facecolor=face, edgecolor=ink, hatch=hatch, linewidth=0)


def held_text(scan):
    """The points the file holds of the grid's, in words: "holds H of its G grid points
    (the whole grid | a partial merge: M missing | shard K of N)"."""
    return f"holds {len(scan.points)} of its {scan.grid_points} grid points ({coverage_kind(scan)})"


def coverage_kind(scan):
    """"shard K of N", "a partial merge: M missing" or "the whole grid"."""
    if scan.is_shard:
        return f"shard {scan.shard_index + 1} of {scan.shard_count}"
    return f"a partial merge: {scan.missing} missing" if scan.missing else "the whole grid"


def coverage_text(scan):
    """The points the file holds, in a few words ("" for a whole scan)."""
    if scan.is_shard:
        return (f"shard {scan.shard_index + 1} of {scan.shard_count}, {len(scan.points)} of {scan.grid_points} "
                "points")
    if scan.missing:
        return f"partial merge, {len(scan.points)} of {scan.grid_points} points"
    return ""


def _error_range(grids):
    """The colour scale of the maps at one step a frame: whole decades around every error
    in `grids` ((err, state) each)."""
    finite = np.concatenate([g[0][np.isfinite(g[0])] for g in grids]) if grids else np.array([])
    vmin, vmax = (math.floor(finite.min()), math.ceil(finite.max())) if len(finite) else (-16, 0)
    return (vmin - 1, vmax) if vmin == vmax else (vmin, vmax)


def one_step_figure(scan, stability, mass, path):
    """A panel per frame rate: x the scan's axis, a row per method, each cell coloured by
    log10 of the max position error of the run at one step a frame, grey with a black x
    where it diverged or failed, hatched where there is no error to colour it by (HATCHED:
    a run that completed at a point without a trusted truth; a point not in the file,
    whole columns; a point without a trusted truth and no run; a run not taken for the
    work budget); for the stiff spring over k_s, a red bar in each method's
    row at the k_s where omega dt is its oscillator limit (theory)."""
    from . import figures  # matplotlib, only when drawing
    plt, Line2D = figures.plt, figures.Line2D
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch
    methods = scan.methods
    rates = scan.rates
    grids = [one_step_grid(scan, hz, methods) for hz in rates]
    vmin, vmax = _error_range(grids)
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
    for ax, hz, (err, state) in zip(axes.flat, rates, grids):
        ax.grid(False)  # before pcolormesh, which no longer removes a grid itself
        mesh = ax.pcolormesh(x_edges, y_edges, np.ma.masked_invalid(np.where(state == OK, err, np.nan)),
                             cmap="viridis", vmin=vmin, vmax=vmax, shading="flat")
        unstable = state == UNSTABLE
        ax.pcolormesh(x_edges, y_edges, np.ma.masked_where(~unstable, np.ones_like(err)), cmap=grey, shading="flat")
        ys, xs = np.nonzero(unstable)
        ax.plot(scan.values[0][xs], ys, linestyle="none", marker="x", color="black", markersize=6,
                markeredgewidth=1.4)
        for i in np.flatnonzero(~scan.held):  # a point not in the file: its whole column
            _hatched_cell(ax, x_edges[i], x_edges[i + 1], y_edges[0], y_edges[-1], MISSING)
        for k, i in zip(*np.nonzero(np.isin(state, (UNTRUSTED, SKIPPED, STABLE_NO_TRUTH)))):
            _hatched_cell(ax, x_edges[i], x_edges[i + 1], y_edges[k], y_edges[k + 1], state[k, i])
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
            figures.log_scale(ax, "x")
        ax.set_xlim(x_edges[0], x_edges[-1])
        ax.set_ylim(len(methods) - 0.5, -0.5)
        ax.set_yticks(range(len(methods)))
        ax.set_yticklabels(methods, fontsize=8.5)
        ax.set_xlabel(scan.axes[0])
        ax.set_title(f"{hz:g} Hz, one step a frame (dt = {1e3 / hz:.3g} ms)")
    for ax in list(axes.flat)[len(rates):]:
        ax.set_axis_off()
    cover = coverage_text(scan)
    fig.suptitle(f"Scan {scan.name} ({scan.problem}): max position error at one step a frame"
                 + (f" ({cover})" if cover else ""), fontsize=12)
    fig.tight_layout(rect=(0, 0, 0.8 if ncols > 1 else 0.74, 0.96))
    cax = fig.add_axes([0.83 if ncols > 1 else 0.77, 0.55, 0.015, 0.35])
    cax.grid(False)
    cb = fig.colorbar(mesh, cax=cax)
    cb.set_label(f"log10 max position error [{scan.unit}]")
    shown = set(np.concatenate([g[1].ravel() for g in grids]).tolist()) if grids else set()
    handles = [Patch(facecolor="0.72", edgecolor="none")]
    labels = ["grey with x: did not complete\n(diverged, failed)"]
    if limits:
        handles.append(Line2D([], [], color="#e8003a", linewidth=3.0))
        labels.append("oscillator limit (theory,\n/stability): k_s = m (y_max hz)^2")
    if NO_RUN in shown:
        handles.append(Patch(facecolor="white", edgecolor="0.5"))
        labels.append("white: no run")
    _hatched_legend(scan, shown, handles, labels)
    fig.legend(handles, labels, loc="upper left", bbox_to_anchor=(0.81 if ncols > 1 else 0.75, 0.45),
               frameon=False, fontsize=8.5)
    figures._save(fig, path)
    return grids


def _tick_text(v):
    """A grid value as a short tick label: 8, 512, 0.25, 1e5, 3.2e4."""
    v = float(v)
    decade = v > 0 and float(f"{v:.0e}") == v and v >= 1e3  # 1e3, not 1000, beside 1e4
    text = f"{v:.4g}" if v == 0 or (1e-3 <= abs(v) < 1e4 and not decade) else f"{v:.2g}"
    return text.replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")


def _value_ticks(axis, values, most=6):
    """Ticks at the grid values (every k-th when there are more than `most`), no minor ones."""
    from matplotlib.ticker import NullLocator
    step = max(1, math.ceil(len(values) / most))
    shown = list(values[::step])
    axis.set_ticks(shown)
    axis.set_ticklabels([_tick_text(v) for v in shown])
    axis.set_minor_locator(NullLocator())


MAP_COLUMNS = 5  # the panels a row of maps_figure, at most
MAP_PANEL_IN = 2.35  # a panel's width and height, inches


def maps_figure(scan, hz, path):
    """A scan of two axes at one rate: a small map per method at one step a frame, x the
    first axis, y the second, each cell coloured by log10 of the run's max position error
    on one colour scale for every rate of the scan (its figures compare), grey with a
    black x where the run diverged or failed, hatched where there is no error to colour it
    by (HATCHED, as in one_step_figure), white where there is no such run. Returns the
    grid drawn, (err, state), each methods x grid points."""
    from . import figures
    plt = figures.plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch
    methods = scan.methods
    grids = [one_step_grid(scan, r, methods) for r in scan.rates]
    vmin, vmax = _error_range(grids)
    err, state = grids[scan.rates.index(hz)]
    ncols = max(1, min(MAP_COLUMNS, len(methods)))
    nrows = max(1, math.ceil(len(methods) / ncols))
    shown = set(state.ravel().tolist())
    entries = sum(1 for x in (UNSTABLE, NO_RUN, STABLE_NO_TRUTH, SKIPPED, UNTRUSTED, MISSING) if x in shown)
    right = 1.3  # the colour bar and its label
    width = ncols * MAP_PANEL_IN + 0.7 + right
    legend_cols = max(1, min(entries, int((width - right) // 2.4)))
    bottom = 0.6 + 0.42 * math.ceil(entries / legend_cols)  # the axis label and the legend
    narrow = ncols < 4  # the title on two lines
    top = 0.75 + (0.25 if narrow else 0)  # the title
    height = nrows * MAP_PANEL_IN + bottom + top
    fig, axes = plt.subplots(nrows, ncols, figsize=(width, height), squeeze=False)
    fig.subplots_adjust(left=0.7 / width, right=1 - right / width, bottom=bottom / height, top=1 - top / height,
                        wspace=0.08, hspace=0.22)
    x_edges, y_edges = _edges(scan.values[0], scan.log[0]), _edges(scan.values[1], scan.log[1])
    xs, ys = np.meshgrid(scan.values[0], scan.values[1], indexing="ij")
    grey = ListedColormap(["0.72"])
    mesh = None
    for k, (ax, m) in enumerate(zip(axes.flat, methods)):
        e, st = err[k].reshape(scan.shape), state[k].reshape(scan.shape)  # [i, j]: first axis i
        ax.grid(False)
        mesh = ax.pcolormesh(x_edges, y_edges, np.ma.masked_invalid(np.where(st == OK, e, np.nan)).T, cmap="viridis",
                             vmin=vmin, vmax=vmax, shading="flat")
        unstable = st == UNSTABLE
        ax.pcolormesh(x_edges, y_edges, np.ma.masked_where(~unstable, np.ones_like(e)).T, cmap=grey, shading="flat")
        ax.plot(xs[unstable], ys[unstable], linestyle="none", marker="x", color="black", markersize=7,
                markeredgewidth=1.5)
        for i, j in zip(*np.nonzero(np.isin(st, tuple(HATCHED)))):
            _hatched_cell(ax, x_edges[i], x_edges[i + 1], y_edges[j], y_edges[j + 1], st[i, j])
        if scan.log[0]:
            figures.log_scale(ax, "x")
        if scan.log[1]:
            figures.log_scale(ax, "y")
        ax.set_xlim(x_edges[0], x_edges[-1])
        ax.set_ylim(y_edges[0], y_edges[-1])
        _value_ticks(ax.xaxis, scan.values[0])
        _value_ticks(ax.yaxis, scan.values[1])
        ax.tick_params(labelsize=8)
        ax.set_title(m, fontsize=9.5, pad=3)
        if k + ncols < len(methods):  # a panel below: its labels say it
            ax.tick_params(labelbottom=False)
        else:
            ax.set_xlabel(scan.axes[0], fontsize=9)
        if k % ncols:
            ax.tick_params(labelleft=False)
        else:
            ax.set_ylabel(scan.axes[1], fontsize=9)
    for ax in list(axes.flat)[len(methods):]:
        ax.set_axis_off()
    cover = coverage_text(scan)
    fig.suptitle(f"Scan {scan.name} ({scan.problem}) at {hz:g} Hz, one step a frame (dt = {1e3 / hz:.3g} ms)"
                 + ("\n" if narrow else ": ") + "max position error per method" + (f" ({cover})" if cover else ""),
                 fontsize=12, y=1 - 0.2 / height, va="top")
    top_edge = 1 - top / height
    cax = fig.add_axes([1 - (right - 0.25) / width, top_edge - 0.55 * (top_edge - bottom / height), 0.16 / width,
                        0.55 * (top_edge - bottom / height)])
    cax.grid(False)
    cb = fig.colorbar(mesh, cax=cax)
    cb.set_label(f"log10 max position error [{scan.unit}]\n(one scale for every rate)", fontsize=9)
    handles, labels = [], []
    if UNSTABLE in shown:
        handles.append(Patch(facecolor="0.72", edgecolor="none"))
        labels.append("grey with x: did not complete\n(diverged, failed)")
    if NO_RUN in shown:
        handles.append(Patch(facecolor="white", edgecolor="0.5"))
        labels.append("white: no run")
    _hatched_legend(scan, shown, handles, labels)
    if handles:
        fig.legend(handles, labels, loc="lower center", bbox_to_anchor=(0.5 * (1 - right / width), 0.0),
                   ncol=legend_cols, frameon=False, fontsize=9)
    figures._save(fig, path)
    return err, state


def best_figure(scan, styles, path):
    """The cheapest run that stays within tol at each point and rate (`best`), coloured by
    method (the report's colour for it) and labelled "method xN"; white where none does;
    hatched where there is nothing to judge (a point not in the file, or whose truth is not
    trusted). One axis: one panel, x the axis, a row per rate. Two axes: a panel per rate."""
    from . import figures
    plt = figures.plt
    from matplotlib.colors import to_rgba
    from matplotlib.patches import Patch
    rates = scan.rates
    fallback = {}
    grids = [best_grid(scan, hz) for hz in rates]
    used = list(dict.fromkeys(m for g in grids for m in g[0].ravel().tolist() if m))
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
    hatched_label = {MISSING: "not run" if not scan.is_shard else "other shard", UNTRUSTED: "no truth",
                     SKIPPED: "skipped"}

    def label(state, m, n, skipped):
        if state == CHOSEN:
            return (choice_text(m, n) if not two else f"x{n}"), _text_colour(colour[m])
        if state == NONE:
            return ("none" if not skipped else "none*"), "0.45"
        return hatched_label[state], "0.3"

    any_none_skipped = False
    for r, (ax, hz, (method, substeps, state, skipped)) in enumerate(zip(axes, rates, grids)):
        colours = [[to_rgba(colour[m], 0.85) if m else None for m in col] for col in method]
        y_edges = [r - 0.5, r + 0.5] if not two else _edges(scan.values[1], scan.log[1])
        _cells(ax, x_edges, y_edges, colours)
        for (i, j), st in np.ndenumerate(state):
            if st in HATCHED:
                _hatched_cell(ax, x_edges[i], x_edges[i + 1], y_edges[j], y_edges[j + 1], st)
        any_none_skipped |= bool(((state == NONE) & (skipped > 0)).any())
        if not two:
            for i in range(state.shape[0]):
                text, ink = label(state[i, 0], method[i, 0], substeps[i, 0], skipped[i, 0])
                ax.text(scan.values[0][i], r, text, rotation=90, ha="center", va="center", fontsize=small, color=ink,
                        bbox=dict(facecolor=HATCHED[state[i, 0]][0], edgecolor="none", pad=0.6)
                        if state[i, 0] in HATCHED else None)
        else:
            if max(scan.shape) <= 14:
                for (i, j), st in np.ndenumerate(state):
                    text, ink = label(st, method[i, j], substeps[i, j], skipped[i, j])
                    ax.text(scan.values[0][i], scan.values[1][j], text, ha="center", va="center", fontsize=small,
                            color=ink, bbox=dict(facecolor=HATCHED[st][0], edgecolor="none", pad=0.6)
                            if st in HATCHED else None)
            if scan.log[1]:
                figures.log_scale(ax, "y")
            ax.set_ylim(y_edges[0], y_edges[-1])
            ax.set_ylabel(scan.axes[1])
            ax.set_title(f"{hz:g} Hz")
        if scan.log[0]:
            figures.log_scale(ax, "x")
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
    if any_none_skipped:
        labels[-1] += "\n(none*: and some runs not taken,\nover the work budget)"
    if two:
        labels[-1] += "\n(in a cell: xN, N substeps a frame)"
    shown = set(np.concatenate([g[2].ravel() for g in grids]).tolist()) if grids else set()
    for state, text in ((SKIPPED, "every run over the work budget\n(skipped, not judged)"),
                        (UNTRUSTED, "no trusted truth: error not\nmeasured, no cheapest here"),
                        (MISSING, f"{scan.missing_label}")):
        if state in shown:
            handles.append(_hatched_handle(state))
            labels.append(text)
    cover = coverage_text(scan)
    fig.suptitle(f"Scan {scan.name} ({scan.problem}): the cheapest run within {scan.tol:g} {scan.unit} "
                 "(method x substeps a frame)" + (f"\n{cover}" if cover else ""), fontsize=12)
    fig.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.0, 0.9), frameon=False, fontsize=8.5)
    fig.tight_layout(rect=(0, 0, 1, 0.93 if not cover else 0.88))
    figures._save(fig, path)


def draw(scan, which, study, styles, path):
    """One of the scan's figures (figure_names)."""
    if which == "one_step":
        problem = next((p for p in study.problems if p.name == scan.problem), None)
        one_step_figure(scan, study.stability, spring_mass(scan, problem), path)
    elif which.startswith("one_step_"):
        maps_figure(scan, scan.rates[int(which[len("one_step_"):])], path)
    else:
        best_figure(scan, styles, path)


# --- the section --------------------------------------------------------------------------------

def _axis_text(scan):
    parts = []
    for a, v, lg in zip(scan.axes, scan.values, scan.log):
        parts.append(f"{a} from {float(v[0]):.3g} to {float(v[-1]):.3g} ({len(v)} points{', log' if lg else ''})")
    return " by ".join(parts)


def method_names(scans):
    """(name, origin) of every method the scans ran, for figures.Styles where the file has
    no problems to name them (a scan file): each is a fixed-step method of ours."""
    return sorted((m, "ours") for m in dict.fromkeys(m for s in scans for m in s.methods))


def summary(scans):
    """summary.json's entry for the scans: what each is and how much of its grid it holds."""
    return [{"name": s.name, "problem": s.problem, "axes": s.axes, "hz": s.rates, "tol": s.tol,
             "grid_points": s.grid_points, "points": len(s.points), "shard_index": s.shard_index,
             "shard_count": s.shard_count} for s in scans]


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


def substep_counts(scan):
    """The substep counts run, from the runs table (a merged file's `substeps` attribute
    may list the default counts before the scan's own: stepbench's read_scan appends to
    them); the attribute, each once, for a scan with no run."""
    counts = scan.runs["substeps"] if len(scan.runs) else np.atleast_1d(scan.attrs["substeps"])
    return sorted(dict.fromkeys(int(n) for n in counts))


def _coverage_paragraph(scan):
    """What the scan does not speak for, said once under its heading ("" for a whole scan
    of trusted points with every run taken)."""
    parts = []
    held, grid, missing = len(scan.points), scan.grid_points, scan.missing
    if scan.is_shard:
        parts.append(f"This file is shard {scan.shard_index + 1} of {scan.shard_count} of the scan (`stepbench scan "
                     f"--shard {scan.shard_index + 1}/{scan.shard_count}`): it holds {held} of the grid's {grid} "
                     f"points. The other {missing} are in the other shards: hatched in the maps as \"not in this "
                     "shard\", and left out of every statement below (not stable, not unstable, never the cheapest); "
                     "`stepbench merge` joins the shards.")
    elif missing:
        parts.append(f"A partial merge (`stepbench merge --partial`): {missing} of the grid's {grid} points are "
                     f"missing (their shards were not merged), and the scan holds {held}. The missing points are "
                     "hatched in the maps as \"not run (missing shard)\" and take no part in any statement below: "
                     "not stable, not unstable, never the cheapest.")
    if scan.untrusted:
        parts.append(_untrusted_text(scan))
    skipped = scan.runs[scan.runs["skipped"] != 0]
    if len(skipped):
        one = int(np.sum(skipped["substeps"] == 1))
        budget = scan.attrs.get("work_budget")
        parts.append(f"{len(skipped)} of the {len(scan.runs)} runs were not taken: their estimated work exceeds the "
                     "scan's work budget" + (f" of {float(budget):.3g}" if budget is not None else "")
                     + " (runs.skipped). A skipped run is not a failure: "
                     + (f"at one step a frame ({one} of them) it is hatched as \"skipped\", and " if one else "")
                     + "`best` chooses among the runs taken.")
    return " ".join(parts)


def _untrusted_text(scan):
    """The points without a trusted truth, in words: how many, why (the first one's note;
    how many for the reference budget), and what is judged there: stability, not the
    error, so neither the tolerance nor the cheapest."""
    bad = scan.points[scan.points["trusted"] == 0]
    first = bad[np.argmin(bad["point"])]
    where = ", ".join(f"{a} = {float(v[i]):.3g}" for a, v, i in
                      zip(scan.axes, scan.values, np.unravel_index(int(first["point"]), scan.shape)))
    note = f" (at {where}: {first['note']})" if str(first["note"]) else ""
    n = len(bad)
    text = (f"{n} of the {len(scan.points)} points {'has' if n == 1 else 'have'} no trusted truth{note}.")
    over = int(sum(str(x).startswith(NO_REFERENCES_NOTE) for x in bad["note"]))
    if over:
        budget = scan.attrs.get("reference_budget")
        text += (f" {'At it' if n == 1 else ('At all of them' if over == n else f'At {over} of them')} the "
                 "references were not run, their predicted work over the scan's reference budget"
                 + (f" of {float(budget):.3g}" if budget is not None else "") + " (`reference_budget`).")
    ran = np.isin(bad["point"], scan.runs["point"])
    if ran.any():
        text += (" Stability is judged there, as stepbench judges it: a run that diverged or failed did not "
                 "complete (grey with an x); one that completed is stable (hatched green, \"completed; no truth "
                 "here\"). The error is not measured there, so neither the tolerance nor the cheapest run is "
                 "judged: `best` names none (stepbench's range answer asks for stability at every point and the "
                 "tolerance at the points with a truth).")
    if not ran.all():
        k = int(np.sum(~ran))
        who = ("It has no run" if n == 1 else "None of them has a run" if k == n
               else f"{k} of them {'has' if k == 1 else 'have'} no run")
        text += f" {who} (hatched as \"no truth and no run here\"): nothing is judged there."
    return text


def _one_scan(doc, study, figs, scan):
    names = figure_names(scan)
    doc.h(3, f"Scan {scan.name}: {scan.problem} over {', '.join(scan.axes)}")
    answer = scan.attrs.get("range_answer")
    if answer is not None:
        doc.p(f"The range answer at the scan's tolerance, as `stepbench advise --scan FILE --tol {scan.tol:g}` "
              "prints it (stepbench computed it when it wrote the scan):")
        doc.pre(_text(answer))
    fixed = ", ".join(f"{k} = {v:g}" for k, v in scan.fixed.items())
    trusted = int(np.sum(scan.points["trusted"] != 0))
    doc.p(f"{_axis_text(scan)}; at {', '.join(f'{hz:g}' for hz in scan.rates)} Hz with "
          f"{', '.join(str(n) for n in substep_counts(scan))} substeps a frame; tolerance "
          f"{scan.tol:g} {scan.unit}" + (f"; set: {fixed}" if fixed else "") + f". {trusted} of "
          f"{len(scan.points)} points have a trusted truth.")
    cover = _coverage_paragraph(scan)
    if cover:
        doc.p(cover)
    if len(scan.axes) == 1:
        _one_step_part(doc, study, figs, scan, names["one_step"])
    else:
        _maps_part(doc, figs, scan, names)
    doc.h(4, f"Scan {scan.name}: the cheapest run within tolerance")
    if names["best"] in figs:
        doc.img(f"fig/{names['best']}", f"the cheapest run within tolerance over the scan {scan.name}")
    rows = []
    unjudged = [unjudged_text(scan, hz) for hz in scan.rates]
    for hz, other in zip(scan.rates, unjudged):
        parts, none = [], ""
        for choice, where, count, note in best_summary(scan, hz):
            text = f"{where} ({count} point{'s' if count != 1 else ''}{'; ' + note if note else ''})"
            if choice:
                parts.append(f"{choice}: {text}")
            else:
                none = text
        rows.append([f"{hz:g} Hz", "; ".join(parts) or "none", none or "-"] + ([other or "-"] if any(unjudged)
                                                                                   else []))
    doc.table(["frame rate", "cheapest (method x substeps a frame): where", "no run within tolerance"]
              + (["not judged"] if any(unjudged) else []), rows,
              caption=f"The scan's `best` table by rate (tolerance {scan.tol:g} {scan.unit}); the range answer: "
                      f"`stepbench advise --scan FILE --tol {scan.tol:g}`.")


def _maps_part(doc, figs, scan, names):
    """A scan of two axes at one step a frame: a figure per rate, a small map per method."""
    grids = [one_step_grid(scan, hz) for hz in scan.rates]
    shown = set(np.concatenate([g[1].ravel() for g in grids]).tolist())
    doc.h(4, f"Scan {scan.name}: one step a frame")
    text = (f"A figure per frame rate, a map per method: x {scan.axes[0]}, y {scan.axes[1]}; each cell the log10 of "
            "the max position error of the run at one step a frame (substeps = 1), on one colour scale for every "
            "rate; grey with an x where the run did not complete (diverged or failed).")
    if STABLE_NO_TRUTH in shown:
        text += (" Hatched green: the run completed where the point has no trusted truth (stable there; its error "
                 "not measured).")
    if shown - {OK, UNSTABLE, STABLE_NO_TRUTH}:
        text += " Other hatching: nothing to judge (the legend says why); white: no such run."
    doc.p(text)
    for k, hz in enumerate(scan.rates):
        name = names[f"one_step_{k}"]
        if name in figs:
            doc.img(f"fig/{name}", f"max position error at one step a frame at {hz:g} Hz, a map per method, over "
                                   f"the scan {scan.name}")


def _one_step_part(doc, study, figs, scan, name):
    axis = scan.axes[0]
    theory = has_theory(scan, study.stability)
    problem = next((p for p in study.problems if p.name == scan.problem), None)
    mass = spring_mass(scan, problem)
    limits = theory_limits(scan, study.stability, mass) if theory else {}
    grids = [one_step_grid(scan, hz) for hz in scan.rates]
    shown = set(np.concatenate([g[1].ravel() for g in grids]).tolist())
    gaps = bool(shown - set(JUDGED))
    doc.h(4, f"Scan {scan.name}: one step a frame")
    text = ("Cells: log10 of the max position error of the run at one step a frame (substeps = 1); grey with an x "
            "where the run did not complete (diverged or failed).")
    if STABLE_NO_TRUTH in shown:
        text += (" Hatched green: the run completed where the point has no trusted truth (stable there; its error "
                 "not measured).")
    if gaps:
        text += " Other hatching: nothing to judge (the legend says why); white: no such run."
    if theory:
        text += (f" Red bars: each explicit method's oscillator stability limit y_max = omega dt from "
                 f"/stability/limits (theory), at k_s = m (y_max hz)^2 with m = {mass:g} kg; the damped spring "
                 "may still complete a little beyond it: the first grey cell is the bar's cell or the next"
                 + (" where both were measured" if gaps else "") + ". An arrow at the edge: the limit is beyond "
                 "the scan.")
    doc.p(text)
    if name in figs:
        doc.img(f"fig/{name}", f"max position error at one step a frame over the scan {scan.name}")
    if spring_over_ks(scan) and not theory:
        doc.note("No stability-limit overlay: it needs /stability/limits, which this file does not hold (a scan "
                 "file never does); the report of a study file with /stability draws it, and `stepbench stability "
                 "--json` prints the limits.")
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
            row.append(boundary_text(scan, hz, m))
        rows.append(row)
    doc.table(head, rows, caption=f"Where each method stops completing at one step a frame ({axis}; none: it "
                                  "completed at every point):" if not gaps else
              f"Where each method stops completing at one step a frame ({axis}; diverged or failed, on the points "
              "measured; none: it completed at each of them):")


def _text(v):
    return v.decode() if isinstance(v, bytes) else str(v)
