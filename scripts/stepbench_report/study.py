"""Reading a study file (docs/study-format.md, format 2) into plain Python objects.

Every method (ours, the peers, the baseline) has one row shape, `methods/<m>/runs`; the
figures derived from the rows (the cheapest method per error target, the Pareto
fronts) are computed in C++ and stored beside them. This module reads them as they are
and checks that everything the report uses is there: a file that lacks a documented
attribute, field or dataset is a StudyError naming the file and what is missing.
Nothing is filled in with a default.
"""
import os
import pickle
import signal
from dataclasses import dataclass, field

import h5py
import numpy as np

from . import energy_runs as energy_section
from . import loop as loop_section
from . import schema
from . import substeps as substeps_section


# What docs/study-format.md documents, and the report reads, at each level.
ROOT_ATTRS = ("format_version", "version", "git_commit", "compiler", "build_type", "dependencies", "created_utc",
              "cpu", "cores", "levels", "base_steps", "tolerances", "sample_count", "reference_rtol",
              "reference_atol", "fit_metric", "divergence_factor", "equal_error_targets", "wall_seconds", "timing")
TIMED_ROOT_ATTRS = ("benchmark_mode", "benchmark_min_time_s", "benchmark_repetitions", "benchmark_case_budget_s",
                    "benchmark_wall_seconds", "cpu_scaling_enabled", "num_cpus", "mhz_per_cpu")
PROBLEM_ATTRS = ("horizon", "dim", "position_unit", "description", "has_closed_form", "has_energy", "has_jacobian",
                 "truth_source", "truth_trusted", "truth_note", "agreement_limit", "pos_scale", "vel_scale",
                 "energy_scale", "methods")
REFERENCE_ATTRS = ("status", "reason", "is_truth", "steps", "failed_steps", "rhs_evals", "lin_rhs_evals",
                   "jac_evals", "rhs_evals_counted", "rtol", "atol", "wall_seconds", "compared_with", "err_pos_rel",
                   "err_vel_rel")
METHOD_ATTRS = ("origin", "kind", "param_kind", "declared_order", "description", "library", "symplectic",
                "reuses_last_force", "needs_jacobian", "error_estimate", "dense_output", "fit_status", "fit_metric",
                "fit_param", "fit_slope", "observed_order", "fit_levels", "fit_residual_log10", "fit_note",
                "exact_for_problem", "declared_order_holds")
# Table fields come from the schema the C++ side declares (schema.py).
RUN_FIELDS = schema.fields("runs")
TIMED_RUN_FIELDS = schema.timed_fields("runs")
EQUAL_ERROR_FIELDS = schema.fields("equal_error")
FRONT_FIELDS = schema.fields("front")
# /problems/<p>/parameters: the scene's declared parameters, apart from its derived attributes.
PARAMETER_FIELDS = schema.fields("parameters")

# The targets of the report's summary: the file must have computed `equal_error` for
# each (the "errors of 1e-2, 1e-4 and 1e-6").
SUMMARY_TARGETS = (1e-2, 1e-4, 1e-6)

# The closed vocabularies of the format: any other value is an error, not a guess.
ORIGINS = ("ours", "peer", "baseline")
FIT_STATUSES = ("fitted", "exact", "insufficient")

# /stability: the stability limits and regions of our integrators, computed in C++ from
# their compiled steps (study/stability.cpp).
STABILITY_ATTRS = ("oscillator", "decay", "adaptive_tolerance", "y_min", "y_max", "y_unconditional", "per_decade",
                   "rho_tol", "clear_factor", "root_rtol", "run_steps", "envelope_growth", "blowup_factor",
                   "decay_floor", "run_y_start", "run_per_decade", "run_rtol", "confirm_y", "agreement", "region_dt",
                   "limits_seconds", "regions_seconds")
LIMIT_FIELDS = schema.fields("stability_limits")
STABILITY_TESTS = ("oscillator", "decay")

# The optional root groups have their own readers: /loop (loop.py), /energy
# (energy_runs.py), /substeps (substeps.py).


class StudyError(Exception):
    """The file is missing, not HDF5, damaged, of another format_version, or lacks
    something the format requires. The message is one line and names the file."""


def _text(value):
    """h5py hands strings back as bytes in compound fields and as str in attributes;
    the report sees str."""
    if isinstance(value, h5py.Empty):  # a null dataspace: fit_levels of a fit that used none
        return np.array([], dtype=int)
    if isinstance(value, bytes):
        return value.decode()
    return value


def _decoded(rows):
    """A structured array with its string fields (HDF5 variable-length strings, read as
    bytes objects) turned into str, so that `rows["method"] == "rk4"` works."""
    if rows.dtype.names is None:
        return rows
    out = rows.copy()
    for name in rows.dtype.names:
        if rows.dtype[name].kind in "OS":
            out[name] = np.char.decode(rows[name].astype(bytes))  # in one call, not a Python loop
    return out


