"""The pendulum challenge and Small Steps section of the report: /challenge as stored
(study/challenge.hpp, docs/study-format.md), one figure and two tables.

Mueller's challenge (Ten Minute Physics, 2022): XPBD with 50 substeps a 60 Hz frame on a
3-link pendulum, against our methods in generalized coordinates, each given the most
whole steps a frame whose measured time is at most xpbd's (an adaptive method: the
tightest of the tolerances 1e-1, 1e-2, ... whose time is). Every number is the study
file's: the errors, the times, the interpolated time at xpbd's error and the verdict
lines were computed by stepbench (run/challenge.cpp); the lines are printed verbatim.
The only arithmetic here is a unit: nanoseconds shown in microseconds."""
from dataclasses import dataclass

import numpy as np

from . import schema

ATTRS = ("hz", "xpbd_substeps", "horizon", "energy_horizon", "small_steps_time", "energy_scale", "wall_seconds")


ENTRY_FIELDS = schema.fields("challenge_entries")
VERDICT_FIELDS = schema.fields("challenge_verdicts")
SMALL_STEPS_FIELDS = schema.fields("small_steps")
CRITERIA = ("accuracy", "stability", "speed")  # the challenge's, in the order the section opens on
SMALL_STEPS = "small_steps"  # the criterion of the Small Steps lines, one a problem
DESIGNS = ("xpbd_substeps", "xpbd_iterations", "semi_implicit_euler_substeps", "implicit_euler")
DESIGN_TEXT = {"xpbd_substeps": "XPBD: n substeps of one pass", "xpbd_iterations": "XPBD: one step of n passes",
               "semi_implicit_euler_substeps": "semi-implicit Euler: n substeps",
               "implicit_euler": "implicit Euler: one step"}
FIGURE = "pendulum_challenge.png"


@dataclass
class Challenge:
    attrs: dict
    entries: np.ndarray  # xpbd first, strings decoded
    verdicts: np.ndarray  # (criterion, verdict)
    small_steps: np.ndarray

    @property
    def xpbd(self):
        return self.entries[0]

    @property
    def title(self):
        return f"The pendulum challenge (XPBD, {int(self.attrs['xpbd_substeps'])} substeps) and Small Steps"

    def lines(self, criterion):
        """The verdict lines of `criterion`, exactly as stepbench wrote them, in order."""
        return [str(v) for c, v in zip(self.verdicts["criterion"].tolist(), self.verdicts["verdict"].tolist())
                if c == criterion]

    @property
    def answer(self):
        """The accuracy, stability and speed lines, in that order."""
        return [line for c in CRITERIA for line in self.lines(c)]

    @property
    def problems(self):
        return list(dict.fromkeys(self.small_steps["problem"].tolist()))


def read(reader, f):
    """/challenge, checked through the study reader (its need_* raise StudyError naming
    what is missing); None when the file has none."""
    g = f.get("challenge")
    if g is None:
        return None
    attrs = reader.need_attrs(g, ATTRS)
    entries = reader.need_table(g, "entries", ENTRY_FIELDS)
    if len(entries) == 0 or entries[0]["method"] != "xpbd":
        raise reader.error(f"{g.name}/entries does not start with xpbd's row")
    verdicts = reader.need_table(g, "verdicts", VERDICT_FIELDS)
    reader.need_column(g, "verdicts", verdicts, "criterion", CRITERIA + (SMALL_STEPS,))
    small = reader.need_table(g, "small_steps", SMALL_STEPS_FIELDS)
    reader.need_column(g, "small_steps", small, "design", DESIGNS)
    return Challenge(attrs, entries, verdicts, small)


# --- formatting ----------------------------------------------------------------------------------

def us_text(ns):
    """A time a frame in microseconds, three digits ("5.44")."""
    ns = float(ns)
    return f"{ns / 1e3:.3g}" if np.isfinite(ns) else "n/a"


def _num(v, signed=False):
    v = float(v)
    if not np.isfinite(v):
        return "n/a"
    return f"{v:+.3g}" if signed else f"{v:.3g}"


def adaptive(r):
    """An entry of an adaptive method: its `tolerance` is finite (NaN for a fixed step)."""
    return bool(np.isfinite(float(r["tolerance"])))


def tolerance_text(r):
    """"tol 1e-07", as the accuracy verdict writes a power of ten ("2.5e-07" otherwise)."""
    mantissa, exponent = f"{float(r['tolerance']):.2e}".split("e")
    return f"tol {mantissa.rstrip('0').rstrip('.')}e{exponent}"


