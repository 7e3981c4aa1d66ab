"""The game-loop section of the report: /loop as stored (docs/study-format.md), its
figure (shown error against display rate, one panel per problem and design) and its
tables. Every number is the study file's: the errors, lags and verdicts, the cheapest
design and the cost verdict were computed by stepbench (run/loop.cpp)."""
from dataclasses import dataclass

import numpy as np

from . import schema
from .formatting import fmt_num, fmt_time_ns

LOOP_ATTRS = ("designs", "display_hz", "physics_hz", "reference_display_hz", "clamp_s", "stall_s", "stall_at_fraction",
              "jitter", "jitter_seed", "jitter_distribution", "accumulator_slack", "target", "stated_step_cost_ns",
              "spiral_factor", "settle_frames", "wall_seconds")
LOOP_PROBLEM_ATTRS = ("position_unit", "horizon", "truth_source")
LOOP_METHOD_ATTRS = ("step_cost_ns", "step_cost_source")
LOOP_RUN_FIELDS = schema.fields("loop_runs")
LOOP_CHEAPEST_FIELDS = schema.fields("loop_cheapest")
DESIGNS = ("variable", "fixed", "interpolated", "substeps")
CLOCKS = ("constant", "jitter", "stall")
OUTCOMES = ("keeps_up", "slow_motion", "spiral")
# Physics rates drawn in the figure, each with its own marker.
RATE_MARKERS = ("o", "s", "^", "D", "v", "P")


@dataclass
class LoopMethod:
    name: str
    attrs: dict
    runs: np.ndarray
    cheapest: np.ndarray

    def rows(self, **match):
        """Runs whose fields equal the given values (floats compared exactly: they are
        the values the file was written with)."""
        ok = np.ones(len(self.runs), bool)
        for k, v in match.items():
            ok &= self.runs[k] == v
        return self.runs[ok]


@dataclass
class LoopProblem:
    name: str
    attrs: dict
    methods: list

    @property
    def unit(self):
        return self.attrs["position_unit"]


@dataclass
class Loop:
    attrs: dict
    problems: list

    @property
    def reference_hz(self):
        return float(self.attrs["reference_display_hz"])

    @property
    def display_rates(self):
        return [float(x) for x in np.atleast_1d(self.attrs["display_hz"])]

    @property
    def physics_rates(self):
        return [float(x) for x in np.atleast_1d(self.attrs["physics_hz"])]


def read(reader, f):
    """/loop, checked through the study reader (its need_* raise StudyError naming what
    is missing); None when the file has no loop study."""
    g = f.get("loop")
    if g is None:
        return None
    attrs = reader.need_attrs(g, LOOP_ATTRS)
    problems = []
    for pname, pg in reader.subgroups(g):
        pattrs = reader.need_attrs(pg, LOOP_PROBLEM_ATTRS)
        methods = []
        for mname, mg in reader.subgroups(pg):
            mattrs = reader.need_attrs(mg, LOOP_METHOD_ATTRS)
            runs = reader.need_table(mg, "runs", LOOP_RUN_FIELDS)
            for field, allowed in (("design", DESIGNS), ("clock", CLOCKS), ("outcome", OUTCOMES)):
                reader.need_column(mg, "runs", runs, field, allowed)
            methods.append(LoopMethod(mname, mattrs, runs, reader.need_table(mg, "cheapest", LOOP_CHEAPEST_FIELDS)))
        problems.append(LoopProblem(pname, pattrs, methods))
    return Loop(attrs, problems)


# --- the figure --------------------------------------------------------------------------------