@dataclass
class Method:
    """One method on one problem: its attributes and its `runs`, one row per ladder entry."""
    name: str
    attrs: dict
    runs: np.ndarray

    @property
    def origin(self):
        return self.attrs["origin"]

    @property
    def adaptive(self):
        return self.attrs["kind"] == "adaptive"

    @property
    def param(self):
        return self.runs["param"]

    def col(self, name):
        return np.asarray(self.runs[name], dtype=float)

    @property
    def completed(self):
        """Rows that ran to the horizon: not diverged, failed or skipped (their errors mean something)."""
        return schema.completed(self.runs)

    @property
    def diverged(self):
        return self.runs["diverged"] != 0

    @property
    def cut(self):
        """Rows whose timing the time budget skipped (timed study only; False elsewhere)."""
        if "cut" not in self.runs.dtype.names:
            return np.zeros(len(self.runs), bool)
        return self.runs["cut"] != 0

    @property
    def declared_order(self):
        return float(self.attrs["declared_order"])

    @property
    def fit_levels(self):
        return [int(k) for k in np.atleast_1d(self.attrs["fit_levels"])]

    def row_at(self, param):
        """The index of the row run at `param` (a dt or tolerance the file names elsewhere)."""
        hits = np.flatnonzero(self.param == param)
        return int(hits[0]) if len(hits) else None


@dataclass
class Problem:
    name: str
    attrs: dict
    methods: list  # Method, ours first (by declared order), then the peers, then the baseline
    references: dict  # source -> attrs
    equal_error: np.ndarray  # the C++ cheapest-method table, strings decoded
    fronts: dict  # "force_evals" and, in a timed study, "time" -> the C++ Pareto front
    parameters: np.ndarray  # the declared parameters, one row each, strings decoded

    @property
    def unit(self):
        return self.attrs["position_unit"]

    def method(self, name):
        return next(m for m in self.methods if m.name == name)

    def by_origin(self, *origins, adaptive=None):
        return [m for m in self.methods if m.origin in origins and (adaptive is None or m.adaptive == adaptive)]


@dataclass
class Stability:
    """/stability as stored: `limits` one row per (integrator, test), strings decoded;
    `regions` integrator -> |R| on the grid (rows: `im`, columns: `re`)."""
    attrs: dict
    limits: np.ndarray
    re: np.ndarray
    im: np.ndarray
    regions: dict

    def limit(self, integrator, test):
        rows = self.limits[(self.limits["integrator"] == integrator) & (self.limits["test"] == test)]
        return rows[0] if len(rows) else None


@dataclass
class Study:
    path: str
    attrs: dict
    problems: list
    gaps: list = field(default_factory=list)  # what a complete study would have and this one lacks
    stability: Stability = None  # None only in a file that lacks /stability (a gap)
    loop: object = None  # loop.Loop: /loop, the game-loop study; None when the study has none
    energy_runs: object = None  # energy_runs.EnergyRuns: /energy, the long-run energy study; None when absent
    substeps: object = None  # substeps.Substeps: /substeps, small steps or one implicit step; None when absent

    @property
    def timed(self):
        return int(self.attrs["timing"]) == 1


def _method_sort_key(m):
    order = m.declared_order
    return (ORIGINS.index(m.origin), m.adaptive, order if np.isfinite(order) else 99, m.name)