def steps_text(r):
    """The entries' "steps a frame": "7", or for an adaptive entry its tolerance and, in
    brackets, its accepted steps a frame (rounded, as stored): "tol 1e-07 (3)"."""
    k = int(r["steps_per_frame"])
    return f"{tolerance_text(r)} ({k})" if adaptive(r) else str(k)


def entry_label(r):
    """An entry's name in the figure: "rk4 x7", "dop853 tol 1e-07"."""
    return f"{r['method']} {tolerance_text(r) if adaptive(r) else 'x%d' % int(r['steps_per_frame'])}"


def entry_head(c):
    a = c.attrs
    return ["method", "steps a frame", "time a frame [us]", f"bobs' max error over {float(a['horizon']):g} s [m]",
            f"energy drift over {float(a['energy_horizon']):g} s [of {float(a['energy_scale']):g} J]",
            "largest energy error", "link error",
            "time a frame at xpbd's error [us]", "stable", "note"]


def entry_rows(c):
    rows = []
    for r in c.entries:
        rows.append([r["method"], steps_text(r), us_text(r["ns_per_frame"]), _num(r["err_pos_max"]),
                     _num(r["energy_drift"], signed=True), _num(r["energy_err_max"]),
                     _num(r["link_err_max"]),
                     us_text(r["ns_per_frame_at_xpbd_error"]), "yes" if r["stable"] else "NO", r["note"]])
    return rows


def counts(c):
    """The n of the Small Steps runs, ascending."""
    return sorted({int(n) for n in c.small_steps["n"]})


def small_steps_rows(c):
    """A row per (problem, design): the error at each n ("diverged" where the run did),
    and the link error, work and time a frame at its largest n."""
    ns = counts(c)
    rows = []
    for p in c.problems:
        for d in DESIGNS:
            sel = c.small_steps[(c.small_steps["problem"] == p) & (c.small_steps["design"] == d)]
            if not len(sel):
                continue
            sel = np.sort(sel, order="n")
            by_n = {int(r["n"]): r for r in sel}
            cells = [p, d]
            for n in ns:
                r = by_n.get(n)
                cells.append("" if r is None else "diverged" if r["diverged"] else _num(r["err_pos"]))
            last = sel[-1]
            cells += [str(int(last["n"])), "diverged" if last["diverged"] else _num(last["link_err"]),
                      f"{float(last['work_per_frame']):.3g}", us_text(last["ns_per_frame"])]
            rows.append(cells)
    return rows


def small_steps_head(c):
    return (["problem", "design"] + [f"n = {n}" for n in counts(c)]
            + ["at n", "link error", "work a frame", "time a frame [us]"])


# --- the figure ----------------------------------------------------------------------------------

def _style(styles, name):
    try:
        return styles(name)
    except (KeyError, TypeError):  # a method the study's problems do not list: still drawn
        return dict(color="grey", marker="o", linestyle="-")


DESIGN_METHOD = {"xpbd_substeps": "xpbd", "xpbd_iterations": "xpbd",
                 "semi_implicit_euler_substeps": "semi_implicit_euler", "implicit_euler": "implicit_euler"}


def _spread(ys, lo, hi, gap):
    """Label heights near `ys` (log axis, limits lo..hi), at least `gap` (a fraction of
    the axis) apart, in the order of ys."""
    span = np.log10(hi) - np.log10(lo)
    order = np.argsort(ys)
    pos = np.log10(np.asarray(ys, float))
    out = pos.copy()
    for k, i in enumerate(order):  # upwards from the lowest
        if k:
            out[i] = max(pos[i], out[order[k - 1]] + gap * span)
    top = np.log10(hi) - gap * span / 2
    for k in range(len(order) - 1, -1, -1):  # then down from the top where they ran over it
        i = order[k]
        limit = top if k == len(order) - 1 else out[order[k + 1]] - gap * span
        out[i] = min(out[i], limit)
    return 10 ** out


