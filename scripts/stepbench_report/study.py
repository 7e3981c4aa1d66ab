"""Reading a study file (docs/study-format.md) into plain Python objects.

The report works on two shapes of file: a plain sweep (convergence rows without
timings, no peers) and a timed study (time_ns / repetitions / cut in `convergence`,
peer groups with `work_precision`, benchmark root attributes). Everything optional is
read as "absent", never assumed.
"""
from dataclasses import dataclass, field

import h5py
import numpy as np

# The position unit of each problem: the format says SI, "metres, or radians for
# pendulum, whose state is the angle". A `position_unit` attribute, if a writer adds one,
# takes precedence over this table.
POSITION_UNIT = {"pendulum": "rad"}

# Root groups that later issues will add (stability limits, long energy runs, game-loop
# figures). Their layout is not defined yet; these are the optional hooks: when a root
# group of one of these names exists the report shows a generic section for it.
OPTIONAL_SECTIONS = {
    "stability": "Measured stability limits",
    "energy_runs": "Energy drift over time (long runs)",
    "game_loop": "Game-loop figures",
}


class StudyError(Exception):
    """The file is missing, not HDF5, or not a study file."""


def _text(value):
    if isinstance(value, h5py.Empty):  # a null dataspace, e.g. fit_levels of an exact fit
        return np.array([], dtype=int)
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.ndarray) and value.dtype.kind in "SO" and value.shape == ():
        return _text(value[()])
    return value


def _attrs(obj):
    return {k: _text(v) for k, v in obj.attrs.items()}


@dataclass
class Method:
    """An integrator (`convergence`) or a peer (`work_precision`) of one problem."""
    name: str
    peer: bool
    attrs: dict
    rows: np.ndarray  # the structured dataset as read

    @property
    def adaptive(self):
        return self.peer and self.attrs.get("kind") == "adaptive"

    @property
    def param_name(self):
        return "rtol" if self.adaptive else "dt"

    @property
    def param(self):
        return self.col("param" if self.peer else "dt")

    def has(self, name):
        return name in (self.rows.dtype.names or ())

    def col(self, name):
        """A field as float64 (NaN where absent), so missing fields need no special case."""
        if not self.has(name):
            return np.full(len(self.rows), np.nan)
        return np.asarray(self.rows[name], dtype=float)

    @property
    def diverged(self):
        """Integrators record `diverged`; a peer row with a non-finite error failed too."""
        bad = ~np.isfinite(self.col("err_pos_max"))
        if self.has("diverged"):
            bad |= self.col("diverged") != 0
        return bad

    @property
    def timed(self):
        return self.has("time_ns")

    @property
    def cut(self):
        return self.col("cut") == 1 if self.has("cut") else np.zeros(len(self.rows), bool)

    @property
    def expected_order(self):
        return self.attrs.get("expected_order", self.attrs.get("declared_order", float("nan")))


@dataclass
class Problem:
    name: str
    attrs: dict
    unit: str
    integrators: list = field(default_factory=list)
    peers: list = field(default_factory=list)
    references: dict = field(default_factory=dict)  # source -> attrs

    @property
    def methods(self):
        return self.integrators + self.peers


@dataclass
class Study:
    path: str
    attrs: dict
    problems: list
    optional: dict  # hook name -> {"title", "attrs", "datasets"}; see OPTIONAL_SECTIONS
    gaps: list = field(default_factory=list)  # what a complete study would have and this one lacks

    @property
    def timings(self):
        """Timings exist when the root says so or any row carries time_ns."""
        if int(self.attrs.get("timing", 0) or 0) == 1:
            return True
        return any(m.timed for p in self.problems for m in p.methods)

    @property
    def has_peers(self):
        return any(p.peers for p in self.problems)


def _method_sort_key(m):
    order = m.expected_order
    return (m.peer, order if np.isfinite(order) else 99, m.name)


def load(path):
    try:
        f = h5py.File(path, "r")
    except FileNotFoundError:
        raise StudyError(f"cannot read study file '{path}': no such file") from None
    except OSError as e:
        raise StudyError(f"cannot read study file '{path}': {str(e).splitlines()[0]}") from None
    with f:
        if "format_version" not in f.attrs:
            raise StudyError(f"cannot read study file '{path}': not a stepbench study (no format_version)")
        problems, optional = [], {}
        for name, g in f.items():
            if not isinstance(g, h5py.Group):
                continue
            if name in OPTIONAL_SECTIONS:
                optional[name] = {
                    "title": OPTIONAL_SECTIONS[name],
                    "attrs": _attrs(g),
                    "datasets": {k: v.shape for k, v in g.items() if isinstance(v, h5py.Dataset)},
                }
                continue
            attrs = _attrs(g)
            unit = attrs.get("position_unit") or POSITION_UNIT.get(name, "m")
            p = Problem(name=name, attrs=attrs, unit=unit)
            for child_name, child in g.items():
                if child_name == "reference" or not isinstance(child, h5py.Group):
                    continue
                # The format's rule: an integrator group holds `convergence`, a peer group
                # holds `work_precision`.
                if isinstance(child.get("convergence"), h5py.Dataset):
                    p.integrators.append(Method(child_name, False, _attrs(child), child["convergence"][()]))
                elif isinstance(child.get("work_precision"), h5py.Dataset):
                    p.peers.append(Method(child_name, True, _attrs(child), child["work_precision"][()]))
            if isinstance(g.get("reference"), h5py.Group):
                p.references = {k: _attrs(v) for k, v in g["reference"].items() if isinstance(v, h5py.Group)}
            if not p.integrators and not p.peers:
                continue
            p.integrators.sort(key=_method_sort_key)
            p.peers.sort(key=_method_sort_key)
            problems.append(p)
        if not problems:
            raise StudyError(f"cannot read study file '{path}': it holds no problem with integrators")
        return Study(path=str(path), attrs=_attrs(f), problems=problems, optional=optional, gaps=_gaps(problems))


def _gaps(problems):
    """A study written by stepbench has every integrator (and, when timed, every peer) on
    every problem and the references of each; a file with less was cut down or damaged,
    and the report says so rather than ranking what is left as if it were everything."""
    gaps = []
    integrators = set().union(*({m.name for m in p.integrators} for p in problems))
    for p in problems:
        missing = sorted(integrators - {m.name for m in p.integrators})
        if missing:
            gaps.append(f"{p.name}: no convergence data for {', '.join(missing)}")
        if not p.references:
            gaps.append(f"{p.name}: no reference solutions")
    return gaps