class _Reader:
    """Reads one open file; every lookup of something required goes through `need_*`,
    which raises a StudyError naming the object and what it lacks."""

    def __init__(self, path, f):
        self.path, self.f = path, f

    def error(self, what):
        return StudyError(f"cannot read study file '{self.path}': {what}")

    def need_attrs(self, obj, names):
        missing = [n for n in names if n not in obj.attrs]
        if missing:
            where = "the root group" if obj.name == "/" else obj.name
            raise self.error(f"{where} lacks attribute{'s' if len(missing) > 1 else ''} {', '.join(missing)}")
        return {k: _text(v) for k, v in obj.attrs.items()}

    def need_group(self, parent, name):
        g = parent.get(name)
        if not isinstance(g, h5py.Group):
            raise self.error(f"{parent.name.rstrip('/')}/{name} is missing (a group)")
        return g

    def need_table(self, parent, name, fields):
        ds = parent.get(name)
        if not isinstance(ds, h5py.Dataset):
            raise self.error(f"{parent.name.rstrip('/')}/{name} is missing (a dataset)")
        names = ds.dtype.names or ()
        missing = [n for n in fields if n not in names]
        if missing:
            raise self.error(f"{ds.name} lacks field{'s' if len(missing) > 1 else ''} {', '.join(missing)}")
        return _decoded(ds[()])

    def need_value(self, obj, key, value, allowed):
        if value not in allowed:
            raise self.error(f"{obj.name}: {key} is '{value}', not one of {', '.join(map(str, allowed))}")

    def need_column(self, parent, table, rows, field, allowed):
        """Every value of column `field` of the table `parent`/`table` (read as `rows`) is
        one of `allowed`."""
        for v in dict.fromkeys(rows[field].tolist()):  # each value once, in the order of the rows
            self.need_value(parent[table], field, v, allowed)

    @staticmethod
    def subgroups(g):
        """(name, group) for each group directly under `g`; datasets and attributes beside
        them are not entries."""
        return [(name, sub) for name, sub in g.items() if isinstance(sub, h5py.Group)]

    def method(self, g, timed):
        attrs = self.need_attrs(g, METHOD_ATTRS)
        self.need_value(g, "origin", attrs["origin"], ORIGINS)
        self.need_value(g, "kind", attrs["kind"], tuple(schema.PARAM_KIND))
        self.need_value(g, "param_kind", attrs["param_kind"], (schema.PARAM_KIND[attrs["kind"]],))
        self.need_value(g, "fit_status", attrs["fit_status"], FIT_STATUSES)
        self.need_value(g, "declared_order_holds", int(attrs["declared_order_holds"]), (-1, 0, 1))
        runs = self.need_table(g, "runs", RUN_FIELDS + (TIMED_RUN_FIELDS if timed else ()))
        name = g.name.rsplit("/", 1)[1]
        levels = np.atleast_1d(attrs["fit_levels"])
        if len(levels) and (levels.min() < 0 or levels.max() >= len(runs)):
            raise self.error(f"{g.name}: fit_levels {levels.tolist()} name rows beyond its {len(runs)} runs")
        return Method(name, attrs, runs)

    def problem(self, g, timed):
        attrs = self.need_attrs(g, PROBLEM_ATTRS)
        methods = [self.method(mg, timed) for mg in self.need_group(g, "methods").values()
                   if isinstance(mg, h5py.Group)]
        methods.sort(key=_method_sort_key)
        refs = g.get("reference")
        references = {}
        if isinstance(refs, h5py.Group):  # absent references are a gap (see _gaps), not a fault
            references = {src: self.need_attrs(r, REFERENCE_ATTRS) for src, r in refs.items()
                          if isinstance(r, h5py.Group)}
        fronts = {"force_evals": self.need_table(g, "front_force_evals", FRONT_FIELDS)}
        if timed:
            fronts["time"] = self.need_table(g, "front_time", FRONT_FIELDS)
        p = Problem(g.name.rsplit("/", 1)[1], attrs, methods, references,
                    self.need_table(g, "equal_error", EQUAL_ERROR_FIELDS), fronts,
                    self.need_table(g, "parameters", PARAMETER_FIELDS))
        self.check_derived(g, p)
        return p

    def check_derived(self, g, p):
        """The derived tables name rows of `runs` by (method, param): each must exist, or
        the report would print a figure it cannot trace to a run."""
        params = {m.name: set(m.param.tolist()) for m in p.methods}
        tables = [("equal_error", p.equal_error)] + [(f"front_{k}", v) for k, v in p.fronts.items()]
        for table, rows in tables:
            for method, param in zip(rows["method"].tolist(), rows["param"].tolist()):
                if param not in params.get(method, ()):
                    raise self.error(f"{g.name}/{table} names a run that {g.name}/methods lacks "
                                     f"({method} at {param:g})")

    def need_array(self, parent, name, ndim):
        ds = parent.get(name)
        if not isinstance(ds, h5py.Dataset) or ds.dtype.names is not None or ds.ndim != ndim:
            raise self.error(f"{parent.name.rstrip('/')}/{name} is missing (a {ndim}-D dataset of numbers)")
        return np.asarray(ds[()], dtype=float)

    def stability(self):
        g = self.f.get("stability")
        if g is None:
            return None
        if not isinstance(g, h5py.Group):
            raise self.error("/stability is not a group")
        attrs = self.need_attrs(g, STABILITY_ATTRS)
        limits = self.need_table(g, "limits", LIMIT_FIELDS)
        for t in limits["test"]:
            self.need_value(g["limits"], "test", t, STABILITY_TESTS)
        re, im = self.need_array(g, "region_re", 1), self.need_array(g, "region_im", 1)
        regions_group = self.need_group(g, "regions")
        regions = {}
        for name in dict.fromkeys(limits["integrator"]):
            grid = self.need_array(regions_group, name, 2)
            if grid.shape != (len(im), len(re)):
                raise self.error(f"/stability/regions/{name} has shape {grid.shape}, not (len(region_im), "
                                 f"len(region_re)) = ({len(im)}, {len(re)})")
            regions[name] = grid
        return Stability(attrs, limits, re, im, regions)

    def study(self):
        f = self.f
        if "format_version" not in f.attrs:
            raise self.error("not a stepbench study (an HDF5 file without format_version)")
        version = int(f.attrs["format_version"])
        if version > schema.FORMAT_VERSION:
            raise self.error(f"written by a newer stepbench (format_version {version}; "
                             f"this report reads {schema.FORMAT_VERSION})")
        if version < schema.FORMAT_VERSION:
            raise self.error(f"format_version {version} is older than this report reads ({schema.FORMAT_VERSION}); "
                             "run the study again with this stepbench")
        attrs = self.need_attrs(f, ROOT_ATTRS)
        self.need_value(f, "timing", int(attrs["timing"]), (0, 1))
        targets = np.atleast_1d(attrs["equal_error_targets"])
        absent = [t for t in SUMMARY_TARGETS if not np.isclose(targets, t, rtol=1e-9, atol=0).any()]
        if absent:
            raise self.error(f"equal_error_targets lacks {', '.join(f'{t:g}' for t in absent)} "
                             "(the report's summary targets)")
        timed = int(attrs["timing"]) == 1
        if timed:
            self.need_attrs(f, TIMED_ROOT_ATTRS)
        problems = [self.problem(g, timed) for g in self.need_group(f, "problems").values()
                    if isinstance(g, h5py.Group)]
        if not problems:
            raise self.error("/problems holds no problem")
        stability = self.stability()
        gaps = _gaps(problems)
        if stability is None:
            gaps.append("no /stability group (the stability limits and regions)")
        return Study(path=str(self.path), attrs=attrs, problems=problems, gaps=gaps,
                     stability=stability, loop=loop_section.read(self, f),
                     energy_runs=energy_section.read(self, f), substeps=substeps_section.read(self, f))