def _challenge_panel(ax, c, styles, figures):
    """(a): bobs' max error over the horizon against measured time a frame, one point per
    entry, named in a column at the right (a leader line to each); the speed verdict's
    times (at xpbd's error) hollow on xpbd's error line."""
    xp = c.xpbd
    xerr = float(xp["err_pos_max"])
    xs, points = [], []
    for r in c.entries:
        st = _style(styles, r["method"])
        x, y = float(r["ns_per_frame"]) / 1e3, float(r["err_pos_max"])
        t = float(r["ns_per_frame_at_xpbd_error"]) / 1e3
        if r["method"] != "xpbd" and np.isfinite(t) and t > 0:
            xs.append(t)
            ax.plot([t], [xerr], linestyle="none", marker=st["marker"], color=st["color"], markerfacecolor="white",
                    markersize=8, markeredgewidth=1.4, zorder=4)
        if not (np.isfinite(x) and np.isfinite(y) and y > 0):
            continue
        xs.append(x)
        ax.plot([x], [y], linestyle="none", marker=st["marker"], color=st["color"], markersize=10,
                markeredgecolor="black", markeredgewidth=0.6, zorder=5)
        points.append((x, y, entry_label(r) + ("" if r["stable"] else " (unstable)"), st["color"]))
    figures.log_scale(ax, "x")
    figures.log_scale(ax, "y")
    lo, hi = figures._log_limits([p[1] for p in points] + [xerr], pad=8.0)
    ax.set_ylim(lo, hi)
    if xs:
        right = max(xs)
        ax.set_xlim(min(xs) / 1.8, right * 9.0)  # the names' column on the right
        heights = _spread([p[1] for p in points], lo, hi, 0.075)
        for (x, y, name, colour), h in zip(points, heights):
            ax.annotate(name, (x, y), xytext=(right * 1.7, h), textcoords="data", fontsize=8.5, color=colour,
                        va="center", zorder=6,
                        arrowprops=dict(arrowstyle="-", color=colour, linewidth=0.7, shrinkA=0, shrinkB=5))
    ax.axhline(xerr, color="0.45", linestyle="--", linewidth=0.9, zorder=1)
    ax.axvline(float(xp["ns_per_frame"]) / 1e3, color="0.45", linestyle=":", linewidth=0.9, zorder=1)
    ax.set_xlabel("measured time a frame [us]")
    ax.set_ylabel(f"bobs' max position error over {float(c.attrs['horizon']):g} s [m]")
    ax.set_title(f"(a) the challenge: n_pendulum at {float(c.attrs['hz']):g} Hz")


def _small_steps_panel(ax, c, problem, letter, styles, figures):
    """(b), (c), ... (`letter`), a panel a problem: error at small_steps_time against n for
    each design; diverged runs as x marks in a band at the top; implicit Euler's one step a
    large marker at n = 1 with a dotted line across."""
    rows = c.small_steps[c.small_steps["problem"] == problem]
    ok_err = [float(r["err_pos"]) for r in rows if not r["diverged"] and np.isfinite(r["err_pos"]) and r["err_pos"] > 0]
    lo, hi = figures._log_limits(ok_err)
    diverging = [d for d in DESIGNS if ((rows["design"] == d) & (rows["diverged"] != 0)).any()]
    band = 0.07 * len(diverging)
    if band:
        hi = hi * (hi / lo) ** (band / (1 - band))
    ax.set_xscale("log", base=2)
    figures.log_scale(ax, "y")
    ax.set_ylim(lo, hi)
    ns = counts(c)
    ax.set_xlim(min(ns) / 1.4, max(ns) * 1.4)
    ax.set_xticks(ns)
    ax.set_xticklabels([str(n) for n in ns])
    for d in DESIGNS:
        sel = np.sort(rows[rows["design"] == d], order="n")
        if not len(sel):
            continue
        st = _style(styles, DESIGN_METHOD[d])
        n = np.asarray(sel["n"], float)
        e = np.asarray(sel["err_pos"], float)
        div = np.asarray(sel["diverged"]) != 0
        ok = ~div & np.isfinite(e) & (e > 0)
        if d == "implicit_euler":
            for x, y in zip(n[ok], e[ok]):
                ax.axhline(y, color=st["color"], linestyle=":", linewidth=1.0, zorder=1)
                ax.plot([x], [y], linestyle="none", marker=st["marker"], markersize=12, color=st["color"],
                        markeredgecolor="black", markeredgewidth=0.8, zorder=6)
        else:
            hollow = d == "xpbd_iterations"
            ax.plot(n[ok], e[ok], color=st["color"], marker=st["marker"], linestyle="--" if hollow else "-",
                    markerfacecolor="white" if hollow else st["color"], linewidth=1.4, markersize=6, zorder=3)
        if div.any():
            row = 0.975 - 0.07 * diverging.index(d)
            figures._edge_markers(ax, n[div], row, dict(marker="x", color=st["color"], markeredgewidth=2), size=7)
    if band:
        ax.axhline(lo * (hi / lo) ** (1 - band), color="0.6", linewidth=0.8)
        ax.text(0.99, 1 - band / 2, "diverged", transform=ax.transAxes, va="center", ha="right", fontsize=8,
                color="0.35")
    ax.set_xlabel("n (substeps or passes a frame)")
    ax.set_ylabel(f"position error at t = {float(c.attrs['small_steps_time']):g} s [m]")
    ax.set_title(f"({letter}) Small Steps: {problem}")