def figure(loop, styles, path):
    """Max shown error against the display rate (constant clocks, clamp on), one row of
    panels per problem and one panel per design; colour the integrator, marker and line
    style the physics rate (the variable design has none: it steps the frame time)."""
    from . import figures  # matplotlib, only when drawing
    plt, Line2D = figures.plt, figures.Line2D
    probs = loop.problems
    rates = loop.physics_rates
    fig, axes = plt.subplots(len(probs), len(DESIGNS), figsize=(15, 3.4 * len(probs) + 1.3), squeeze=False,
                             sharex=True)
    target = float(loop.attrs["target"])
    for row, p in zip(axes, probs):
        values = [v for m in p.methods for v in m.rows(clock="constant")["shown_err_max"] if np.isfinite(v) and v > 0]
        lo, hi = figures._log_limits(values + [target])
        for ax, design in zip(row, DESIGNS):
            for m in p.methods:
                st = styles(m.name)
                for k, rate in enumerate([None] if design == "variable" else rates):
                    r = m.rows(clock="constant", design=design, clamp_s=float(loop.attrs["clamp_s"]))
                    if rate is not None:
                        r = r[r["physics_hz"] == rate]
                    r = np.sort(r, order="display_hz")
                    e = np.asarray(r["shown_err_max"], float)
                    ok = np.isfinite(e) & (e > 0)
                    ax.plot(r["display_hz"][ok], e[ok], color=st["color"], linestyle="-" if rate is None else
                            ("-", "--", ":", "-.")[k % 4], marker=RATE_MARKERS[k % len(RATE_MARKERS)], markersize=5,
                            linewidth=1.1)
            ax.axhline(target, color="grey", linewidth=0.8, linestyle=":")
            figures.log_scale(ax, "y")
            ax.set_ylim(lo, hi)
            ax.set_xticks(loop.display_rates)
            ax.set_xticklabels([f"{x:g}" for x in loop.display_rates], fontsize=8)
            ax.set_title(f"{p.name}: {design}")
            ax.set_xlabel("display rate [Hz]")
        row[0].set_ylabel(f"max shown error [{p.unit}]")
    handles, labels = [], []
    for name in dict.fromkeys(m.name for p in probs for m in p.methods):
        handles.append(Line2D([], [], color=styles(name)["color"], linewidth=2))
        labels.append(name)
    for k, rate in enumerate(rates):
        handles.append(Line2D([], [], color="black", marker=RATE_MARKERS[k % len(RATE_MARKERS)],
                              linestyle=("-", "--", ":", "-.")[k % 4]))
        labels.append(f"physics {rate:g} Hz")
    handles.append(Line2D([], [], color="grey", linestyle=":", linewidth=0.8))
    labels.append(f"target {target:g}")
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 8), frameon=False)
    fig.suptitle("What the player sees: max error of the shown state against the display rate, per loop design",
                 fontsize=12)
    fig.tight_layout(rect=(0, 0.06, 1, 0.96))
    figures._save(fig, path)


# --- the section --------------------------------------------------------------------------------

def _err(v):
    return fmt_num(v) if np.isfinite(v) else "n/a"


def shown_error_rows(loop, p, display_hz):
    """The README's table: at one constant display rate, the max shown error of each
    design per integrator and physics rate (variable: one value, the frame time is its dt)."""
    rows = []
    clamp = float(loop.attrs["clamp_s"])
    for m in p.methods:
        for rate in loop.physics_rates:
            cells = [m.name, f"{rate:g}"]
            for design in DESIGNS:
                r = m.rows(clock="constant", design=design, display_hz=display_hz, clamp_s=clamp)
                if design != "variable":
                    r = r[r["physics_hz"] == rate]
                cells.append(_err(r["shown_err_max"][0]) if len(r) else "")
            rows.append(cells)
    return rows


def cheapest_text(loop, p, m, display_hz):
    c = m.cheapest[m.cheapest["display_hz"] == display_hz]
    if not len(c):
        return None
    c = c[0]
    if not c["found"]:
        return (f"{m.name}: no design stays under {c['target']:g} {p.unit} at these physics rates "
                f"({', '.join(f'{x:g}' for x in loop.physics_rates)} Hz)")
    rate = "" if not np.isfinite(c["physics_hz"]) else f" at {c['physics_hz']:g} Hz physics"
    return (f"{m.name}: {c['design']}{rate} (steps a frame: {c['steps_per_frame_mean']:.3g}; "
            f"max shown error {c['shown_err_max']:.3g} {p.unit})")