def load(path):
    """The study at `path`, checked; StudyError (one line, naming the file) otherwise.

    HDF5 1.10 trusts sizes stored in the file where h5py cannot check them first (a
    global heap object's length, an attribute message's size): a damaged file can crash
    it. So the file is read in a child process, which hands back the study (or the error)
    pickled; a child ended by a signal is a damaged file, not a dead report."""
    readable, writable = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(readable)
        os.dup2(os.open(os.devnull, os.O_WRONLY), 2)  # HDF5's own diagnostics: the error says it
        try:
            result = _load(path)
        except Exception as e:  # noqa: BLE001 -- raised again in the parent
            result = e
        with os.fdopen(writable, "wb") as out:
            pickle.dump(result, out, protocol=pickle.HIGHEST_PROTOCOL)
        os._exit(0)
    os.close(writable)
    with os.fdopen(readable, "rb") as inp:
        data = inp.read()
    status = os.waitpid(pid, 0)[1]
    if os.WIFSIGNALED(status) or not data:
        end = signal.Signals(os.WTERMSIG(status)).name if os.WIFSIGNALED(status) else f"exit {status >> 8}"
        raise StudyError(f"cannot read study file '{path}': damaged: reading it crashes the HDF5 library ({end})")
    result = pickle.loads(data)
    if isinstance(result, Exception):
        raise result
    return result


def _load(path):
    def error(what):
        return StudyError(f"cannot read study file '{path}': {what}")
    if not os.path.exists(path):
        raise error("no such file")
    if os.path.isdir(path):
        raise error("it is a directory")
    try:
        if not h5py.is_hdf5(path):
            raise error("not an HDF5 file")
        f = h5py.File(path, "r")
    except StudyError:
        raise
    except OSError as e:  # HDF5's signature is there but the file cannot be opened
        raise error(f"damaged or truncated HDF5 file: {_first_line(e)}") from None
    try:
        with f:
            return _Reader(path, f).study()
    except StudyError:
        raise
    except (OSError, KeyError, ValueError, RuntimeError, TypeError, MemoryError) as e:  # h5py's on a damaged object
        raise error(f"damaged or truncated HDF5 file: {_first_line(e)}") from None


def _first_line(e):
    return str(e).splitlines()[0] if str(e) else type(e).__name__


def _gaps(problems):
    """A study written by stepbench has, on every problem, each method that applies to it
    (the problem's `methods` attribute lists them) and the references; a file with less
    was cut down or damaged, and the report says so rather than ranking what is left as
    if it were everything. A method that does not apply to a problem (Odeint's on the
    chain, whose state size is not known at compile time) is not a gap."""
    gaps = []
    for p in problems:
        applies = [n for n in str(p.attrs["methods"]).split(",") if n]
        missing = [n for n in applies if n not in {m.name for m in p.methods}]
        if missing:
            gaps.append(f"{p.name}: no runs for {', '.join(missing)} (it applies)")
        if not p.references:
            gaps.append(f"{p.name}: no reference solutions")
    return gaps