def small_steps_letters(c):
    """The letters of the Small Steps panels, one a problem after (a): "b", "c", ..."""
    return [chr(ord("b") + i) for i in range(len(c.problems))]


def _letters_text(letters):
    """"(b)", "(b, c)", "(b-d)": the panels a legend entry or the caption speaks of."""
    if len(letters) <= 2:
        return f"({', '.join(letters)})"
    return f"({letters[0]}-{letters[-1]})"


def figure(c, styles, path):
    """One figure, panels in a row: (a) the challenge's entries, error against measured
    time a frame; (b), (c), ... Small Steps, error against n for each design, a panel per
    problem. The legend below the panels; at most 1380 px wide."""
    from . import figures  # matplotlib, only when drawing
    plt, Line2D = figures.plt, figures.Line2D
    problems = c.problems
    fig, axes = plt.subplots(1, 1 + len(problems), figsize=(4.5 * (1 + len(problems)), 5.3), squeeze=False,
                             gridspec_kw=dict(width_ratios=[1.25] + [1.0] * len(problems)))
    axes = axes[0]
    _challenge_panel(axes[0], c, styles, figures)
    letters = small_steps_letters(c)
    for ax, p, letter in zip(axes[1:], problems, letters):
        _small_steps_panel(ax, c, p, letter, styles, figures)
    small = _letters_text(letters)
    grey = "0.45"
    hs = [Line2D([], [], color=grey, linestyle="--"), Line2D([], [], color=grey, linestyle=":"),
          Line2D([], [], color=grey, marker="o", markerfacecolor="white", linestyle="none")]
    labels = ["(a) dashed: xpbd's error", "(a) dotted: xpbd's time a frame",
              "(a) hollow: time a frame at xpbd's error (interpolated)"]
    present = set(c.small_steps["design"].tolist())
    for d in DESIGNS:
        if d not in present:
            continue
        st = _style(styles, DESIGN_METHOD[d])
        if d == "implicit_euler":
            hs.append(Line2D([], [], color=st["color"], marker=st["marker"], markersize=10, markeredgecolor="black",
                             linestyle=":"))
        else:
            hollow = d == "xpbd_iterations"
            hs.append(Line2D([], [], color=st["color"], marker=st["marker"], linestyle="--" if hollow else "-",
                             markerfacecolor="white" if hollow else st["color"]))
        labels.append(f"{small} {DESIGN_TEXT[d]}")
    if (c.small_steps["diverged"] != 0).any():
        hs.append(Line2D([], [], color="grey", marker="x", linestyle="none", markeredgewidth=2))
        labels.append(f"{small} x in the top band: diverged")
    fig.legend(hs, labels, loc="lower center", ncol=3, frameon=False, fontsize=8.5)
    fig.tight_layout(rect=(0, 0.14, 1, 1))
    figures._save(fig, path)


# --- the section --------------------------------------------------------------------------------

