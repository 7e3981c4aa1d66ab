"""Reading a study file (docs/study-format.md, format 2) into plain Python objects.

Every method (ours, the peers, the baseline) has one row shape, `methods/<m>/runs`; the
figures derived from the rows (the cheapest method per error target, the Pareto
fronts) are computed in C++ and stored beside them. This module reads them as they are
and checks that everything the report uses is there: a file that lacks a documented
attribute, field or dataset is a StudyError naming the file and what is missing.
Nothing is filled in with a default.
"""
import ctypes
import json
import os
import sys
from dataclasses import dataclass, field

import h5py
import numpy as np
from h5py import h5, h5a, h5d, h5i, h5o, h5p, h5s, h5t

from . import challenge as challenge_section
from . import child_read
from . import energy_runs as energy_section
from . import loop as loop_section
from . import schema
from . import substeps as substeps_section
from . import verdict as verdict_section


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

# Older formats the report still reads, each with the fields of the current schema its
# tables lack (table -> fields). Format 3 is the last without /verdict: its report says
# the verdict is absent and goes on with the rest.
OLDER_FORMATS = {3: {"equal_error": ("cost_lo", "cost_hi", "interpolated")}}

# The closed vocabularies of the format: any other value is an error, not a guess.
ORIGINS = ("ours", "peer", "baseline", "plugin")
FIT_STATUSES = ("fitted", "exact", "insufficient")

# /stability: the stability limits and regions of our integrators, computed in C++ from
# their compiled steps (run/stability.cpp).
STABILITY_ATTRS = ("oscillator", "decay", "adaptive_tolerance", "y_min", "y_max", "y_unconditional", "per_decade",
                   "rho_tol", "clear_factor", "root_rtol", "run_steps", "envelope_growth", "blowup_factor",
                   "decay_floor", "run_y_start", "run_per_decade", "run_rtol", "confirm_y", "agreement", "region_dt",
                   "limits_seconds", "regions_seconds")
LIMIT_FIELDS = schema.fields("stability_limits")
STABILITY_TESTS = ("oscillator", "decay")

# Raised by every reader of a study file; defined beside the child that reads it.
StudyError = child_read.StudyError

# The optional root groups have their own readers: /loop (loop.py), /energy
# (energy_runs.py), /substeps (substeps.py), /challenge (challenge.py).


# One str object for each value: a full study holds some 30000 strings of 450 values,
# and the child that reads it (load) pickles each object once.
_interned = sys.intern


def _text(value):
    """h5py hands strings back as bytes in compound fields and as str in attributes;
    the report sees str."""
    if isinstance(value, h5py.Empty):  # a null dataspace: fit_levels of a fit that used none
        return np.array([], dtype=int)
    if isinstance(value, bytes):
        return value.decode()
    return value


def _decoded(rows, in_place=False):
    """A structured array with its string fields (HDF5 variable-length strings, read as
    bytes objects) turned into str, so that `rows["method"] == "rk4"` works; in place
    when the caller owns `rows`. The strings are interned (_interned)."""
    if rows.dtype.names is None:
        return rows
    out = rows if in_place else rows.copy()
    for name in rows.dtype.names:
        if rows.dtype[name].kind in "OS":
            # A list: np.char.decode costs more than the loop on the few rows a table has.
            out[name] = [_interned(b.decode()) for b in rows[name].astype(bytes).tolist()]
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
    verdict: object = None  # verdict.Verdict: /verdict, the answer the report opens on; None in an older file
    challenge: object = None  # challenge.Challenge: /challenge, the pendulum challenge, Small Steps; None when absent
    # A scan file (`stepbench scan --out`, `stepbench merge`): /scan and no problem. Its
    # report is the scan section alone (report.scan_file_document); problems is empty,
    # verdict and the study-wide sections None, stability only where /stability/limits
    # has rows (a scan file's /stability is empty).
    scan_only: bool = False

    @property
    def timed(self):
        return int(self.attrs["timing"]) == 1


def _path(obj):
    """An object's path for a message: h5py gives None for one HDF5 cannot name (a damaged
    link), and a message must not fail on it."""
    return obj.name if obj.name is not None else "(an object of a damaged file)"


def _method_sort_key(m):
    order = m.declared_order
    return (ORIGINS.index(m.origin), m.adaptive, order if np.isfinite(order) else 99, m.name)


@dataclass(frozen=True)
class _ReadType:
    """How h5py reads a datatype stored in the file: into the numpy `dtype`, through the
    HDF5 memory type `memory` (h5t.py_create of it); `vlen_text`: a variable-length
    string, which h5py hands back as str in an attribute."""
    dtype: np.dtype
    memory: object
    vlen_text: bool