def section(doc, study, figs):
    doc.h(2, "Game loop")
    loop = study.loop
    if loop is None:
        doc.note("Game loop: absent (this study file has no /loop group).")
        return
    a = loop.attrs
    ref = loop.reference_hz
    doc.p("A display clock shows frames; the loop around the integrator decides what physics runs between them and "
          "which state is drawn. Compared here, per problem and integrator, is the state each displayed frame shows "
          "with the exact state at that frame's display time (the game clock). Designs: `variable` (one step of the "
          "frame time), `fixed` (the accumulator with a fixed dt, showing the latest state), `interpolated` (the same "
          "loop showing previous x (1 - alpha) + current x alpha, alpha = accumulator / dt; the lecture's snippet "
          "blends a state it never initialised), `substeps` (ceil(physics rate / display rate) steps of the frame "
          f"time a frame). The frame time is clamped at {float(a['clamp_s']):g} s. Clocks: constant at "
          f"{', '.join(f'{x:g}' for x in loop.display_rates)} Hz; jittered around {ref:g} Hz "
          f"(+-{100 * float(a['jitter']):g} %, seed {int(a['jitter_seed'])}: {a['jitter_distribution']}); a "
          f"{float(a['stall_s']):g} s stall at {100 * float(a['stall_at_fraction']):g} % of the run, with the clamp "
          f"and without. The study took {float(a['wall_seconds']):.2f} s.")
    if "loop_shown_error.png" in figs:
        doc.img("fig/loop_shown_error.png", "shown error against display rate per design")
    for p in loop.problems:
        doc.h(3, f"{p.name}: shown error at a {ref:g} Hz display")
        doc.table(["integrator", "physics Hz"] + [f"{d} [{p.unit}]" for d in DESIGNS],
                  shown_error_rows(loop, p, ref),
                  caption=f"Max shown error over the run, constant {ref:g} Hz display (variable has no physics rate: "
                          "its column repeats):")
        lines = [cheapest_text(loop, p, m, ref) for m in p.methods]
        doc.p(f"Cheapest design keeping the shown error at or under {float(a['target']):g} {p.unit} (fewest physics "
              "steps a frame, then the smaller error; ties to fixed, interpolated, substeps, variable in that order): "
              + "; ".join(x for x in lines if x) + ".")
    doc.h(3, "Frame-rate independence, judder and lag")
    doc.p(f"Clock dependence: the largest difference over the constant and jittered clocks between the state at "
          f"the horizon and the same configuration's on the constant {ref:g} Hz clock (position, in the problem's "
          "unit), for the physics state and the shown one (the stall's is in the next table). Judder: the standard deviation of (shown - exact) velocity, both finite "
          "differences of positions over display time. Lag: the time the shown state trails the display time, "
          "measured as the least-squares tau of shown(t) = exact(t - tau), beside the lag the loop's clocks imply. "
          f"Judder and lag at a 144 Hz display (not a multiple of the physics rate), physics at "
          f"{loop.physics_rates[1] if len(loop.physics_rates) > 1 else loop.physics_rates[0]:g} Hz.")
    judder_hz = 144.0 if 144.0 in loop.display_rates else loop.display_rates[-1]
    rate = loop.physics_rates[1] if len(loop.physics_rates) > 1 else loop.physics_rates[0]
    rows = []
    for p in loop.problems:
        for m in p.methods:
            for design in DESIGNS:
                r = m.rows(design=design)
                if design != "variable":
                    r = r[r["physics_hz"] == rate]
                j = r[(r["clock"] == "constant") & (r["display_hz"] == judder_hz)]
                r = r[r["clock"] != "stall"]
                rows.append([p.name, m.name, design, _err(np.nanmax(r["physics_clock_dependence"])),
                             _err(np.nanmax(r["clock_dependence"])),
                             _err(j["judder"][0]) if len(j) else "", _err(j["lag_s"][0]) if len(j) else "",
                             _err(j["lag_clock_s"][0]) if len(j) else ""])
    doc.table(["problem", "integrator", "design", "clock dependence, physics", "clock dependence, shown",
               f"judder at {judder_hz:g} Hz [unit/s]", "lag measured [s]", "lag from the clocks [s]"], rows)
    doc.h(3, "The stall, the clamp and the cost of a step")
    doc.p(f"A {float(a['stall_s']):g} s frame in the middle of the run, physics at {rate:g} Hz, display {ref:g} Hz. "
          "Burst: the steps of the stall frame. Cost model: each step costs the integrator's measured median ns a "
          "step on the problem (timed study) or the stated "
          f"{float(a['stated_step_cost_ns']):g} ns; a frame lasts its display interval or its physics work, "
          "whichever is longer, and the next frame's time is that duration. Load: physics work per second of game "
          "time (a spiral of death needs > 1). Outcome: `keeps_up`, `slow_motion` (late frames held bounded by the "
          f"clamp), `spiral` (a frame grew past {float(a['spiral_factor']):g} x the longest the clock or the clamp "
          "allows).")
    rows = []
    for p in loop.problems:
        for m in p.methods:
            for design in DESIGNS:
                r = m.rows(design=design, clock="stall")
                if design != "variable":
                    r = r[r["physics_hz"] == rate]
                for x in np.sort(r, order="clamp_s")[::-1]:
                    rows.append([p.name, m.name, design, f"{x['clamp_s']:g} s" if x["clamp_s"] > 0 else "off",
                                 str(int(x["stall_burst_steps"])), _err(x["shown_err_max"]),
                                 _err(x["clock_dependence"]),
                                 f"{fmt_num(x['step_cost_ns'])} ns ({m.attrs['step_cost_source']})",
                                 f"{fmt_time_ns(x['worst_frame_work_ns'])} of {fmt_time_ns(x['frame_budget_ns'])}",
                                 fmt_num(x["physics_load"]), x["outcome"],
                                 "yes" if x["clamp_prevented_spiral"] else "no"])
    doc.table(["problem", "integrator", "design", "clamp", "burst steps", "max shown error",
               "clock dependence, shown", "step cost",
               "worst frame's work", "load", "outcome", "clamp prevented a spiral"], rows)