def section(doc, study, figs):
    """Nothing for a study without /challenge."""
    c = getattr(study, "challenge", None)
    if c is None:
        return
    a = c.attrs
    xp = c.xpbd
    doc.h(2, c.title)
    for line in c.answer:
        doc.p(line, cls="answer")
    doc.p(f"Mueller's pendulum challenge (Ten Minute Physics, 2022): XPBD steps a 3-link pendulum (n_pendulum at its "
          f"defaults) at {float(a['hz']):g} Hz with {int(a['xpbd_substeps'])} substeps a frame, and invites anyone to "
          "beat it in simplicity, speed, stability or accuracy. Against it here: our methods in generalized "
          "coordinates, each given the most whole steps a frame whose measured time a frame is at most xpbd's "
          f"({us_text(xp['ns_per_frame'])} us"
          + ("; an adaptive method, the tightest of the tolerances 1e-1, 1e-2, ... that keeps to it"
             if any(adaptive(r) for r in c.entries) else "")
          + "). The lines above are stepbench's own verdicts: accuracy at xpbd's time "
          f"a frame (the bobs' largest position error over {float(a['horizon']):g} s), stability (the energy drift "
          f"over {float(a['energy_horizon']):g} s, of m g l N(N+1)/2 = {float(a['energy_scale']):g} J), speed (the "
          "time a frame each method needs for xpbd's error, interpolated log-log between the two measured step "
          "counts that bracket it).")
    doc.table(entry_head(c), entry_rows(c),
              caption=f"The entries. Times a frame: the median of repeated whole runs over {float(a['horizon']):g} s, "
                      "measured when the study was written (the challenge's own timings, "
                      f"{float(a['wall_seconds']):.1f} s in all); the last time is interpolated, the one the speed "
                      "verdict rests on. Energy drift: (E(end) - E0) / energy scale, signed; link error: the largest "
                      "relative error of a link's length over the frames (0 in generalized coordinates)."
                      + (" Steps a frame of an adaptive method: its tolerance, and in brackets its accepted steps a "
                         "frame (rounded)." if any(adaptive(r) for r in c.entries) else ""))
    if FIGURE in figs:
        doc.img(f"fig/{FIGURE}", "the pendulum challenge: error against time a frame; Small Steps: error against n")
    letters = small_steps_letters(c)
    on = " and ".join(f"({x}) on {p}" for x, p in zip(letters, c.problems))
    doc.p("(a) each entry's error against its measured time a frame (steps a frame beside the name, or an adaptive "
          "method's tolerance); hollow on xpbd's error line: the time a frame at which each would match xpbd's error. "
          f"{_letters_text(letters)} Small Steps (Macklin et al., SCA 2019), {on}: the position error at "
          f"t = {float(a['small_steps_time']):g} s for n substeps of one XPBD constraint pass, one step of n passes, "
          "n semi-implicit Euler substeps and one implicit Euler step (at n = 1, dotted across).", cls="caption")
    doc.h(3, "Small Steps: substeps against iterations")
    for line in c.lines(SMALL_STEPS):
        doc.p(line, cls="answer")
    doc.table(small_steps_head(c), small_steps_rows(c),
              caption=f"Position error [m] at t = {float(a['small_steps_time']):g} s for each n; then, at the "
                      "largest n, the link error (relative), the work a frame (force evaluations or constraint "
                      "passes) and the measured time a frame:")


# --- --markdown: the verdict lines, and Small Steps as one compact table ---------------------------

BRIEF_COUNTS = (1, 4, 16, 64)  # the n the compact Small Steps table shows, of those the study ran


def brief_counts(c):
    """(the n the compact table shows, the n the study ran that it leaves out): BRIEF_COUNTS
    where the study ran them (all its n when it ran none of them), and always the n of a
    design run at one n only (implicit Euler's one step)."""
    ns = counts(c)
    shown = {n for n in ns if n in BRIEF_COUNTS} or set(ns)
    for d in DESIGNS:
        design_ns = {int(n) for n in c.small_steps["n"][c.small_steps["design"] == d]}
        if len(design_ns) == 1:
            shown |= design_ns
    return sorted(shown), [n for n in ns if n not in shown]


def brief_cell(r):
    """One run: "0.0144 m, 6.74 us" (its error and its measured time a frame), "diverged",
    or "" where the design has no run at that n."""
    if r is None:
        return ""
    if r["diverged"]:
        return "diverged"
    err = _num(r["err_pos"])
    return f"{err if err == 'n/a' else err + ' m'}, {us_text(r['ns_per_frame'])} us"


def small_steps_brief(c):
    """The Small Steps table of --markdown: (caption, head, rows), a row per
    problem and n, a column per design, each cell a run's error and time a frame."""
    shown, left_out = brief_counts(c)
    present = set(c.small_steps["design"].tolist())
    designs = [d for d in DESIGNS if d in present]
    head = ["problem", "n"] + [DESIGN_TEXT[d] for d in designs]
    rows = []
    for p in c.problems:
        sel = c.small_steps[c.small_steps["problem"] == p]
        by = {(r["design"], int(r["n"])): r for r in sel}
        for n in shown:
            cells = [brief_cell(by.get((d, n))) for d in designs]
            if any(cells):
                rows.append([p, str(n)] + cells)
    ns = counts(c)
    caption = (f"Small Steps at t = {float(c.attrs['small_steps_time']):g} s: each design's position error [m] and "
               "measured time a frame [us] with n substeps or passes a frame ("
               + ("n = " + ", ".join(map(str, shown)) + f" of the study's {ns[0]} to {ns[-1]}; every n in the report"
                  if left_out else "every n the study ran")
               + "); implicit Euler takes one step a frame, shown at n = 1:")
    return caption, head, rows


def _md_row(cells):
    return "| " + " | ".join(str(x).replace("|", "\\|") for x in cells) + " |"


def answer(doc, c, level=2):
    """--markdown: the challenge's verdict lines and the Small Steps lines, verbatim, and
    the Small Steps table."""
    doc.h(level, "Pendulum challenge")
    doc.items(c.answer)
    doc.p("Small Steps:")
    doc.items(c.lines(SMALL_STEPS))
    caption, head, rows = small_steps_brief(c)
    doc.table(head, rows, caption=caption)