class _Reader:
    """Reads one open file; every lookup of something required goes through `need_*`,
    which raises a StudyError naming the object and what it lacks."""

    def __init__(self, path, f):
        self.path, self.f = path, f
        self.lacks = {}  # table -> fields of the current schema an older format lacks (OLDER_FORMATS)
        self.read_types = {}  # (class, size) -> [(stored type, _ReadType)]: see read_type
        self.transfer = _small_buffer_transfer()

    def error(self, what):
        return _error(self.path, what)

    def need_attrs(self, obj, names):
        location = _attribute_holder(obj)
        missing = [n for n in names if not h5a.exists(location, n.encode())]
        if missing:
            where = "the root group" if obj.name == "/" else _path(obj)
            raise self.error(f"{where} lacks attribute{'s' if len(missing) > 1 else ''} {', '.join(missing)}")
        return self.attributes(obj)

    def attributes(self, obj):
        """Every attribute of `obj` as `{name: _text(obj.attrs[name])}`, in the order of
        `obj.attrs`. Read through h5py's low-level API the way h5py's AttributeManager
        reads each, but with its types made once (read_type): a full study has some
        8000 attributes, and `obj.attrs[name]` spends half its time making them anew."""
        location = _attribute_holder(obj)
        creation = location.get_create_plist()
        tracked = creation.get_attr_creation_order() & h5p.CRT_ORDER_TRACKED
        creation.close()
        names = []
        h5a.iterate(location, names.append, index_type=h5.INDEX_CRT_ORDER if tracked else h5.INDEX_NAME)
        values = {}
        for encoded in names:
            name = _name(encoded)
            attr = h5a.open(location, encoded)
            space = attr.get_space()
            extent = space.get_simple_extent_type()
            read_as = self.read_type(attr.get_type())
            if extent == h5s.NULL:
                value = h5py.Empty(read_as.dtype)
            elif read_as.dtype.subdtype is not None:  # an array datatype, which no study writes: h5py's own way
                value = obj.attrs[name]
            else:
                array = np.zeros(() if extent == h5s.SCALAR else space.shape, read_as.dtype)
                attr.read(array, mtype=read_as.memory)
                if not read_as.vlen_text:
                    value = array[()] if array.ndim == 0 else array
                elif array.ndim == 0:
                    value = _interned(array[()].decode("utf-8", "surrogateescape"))
                else:
                    value = np.array([b.decode("utf-8", "surrogateescape") for b in array.flat],
                                     dtype=read_as.dtype).reshape(array.shape)
            values[name] = _text(value)
        return values

    def read_type(self, stored):
        """The _ReadType of the datatype `stored` (an attribute's or a dataset's). h5py
        makes the numpy dtype and the memory type anew on every read: about 10 us for a
        number, 0.3 ms for a 30-field table row, and a full study has some 8000 attributes
        and 400 tables of a few dozen distinct types. Here each is made once, and found
        again by H5Tequal among the types of its class and size."""
        seen = self.read_types.setdefault((stored.get_class(), stored.get_size()), [])
        for known, read_as in seen:
            if known == stored:
                return read_as
        dtype = stored.dtype
        string = h5t.check_string_dtype(dtype)
        read_as = _ReadType(dtype, h5t.py_create(dtype), string is not None and string.length is None)
        seen.append((stored, read_as))
        return read_as

    def need_group(self, parent, name):
        g = parent.get(name)
        if not isinstance(g, h5py.Group):
            raise self.error(f"{_path(parent).rstrip('/')}/{name} is missing (a group)")
        return g

    def need_table(self, parent, name, fields):
        """The table `parent`/`name` with its strings decoded (_decoded), read as h5py's
        `parent[name][()]` reads it, but with its types made once (read_type) and a small
        conversion buffer (_small_buffer_transfer)."""
        try:
            ds = h5o.open(parent.id, name.encode())
        except KeyError:
            ds = None
        if not isinstance(ds, h5d.DatasetID):
            raise self.error(f"{_path(parent).rstrip('/')}/{name} is missing (a dataset)")
        stored = ds.get_type()
        read_as = self.read_type(stored)
        missing = [n for n in fields if n not in (read_as.dtype.names or ())]
        if missing:
            raise self.error(f"{_name(h5i.get_name(ds))} lacks field{'s' if len(missing) > 1 else ''} "
                             f"{', '.join(missing)}")
        space = ds.get_space()
        if space.get_simple_extent_type() != h5s.SIMPLE:  # a table never is: h5py's own way
            return _decoded(h5py.Dataset(ds)[()])
        rows = np.zeros(space.shape, read_as.dtype)
        if rows.size:
            # HDF5 converts whole rows, and a row takes at most twice its size here in the
            # file (a variable-length string: 16 bytes there, a pointer here).
            row_fits = 2 * max(stored.get_size(), read_as.dtype.itemsize) <= TRANSFER_BUFFER
            ds.read(h5s.ALL, h5s.ALL, rows, read_as.memory, dxpl=self.transfer if row_fits else None)
        return _decoded(rows, in_place=True)

    def need_value(self, obj, key, value, allowed):
        if value not in allowed:
            raise self.error(f"{_path(obj)}: {key} is '{value}', not one of {', '.join(map(str, allowed))}")

    def need_column(self, parent, table, rows, field, allowed):
        """Every value of column `field` of the table `parent`/`table` (read as `rows`) is
        one of `allowed`."""
        for v in dict.fromkeys(rows[field].tolist()):  # each value once, in the order of the rows
            if v not in allowed:
                self.need_value(parent[table], field, v, allowed)  # raises, naming the table

    @staticmethod
    def subgroups(g):
        """(name, group) for each group directly under `g`; datasets and attributes beside
        them are not entries."""
        return [(name, sub) for name, sub in g.items() if isinstance(sub, h5py.Group)]

    def method(self, g, timed, name):
        attrs = self.need_attrs(g, METHOD_ATTRS)
        self.need_value(g, "origin", attrs["origin"], ORIGINS)
        self.need_value(g, "kind", attrs["kind"], tuple(schema.PARAM_KIND))
        self.need_value(g, "param_kind", attrs["param_kind"], (schema.PARAM_KIND[attrs["kind"]],))
        self.need_value(g, "fit_status", attrs["fit_status"], FIT_STATUSES)
        self.need_value(g, "declared_order_holds", int(attrs["declared_order_holds"]), (-1, 0, 1))
        runs = self.need_table(g, "runs", RUN_FIELDS + (TIMED_RUN_FIELDS if timed else ()))
        levels = np.atleast_1d(attrs["fit_levels"])
        if len(levels) and (levels.min() < 0 or levels.max() >= len(runs)):
            raise self.error(f"{_path(g)}: fit_levels {levels.tolist()} name rows beyond its {len(runs)} runs")
        return Method(name, attrs, runs)

    def problem(self, g, timed, name):
        attrs = self.need_attrs(g, PROBLEM_ATTRS)
        methods = [self.method(mg, timed, mname) for mname, mg in self.need_group(g, "methods").items()
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
        equal_error_fields = tuple(n for n in EQUAL_ERROR_FIELDS if n not in self.lacks.get("equal_error", ()))
        p = Problem(name, attrs, methods, references,
                    self.need_table(g, "equal_error", equal_error_fields), fronts,
                    self.need_table(g, "parameters", PARAMETER_FIELDS))
        self.check_derived(g, p)
        return p

    def check_derived(self, g, p):
        """The derived tables name rows of `runs` by (method, param): each must exist, or
        the report would print a figure it cannot trace to a run. An interpolated row of
        `equal_error` lies between two runs and names none."""
        params = {m.name: set(m.param.tolist()) for m in p.methods}
        measured = p.equal_error
        if "interpolated" in (measured.dtype.names or ()):
            measured = measured[measured["interpolated"] == 0]
        tables = [("equal_error", measured)] + [(f"front_{k}", v) for k, v in p.fronts.items()]
        for table, rows in tables:
            for method, param in zip(rows["method"].tolist(), rows["param"].tolist()):
                if param not in params.get(method, ()):
                    raise self.error(f"{_path(g)}/{table} names a run that {_path(g)}/methods lacks "
                                     f"({method} at {param:g})")

    def need_array(self, parent, name, ndim):
        ds = parent.get(name)
        if not isinstance(ds, h5py.Dataset) or ds.dtype.names is not None or ds.ndim != ndim:
            raise self.error(f"{_path(parent).rstrip('/')}/{name} is missing (a {ndim}-D dataset of numbers)")
        return np.asarray(ds[()], dtype=float)

    def stability(self):
        g = self.f.get("stability")
        if g is None:
            return None
        if not isinstance(g, h5py.Group):
            raise self.error("/stability is not a group")
        attrs = self.need_attrs(g, STABILITY_ATTRS)
        limits = self.need_table(g, "limits", LIMIT_FIELDS)
        self.need_column(g, "limits", limits, "test", STABILITY_TESTS)
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

    def has_scan(self):
        """The file holds at least one /scan/<name> group."""
        g = self.f.get("scan")
        return isinstance(g, h5py.Group) and bool(self.subgroups(g))

    def scan_file(self, attrs, share):
        """The Study of a scan file (Study.scan_only): the root attributes, and for share 0
        /stability where its limits table has rows. The scans themselves are read by
        scan.load, as for a study."""
        stability = self.stability() if share == 0 else None
        if stability is not None and not len(stability.limits):
            stability = None
        return Study(path=str(self.path), attrs=attrs, problems=[], stability=stability, scan_only=True)

    def study(self, share=0, shares=1):
        """Share `share` of `shares` of the study (see load): the problems _problem_share
        gives it and, for share 0, the rest of the file; every share checks the root."""
        f = self.f
        if "format_version" not in f.attrs:
            raise self.error("not a stepbench study (an HDF5 file without format_version)")
        version = int(f.attrs["format_version"])
        if version > schema.FORMAT_VERSION:
            raise self.error(f"written by a newer stepbench (format_version {version}; "
                             f"this report reads {schema.FORMAT_VERSION})")
        oldest = min([schema.FORMAT_VERSION] + list(OLDER_FORMATS))
        if version < oldest:
            reads = f"{oldest}" if oldest == schema.FORMAT_VERSION else f"{oldest} to {schema.FORMAT_VERSION}"
            raise self.error(f"format_version {version} is older than this report reads ({reads}); "
                             "run the study again with this stepbench")
        if version < schema.FORMAT_VERSION:
            self.lacks = OLDER_FORMATS[version]
        attrs = self.need_attrs(f, ROOT_ATTRS)
        # A study merged with --partial names the selected problems no shard held.
        missing = f.attrs.get("missing_problems", "")
        attrs["missing_problems"] = [p for p in (missing.decode() if isinstance(missing, bytes) else missing).split(",")
                                     if p]
        # The scene files the study ran (name, path as given, FNV-1a 64 of the bytes; none: []).
        scenes = f.attrs.get("scenes")
        attrs["scenes"] = [] if scenes is None else \
            json.loads(scenes.decode() if isinstance(scenes, bytes) else scenes)
        # The parts the study ran, in its order (a file written before the attribute: None).
        parts = f.attrs.get("parts")
        attrs["parts"] = None if parts is None else \
            [p for p in (parts.decode() if isinstance(parts, bytes) else parts).split(",") if p]
        self.need_value(f, "timing", int(attrs["timing"]), (0, 1))
        targets = np.atleast_1d(attrs["equal_error_targets"])
        absent = [t for t in SUMMARY_TARGETS if not np.isclose(targets, t, rtol=1e-9, atol=0).any()]
        if absent:
            raise self.error(f"equal_error_targets lacks {', '.join(f'{t:g}' for t in absent)} "
                             "(the report's summary targets)")
        timed = int(attrs["timing"]) == 1
        if timed:
            self.need_attrs(f, TIMED_ROOT_ATTRS)
        problems_group = f.get("problems")
        groups = [(name, g) for name, g in problems_group.items() if isinstance(g, h5py.Group)] \
            if isinstance(problems_group, h5py.Group) else []
        if not groups:
            if self.has_scan():
                return self.scan_file(attrs, share)
            self.need_group(f, "problems")
            raise self.error("/problems holds no problem and the file has no /scan (neither a study nor a scan file)")
        problems = [self.problem(g, timed, name) for name, g in groups[_problem_share(share, shares)]]
        if share > 0:
            return Study(path=str(self.path), attrs=attrs, problems=problems)
        return Study(path=str(self.path), attrs=attrs, problems=problems, stability=self.stability(),
                     loop=loop_section.read(self, f), energy_runs=energy_section.read(self, f),
                     substeps=substeps_section.read(self, f), verdict=verdict_section.read(self, f),
                     challenge=challenge_section.read(self, f))


def _problem_share(share, shares):
    """The positions in /problems of the problems share `share` of `shares` reads: they
    are dealt in turn starting with the last share, so that share 0, which reads the rest
    of the file too, has the fewest."""
    return slice(shares - 1 - share, None, shares)


def _merged(shares):
    """The study from its shares (Reader.study): share 0's, with every share's problems in
    the order of /problems, and what it lacks (_gaps)."""
    study = shares[0]
    problems = [None] * sum(len(s.problems) for s in shares)
    for k, share in enumerate(shares):
        problems[_problem_share(k, len(shares))] = share.problems
    study.problems = problems
    study.gaps = _gaps(problems)
    # A study that did not run the part (its `parts` lacks it) is not missing it.
    ran = study.attrs.get("parts")
    if study.stability is None and not study.scan_only and (ran is None or "stability" in ran):
        study.gaps.append("no /stability group (the stability limits and regions)")
    return study


# Child processes reading a study at once (see load), one a core: with two, a full study
# reads in 60 % of the time one child takes.
READERS = min(2, os.cpu_count() or 1)


def load(path):
    """The study at `path`, checked; StudyError (one line, naming the file) otherwise.

    The file is read in child processes bounded in CPU time and memory (child_read.py): a
    damaged file can make HDF5 crash, loop or allocate what a damaged length says, and a
    child that crashed or ran out of its bounds is a damaged file, not a dead or hung report.
    READERS children read at once, each its share of the problems (the bulk of the file;
    Reader.study). Which error a damaged file raises depends on the order it is read in,
    so when a share fails the file is read again by one child, in order, for the error."""
    shares = _read_shares(path, READERS)
    if READERS > 1 and any(isinstance(share, Exception) for share in shares):
        shares = _read_shares(path, 1)
    for share in shares:
        if isinstance(share, Exception):
            raise share
    return _merged(shares)


def _read_shares(path, shares):
    """Each of the `shares` shares of the study at `path` (or the exception reading it
    raised), read by a child process of its own, all at once."""
    children = [child_read.start(path, lambda share=share: _read(path, _open(path), share, shares))
                for share in range(shares)]
    return [child_read.finish(path, *child) for child in children]


def _open(path):
    """The study file `path` opened for reading; StudyError when it cannot be."""
    if not os.path.exists(path):
        raise _error(path, "no such file")
    if os.path.isdir(path):
        raise _error(path, "it is a directory")
    try:
        if not h5py.is_hdf5(path):
            raise _error(path, "not an HDF5 file")
        return h5py.File(path, "r")
    except StudyError:
        raise
    except OSError as e:  # HDF5's signature is there but the file cannot be opened
        raise _error(path, f"damaged or truncated HDF5 file: {_first_line(e)}") from None


def _read(path, f, share, shares):
    """Share `share` of `shares` of the study in the open file `f` (Reader.study), checked."""
    try:
        return _Reader(path, f).study(share, shares)
    except StudyError:
        raise
    # h5py's errors on a damaged object; MemoryError is the reading child's to name (child_read.py).
    except (OSError, KeyError, ValueError, RuntimeError, TypeError) as e:
        raise _error(path, f"damaged or truncated HDF5 file: {_first_line(e)}") from None


_error = child_read.error


TRANSFER_BUFFER = 64 << 10  # bytes


def _small_buffer_transfer():
    """A dataset transfer property list with a TRANSFER_BUFFER-byte type-conversion buffer
    (H5Pset_buffer) instead of HDF5's 1 MiB; None where it cannot be made.

    HDF5 1.10 allocates that buffer, and a background buffer of the same size zeroed by
    calloc, on every read that converts a compound type, which every table with a string
    field needs; freed, the two MiB go back to the kernel, so each of a study's ~400 table
    reads faulted them in and zeroed them afresh: about 0.6 ms a read, 0.2 s a full study.
    h5py does not wrap H5Pset_buffer: it is called through ctypes in the HDF5 library h5py
    loaded (found in /proc/self/maps). Without it the tables read the same, only slower."""
    transfer = h5p.create(h5p.DATASET_XFER)
    try:
        with open("/proc/self/maps") as maps:
            libraries = {line.split()[-1] for line in maps if "/libhdf5" in line and ".so" in line}
    except OSError:
        return None
    for path in sorted(libraries):
        try:
            set_buffer = ctypes.CDLL(path).H5Pset_buffer
        except (OSError, AttributeError):
            continue
        set_buffer.argtypes = (ctypes.c_int64, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p)
        set_buffer.restype = ctypes.c_int
        if set_buffer(transfer.id, TRANSFER_BUFFER, None, None) >= 0:
            return transfer
    return None


def _attribute_holder(obj):
    """The low-level id whose attributes are `obj.attrs` (a file's are its root group's)."""
    return obj["/"].id if isinstance(obj, h5py.File) else obj.id


def _name(encoded):
    """An HDF5 name as h5py gives it: str (_interned) when it is UTF-8, else the bytes."""
    try:
        return _interned(encoded.decode("utf8"))
    except UnicodeDecodeError:
        return encoded


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
