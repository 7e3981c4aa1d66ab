"""The answer first: /verdict as stored (docs/study-format.md), the tables the report
opens on, each problem's share of them, summary.json, and the Markdown of --markdown
(the README's block is readme.py's, from `stepbench summary`). Every number is the study file's: the equal-error costs, the ratios and
their verdicts, the frame-rate answers and the findings were computed by stepbench
(judge/verdict.cpp). Nothing here interpolates, ranks or selects: rows are looked up
by (problem, target) or (problem, hz) and formatted."""
import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.lib import recfunctions as rfn

from . import schema
from .formatting import fmt_count, fmt_sci, fmt_seconds, fmt_time_ns
from .render import Cell, esc

VERDICT_ATTRS = ("metric", "targets", "frame_hz", "cost_kind", "findings", "rule")
VERDICTS = ("ahead", "behind", "within spread", "bounded", "ours only", "peers only", "not reached")
PLUGIN_VERDICTS = ("ahead", "behind", "within spread", "bounded", "plugin only", "others only", "not reached")
COST_KINDS = ("time_ns", "force_evals")
# Fields of /verdict/equal_error added within format 4: a study written before them reads them as NaN.
EQUAL_ERROR_LATER = ("ours_force_evals", "peer_force_evals", "noise_factor", "evals_ratio", "per_eval_ratio")
# The cell's class in index.html: green ahead, red behind, grey within the timing noise; none
# (white) for "bounded", "ours only", "plugin only"; a plugin's "others only" is red as "peers only" is.
VERDICT_CLASS = {"ahead": "ahead", "behind": "behind", "within spread": "within", "peers only": "behind",
                 "others only": "behind", "not reached": "none"}
# Names shortened in the frame-rate table, whose cells list several methods; the key is printed under it.
SHORT = {"semi_implicit_euler": "sie", "velocity_verlet": "vv", "forest_ruth": "fr", "implicit_euler": "ie",
         "implicit_midpoint": "im"}


@dataclass
class Verdict:
    attrs: dict
    equal_error: np.ndarray  # one row per (problem, target), strings decoded
    frame_rate: np.ndarray  # one row per (problem, hz, method)
    frame_answer: np.ndarray  # one row per (problem, hz, target)
    plugin_equal_error: np.ndarray = None  # one row per (problem, target); None: the study loaded no plugin

    @property
    def targets(self):
        return [float(t) for t in np.atleast_1d(self.attrs["targets"])]

    @property
    def shown_targets(self):
        """The targets of the opening tables, every second decade (1e-2, 1e-4, ...) so
        that they fit a screen; a problem's section has them all."""
        even = [t for t in self.targets if round(math.log10(t)) % 2 == 0]
        return even if len(even) >= 2 else self.targets

    @property
    def tight_targets(self):
        """The targets of the table against the peers: 1e-6 and finer, where the high-order
        methods compete, every second decade."""
        return [t for t in self.shown_targets if t <= 1e-6 * (1 + 1e-9)]

    @property
    def frame_hz(self):
        return [float(h) for h in np.atleast_1d(self.attrs["frame_hz"])]

    @property
    def cost_kind(self):
        return self.attrs["cost_kind"]

    @property
    def findings(self):
        return [line.strip() for line in str(self.attrs["findings"]).split("\n") if line.strip()]

    @property
    def problems(self):
        """The problems in the order of the equal-error table."""
        return list(dict.fromkeys(self.equal_error["problem"].tolist()))

    def only(self, problem):
        """The verdict of one problem."""
        pe = self.plugin_equal_error
        return replace(self, equal_error=self.equal_error[self.equal_error["problem"] == problem],
                       plugin_equal_error=None if pe is None else pe[pe["problem"] == problem],
                       frame_rate=self.frame_rate[self.frame_rate["problem"] == problem],
                       frame_answer=self.frame_answer[self.frame_answer["problem"] == problem])

    def equal(self, problem, target):
        rows = self.equal_error[(self.equal_error["problem"] == problem)
                                & np.isclose(self.equal_error["target"], target, rtol=1e-9, atol=0)]
        return rows[0] if len(rows) else None

    def plugin(self, problem, target):
        pe = self.plugin_equal_error
        if pe is None:
            return None
        rows = pe[(pe["problem"] == problem) & np.isclose(pe["target"], target, rtol=1e-9, atol=0)]
        return rows[0] if len(rows) else None

    def answer(self, problem, hz, target):
        fa = self.frame_answer
        rows = fa[(fa["problem"] == problem) & (fa["hz"] == hz) & np.isclose(fa["target"], target, rtol=1e-9, atol=0)]
        return rows[0] if len(rows) else None

    def rates(self, problem, hz):
        fr = self.frame_rate
        return fr[(fr["problem"] == problem) & (fr["hz"] == hz)]

    def unit(self, problem):
        rows = self.equal_error[self.equal_error["problem"] == problem]
        return rows[0]["unit"] if len(rows) else ""


def read(reader, f):
    """/verdict, checked through the study reader; None when the file has none (a study
    written before format 4)."""
    g = f.get("verdict")
    if g is None:
        return None
    attrs = reader.need_attrs(g, VERDICT_ATTRS)
    reader.need_value(g, "cost_kind", attrs["cost_kind"], COST_KINDS)
    ee = reader.need_table(g, "equal_error",
                           [n for n in schema.fields("verdict_equal_error") if n not in EQUAL_ERROR_LATER])
    absent = [n for n in EQUAL_ERROR_LATER if n not in ee.dtype.names]
    if absent:
        ee = rfn.append_fields(ee, absent, [np.full(len(ee), np.nan) for _ in absent], usemask=False)
    reader.need_column(g, "equal_error", ee, "verdict", VERDICTS)
    pe = None
    if "plugin_equal_error" in g:  # only in a study that loaded plugins
        pe = reader.need_table(g, "plugin_equal_error", schema.fields("verdict_plugin_equal_error"))
        for column in ("verdict_ours", "verdict_peer"):
            reader.need_column(g, "plugin_equal_error", pe, column, PLUGIN_VERDICTS)
    return Verdict(attrs, ee, reader.need_table(g, "frame_rate", schema.fields("verdict_frame_rate")),
                   reader.need_table(g, "frame_answer", schema.fields("verdict_frame_answer")), pe)


# --- text ----------------------------------------------------------------------------------------

def target_text(t):
    return fmt_sci(t, 1) if math.isclose(10 ** round(math.log10(t)), t, rel_tol=1e-9) else fmt_sci(t)


def targets_span(targets):
    """A run of targets as a heading says it: "1e-6" or "1e-6 to 1e-12"."""
    first, last = target_text(targets[0]), target_text(targets[-1])
    return first if len(targets) == 1 else f"{first} to {last}"


def param_text(kind, value):
    """An interpolated dt (a fixed-step method) or relative tolerance (an adaptive one)."""
    return f"tol {fmt_sci(value)}" if kind == "adaptive" else f"dt {fmt_seconds(value)}"


def cost_text(kind, value):
    if kind == "time_ns":
        return fmt_time_ns(value)
    count = fmt_count(value)
    return f"{count} eval{'' if count == '1' else 's'}"


def ratio_text(ratio):
    return f"{ratio:.2g}x" if abs(ratio) < 100 else f"{ratio:.0f}x"


def _spread(kind, r, side):
    """A side's cost with its repetition spread, where it has one."""
    cost, lo, hi = (float(r[f"{side}_cost{s}"]) for s in ("", "_lo", "_hi"))
    text = cost_text(kind, cost)
    if np.isfinite(lo) and np.isfinite(hi) and (lo != cost or hi != cost):
        text += f" ({cost_text(kind, lo)} to {cost_text(kind, hi)})"
    return text


def equal_error_cell(r, kind):
    """One (problem, target) of the opening table: our fastest method, its dt or
    tolerance and cost; under it the ratio to the fastest peer."""
    verdict = r["verdict"]
    cls = VERDICT_CLASS.get(verdict, "")
    ours, peer = r["ours_method"], r["peer_method"]
    if ours:
        param, cost = param_text(r["ours_kind"], r["ours_param"]), cost_text(kind, r["ours_cost"])
        md = f"{ours} {param}, {cost}"
        html = f"<b>{esc(ours)}</b> {esc(param)} &middot; {esc(cost)}"
        if peer:
            md += f" ({ratio_text(r['ratio'])} {peer})"
            html += f'<br><span class="small">{esc(ratio_text(r["ratio"]))} {esc(peer)}</span>'
        else:
            md += " (no peer reaches it)"
            html += '<br><span class="small">no peer reaches it</span>'
        return Cell(md, html, cls)
    if peer:
        param, cost = param_text(r["peer_kind"], r["peer_param"]), cost_text(kind, r["peer_cost"])
        return Cell(f"none of ours; peer {peer} {param}, {cost}",
                    f'<span class="small">none of ours</span><br>{esc(peer)} {esc(param)} &middot; {esc(cost)}', cls)
    return Cell("not reached", "&ndash;", cls)


def noise_text(r):
    """What a ratio is judged against: the timing noise factor b (ahead or behind only outside
    1/b to b), or "evaluations" for a target ranked by counted force evaluations (exact)."""
    if r["cost_kind"] != "time_ns":
        return "evaluations"
    return f"noise {r['noise_factor']:.3g}x" if np.isfinite(r["noise_factor"]) else ""


def factors_text(r):
    """The ratio's two measured factors: force evaluations at equal error, time an evaluation."""
    parts = []
    if np.isfinite(r["evals_ratio"]):
        parts.append(f"evaluations {ratio_text(r['evals_ratio'])}")
    if np.isfinite(r["per_eval_ratio"]):
        parts.append(f"time an evaluation {ratio_text(r['per_eval_ratio'])}")
    return ", ".join(parts)


def peer_cell(r):
    """One (problem, tight target) of the table against the peers: ours / peer, the verdict and
    the noise it was judged against; the two methods; the ratio's two factors."""
    if r is None:
        return Cell("-", "&ndash;", "none")
    verdict = r["verdict"]
    cls = VERDICT_CLASS.get(verdict, "")
    if not (r["ours_method"] and r["peer_method"]):
        return Cell(verdict, f'<span class="small">{esc(verdict)}</span>', cls)
    noise = noise_text(r)
    head = f"{ratio_text(r['ratio'])} {verdict}" + (f" ({noise})" if noise else "")
    pair = f"{r['ours_method']} / {r['peer_method']}"
    why = factors_text(r)
    return Cell(f"{head}: {pair}" + (f"; {why}" if why else ""),
                f"<b>{esc(head)}</b><br>{esc(pair)}" + (f'<br><span class="small">{esc(why)}</span>' if why else ""),
                cls)


def plugin_cell(r, kind):
    """One (problem, target) of the plugins' table: their fastest method, its dt or tolerance
    and cost; under it its cost as a multiple of the fastest of ours's and the fastest peer's."""
    if r is None or not r["plugin_method"]:
        return Cell("not reached", "&ndash;", "none")
    method = r["plugin_method"]
    param, cost = param_text(r["plugin_kind"], r["plugin_param"]), cost_text(kind, r["plugin_cost"])
    ratios = [f"{ratio_text(r[f'vs_{side}'])} {side}" for side in ("ours", "peer") if np.isfinite(r[f"vs_{side}"])]
    return Cell(f"{method} {param}, {cost}" + (f" ({', '.join(ratios)})" if ratios else ""),
                f"<b>{esc(method)}</b> {esc(param)} &middot; {esc(cost)}"
                + (f'<br><span class="small">{" &middot; ".join(esc(x) for x in ratios)}</span>' if ratios else ""),
                VERDICT_CLASS.get(r["verdict_ours"], ""))


def problem_cell(verdict, problem):
    best = verdict.equal(problem, verdict.targets[0])
    best_error = float(best["best_error"]) if best is not None else float("nan")
    unit = verdict.unit(problem)
    return Cell(f"{problem} [{unit}]", f'<a href="{esc(page_of(problem))}">{esc(problem)}</a> [{esc(unit)}]'
                f'<br><span class="small">best {esc(fmt_sci(best_error))}</span>')


def short(name):
    return SHORT.get(name, name)


def stable_text(rates, shorten=True):
    """Which of our fixed-step methods are stable at one step a frame, briefly: all, none,
    or the shorter of the two lists."""
    name = short if shorten else (lambda n: n)
    stable = [name(m) for m, s in zip(rates["method"].tolist(), rates["stable"]) if s]
    unstable = [name(m) for m, s in zip(rates["method"].tolist(), rates["stable"]) if not s]
    if not len(rates):
        return "no runs"
    if not unstable:
        return f"all {len(stable)} stable"
    if not stable:
        return "none stable"
    if len(unstable) <= len(stable):
        return "unstable: " + ", ".join(unstable)
    return "stable: only " + ", ".join(stable)


def frame_answers(verdict, problem, hz):
    """`(target, row)` for each shown target up to the first that no method meets
    (monotone: a tighter target is not met either)."""
    out = []
    for t in verdict.shown_targets:
        row = verdict.answer(problem, hz, t)
        if row is None:
            continue
        out.append((t, row))
        if not row["method"]:
            break
    return out


def frame_cell(verdict, problem, hz):
    rates = verdict.rates(problem, hz)
    parts = []
    for t, row in frame_answers(verdict, problem, hz):
        if row["method"]:
            parts.append(f"{target_text(t)} {short(row['method'])} x{int(row['substeps'])}")
        else:
            parts.append(f"{target_text(t)} none in 64")
    md = stable_text(rates) + "; " + ", ".join(parts)
    html = esc(stable_text(rates)) + '<br><span class="small">' + " &middot; ".join(esc(p) for p in parts) + "</span>"
    return Cell(md, html)


def used_short_names(verdict):
    names = set(verdict.frame_rate["method"].tolist()) | set(verdict.frame_answer["method"].tolist())
    return [(s, n) for n, s in SHORT.items() if n in names]


def frame_cost_text(kind, row):
    cost = cost_text(kind, float(row["cost_per_frame"]))
    share = 100 * float(row["frame_share"])
    if not np.isfinite(share):
        return cost
    return cost + (" (< 0.01 %)" if share < 0.01 else f" ({share:.2g} %)")


# --- the opening of the report -------------------------------------------------------------------

# The game programmer's question as the index asks it by default (scripts/report --hz, --tol):
# a frame at 60 Hz, within 1 cm, 1 mm and 0.1 mm (the README's, `stepbench summary`'s).
FRAME_HZ = 60.0
FRAME_TARGETS = (1e-2, 1e-3, 1e-4)
# A target in plain words, for the problems in metres (the angles' in rad read the same way: 1 mrad).
METRES = {-2: "1 cm", -3: "1 mm", -4: "0.1 mm", -5: "10 um", -6: "1 um"}


class ChoiceError(ValueError):
    """A --hz or --tol the study's verdict does not hold; its text names what it holds."""


def held(wanted, have, what, flag, text):
    """The values of `have` (the study's rates or targets) equal to each of `wanted`, in the
    order asked; ChoiceError naming what the study has when one is not there. `text`: a
    value as the message writes it."""
    out = []
    for w in wanted:
        match = next((h for h in have if math.isclose(h, w, rel_tol=1e-9)), None)
        if match is None:
            raise ChoiceError(f"{flag} {text(w)}: the study holds per-frame answers at the {what} "
                              f"{', '.join(text(h) for h in have)} only")
        out.append(match)
    return out


def frame_choice(verdict, hz=None, targets=None):
    """(rate, targets) the index answers: those asked (ChoiceError when the study lacks one),
    else 60 Hz and 1e-2, 1e-3, 1e-4 where the study has them (else its first rate, and its
    first three targets)."""
    rate = held([hz], verdict.frame_hz, "rates", "--hz", lambda h: f"{h:g}")[0] if hz is not None else next(
        (h for h in verdict.frame_hz if math.isclose(h, FRAME_HZ)), verdict.frame_hz[0])
    if targets:
        return rate, held(targets, verdict.targets, "targets", "--tol", target_text)
    default = [t for t in verdict.targets if any(math.isclose(t, d, rel_tol=1e-9) for d in FRAME_TARGETS)]
    return rate, default or verdict.targets[:3]


def target_words(t):
    """1e-3 as a reader says it: "1 mm"; the plain number where no short word fits."""
    return METRES.get(round(math.log10(t)), target_text(t)) if math.isclose(
        10 ** round(math.log10(t)), t, rel_tol=1e-9) else target_text(t)


def answer_cell(kind, row):
    """One (problem, rate, target) of the per-frame answer: method x substeps, its cost a
    frame; under it the error it keeps (the study's `frame_answer` row, as stored)."""
    if row is None:
        return Cell("-", "&ndash;", "none")
    if not row["method"]:
        return Cell("none within 64 substeps", '<span class="small">none within 64 substeps</span>', "none")
    method, n = row["method"], int(row["substeps"])
    cost = cost_text(kind, float(row["cost_per_frame"]))
    error = fmt_sci(float(row["err_pos_max"]))
    return Cell(f"{method} x{n}, {cost} a frame (error {error})",
                f"<b>{esc(method)}</b> x{n} &middot; {esc(cost)}"
                f'<br><span class="small">error {esc(error)}</span>')


def page_of(problem):
    """A problem's page in the report's folder."""
    return f"problems/{problem}.html"


def scene_cell(problem, unit, scene):
    """The problem's name, linked to its page, and its scene as the study ran it."""
    return Cell(f"{problem} [{unit}]", f'<a href="{esc(page_of(problem))}">{esc(problem)}</a> [{esc(unit)}]'
                f'<br><span class="small">{esc(scene)}</span>')


def frame_answer(doc, verdict, hz, targets, scenes):
    """The index's first table: per problem, at `hz`, the cheapest of our methods and substeps a
    frame within each of `targets`, and its cost a frame. `scenes`: {problem: its parameters as
    run}."""
    kind = verdict.cost_kind
    words = ", ".join(f"{target_text(t)} ({target_words(t)})" for t in targets)
    doc.h(2, f"At {hz:g} Hz: which method, how many substeps, what a frame costs")
    doc.p(f"At {hz:g} frames a second, within {words} of the truth: the cheapest of our fixed-step methods, "
          "how many substeps a frame it takes (x n) and what a frame costs "
          + ("(the benchmark's median time a step on the scene, times the steps of a frame)" if kind == "time_ns"
             else "(force evaluations: this study is untimed)")
          + "; under it, the error it keeps: the worst body's largest position error over the run, in the "
          "problem's unit (rad for the angles: 1e-3 is 1 mrad).", cls="lead")
    head = ["problem [unit], scene as run"] + [f"{target_text(t)} ({target_words(t)})" for t in targets] \
        + ["stable at one step a frame"]
    rows = [[scene_cell(p, verdict.unit(p), scenes.get(p, ""))]
            + [answer_cell(kind, verdict.answer(p, hz, t)) for t in targets]
            + [stable_text(verdict.rates(p, hz), shorten=False)] for p in verdict.problems]
    doc.table(head, rows, cls="answer")


def opening(doc, verdict):
    """The equal-error table, the frame-rate table and the findings (the index has the
    per-frame answer, frame_answer, above them)."""
    kind = verdict.cost_kind
    by = "measured time" if kind == "time_ns" else "counted force evaluations"
    doc.h(2, "Fastest at equal error")
    shown = verdict.shown_targets
    head = ["problem [unit]"] + [target_text(t) for t in shown]
    rows = [[problem_cell(verdict, p)] + [equal_error_cell(r, kind) if (r := verdict.equal(p, t)) is not None else ""
                                          for t in shown] for p in verdict.problems]
    doc.table(head, rows, cls="verdict")
    doc.p(f"Each cell: the fastest of our methods whose max position error over the run (`{verdict.attrs['metric']}`, "
          f"in the problem's unit) reaches the column's target, its dt or tolerance there and its cost by {by}; under "
          "it, that cost as a multiple of the fastest library peer's at the same error (0.5x: half the peer's). The "
          "colour is the stored verdict: green ours ahead, red behind (or none of ours reaches the target), grey "
          "within the timing noise, white undecided (the side found dearer is charged only an upper bound, a "
          "measured row already under the target: its ladder does not bracket it) or no peer runs on the problem; "
          f"best: the lowest error any method reached. Rule: {verdict.attrs['rule']}.",
          cls="caption")
    tight = verdict.tight_targets
    faced = [p for p in verdict.problems if any(
        (r := verdict.equal(p, t)) is not None and r["ours_method"] and r["peer_method"] for t in tight)]
    if tight and faced:
        doc.h(2, f"Against the fastest library peer, {targets_span(tight)}")
        doc.table(["problem [unit]"] + [target_text(t) for t in tight],
                  [[problem_cell(verdict, p)] + [peer_cell(verdict.equal(p, t)) for t in tight] for p in faced],
                  cls="verdict")
        left_out = [p for p in verdict.problems if p not in faced]
        doc.p(f"Each cell: the cost of the fastest of ours over the fastest library peer's at the same "
              f"`{verdict.attrs['metric']}` (below 1: ours cheaper), by the rule above, and the verdict with what it "
              "was judged against: the timing noise factor b (ahead or behind only outside 1/b to b; within spread "
              "inside it), or the exact count of force evaluations where a target was ranked by them; the two "
              "methods; and why, in two measured factors whose product is the ratio: the force evaluations each needs "
              "at that error and the time an evaluation takes (the force plus the step's own arithmetic and "
              "bookkeeping). In a bounded cell the side charged an upper bound is charged it in both factors too. "
              + (f"Left out, no library peer reaching these targets there: {', '.join(left_out)}."
                 if left_out else ""),
              cls="caption")
    if verdict.plugin_equal_error is not None:
        doc.h(2, "Your plugin's methods at equal error")
        doc.table(head, [[problem_cell(verdict, p)] + [plugin_cell(verdict.plugin(p, t), kind) for t in shown]
                         for p in verdict.problems], cls="verdict")
        doc.p("Each cell: the fastest method the study's plugins brought (--plugin) at the column's target, by the "
              f"same rule, its dt or tolerance and its cost by {by}; under it, that cost as a multiple of the fastest "
              "of ours's and of the fastest library peer's at the same error (0.5x: half theirs). The colour is its "
              "verdict against ours: green the plugin's is cheaper, red dearer (or only ours reach the target), grey "
              f"within the {'timing noise' if kind == 'time_ns' else 'rounding'}, white undecided (the dearer side "
              "charged only an upper bound) or only the plugin reaches the target.",
              cls="caption")
    doc.h(2, "At a frame rate")
    doc.table(["problem [unit]"] + [f"{hz:g} Hz" for hz in verdict.frame_hz],
              [[problem_cell(verdict, p)] + [frame_cell(verdict, p, hz) for hz in verdict.frame_hz]
               for p in verdict.problems], cls="frames")
    key = ", ".join(f"{s} = {n}" for s, n in used_short_names(verdict))
    doc.p("Each cell: which of our fixed-step methods stay stable at one step a frame (dt = 1 / rate); under it, "
          "for each error target, the cheapest of them with n substeps a frame (x n, n up to 64) that meets it. "
          + (f"Short names: {key}." if key else ""), cls="caption")
    doc.h(2, "Findings")
    doc.items(verdict.findings or ["(none stored)"])


# --- one problem's share -------------------------------------------------------------------------

def problem_section(doc, verdict, problem):
    v = verdict.only(problem)
    kind = v.cost_kind
    unit = v.unit(problem)
    doc.h(3, f"{problem}: verdict at equal error")
    rows = []
    for t in v.targets:
        r = v.equal(problem, t)
        if r is None:
            continue
        ours = [r["ours_method"], param_text(r["ours_kind"], r["ours_param"]), _spread(kind, r, "ours")] \
            if r["ours_method"] else ["none", "", ""]
        peer = [r["peer_method"], param_text(r["peer_kind"], r["peer_param"]), _spread(kind, r, "peer")] \
            if r["peer_method"] else ["none", "", ""]
        ratio = ratio_text(r["ratio"]) if np.isfinite(r["ratio"]) else ""
        rows.append([target_text(t)] + ours + peer + [ratio, r["verdict"]])
    cost = "time" if kind == "time_ns" else "force evals"
    doc.table([f"target [{unit}]", "fastest of ours", "its dt or tolerance", f"{cost} (spread)", "fastest peer",
               "its dt or tolerance", f"{cost} (spread)", "ours / peer", "verdict"], rows)
    if v.plugin_equal_error is not None:
        rows = []
        for t in v.targets:
            r = v.plugin(problem, t)
            if r is None:
                continue
            mine = [r["plugin_method"], param_text(r["plugin_kind"], r["plugin_param"]), _spread(kind, r, "plugin")] \
                if r["plugin_method"] else ["none", "", ""]
            ratios = [ratio_text(r[c]) if np.isfinite(r[c]) else "" for c in ("vs_ours", "vs_peer")]
            rows.append([target_text(t)] + mine + [ratios[0], r["verdict_ours"], ratios[1], r["verdict_peer"]])
        doc.table([f"target [{unit}]", "fastest plugin method", "its dt or tolerance", f"{cost} (spread)",
                   "plugin / ours", "against ours", "plugin / peer", "against the peer"], rows,
                  caption="The plugins' fastest method at the same targets (the verdicts from its side):")
    doc.h(3, f"{problem}: at a frame rate")
    rows = []
    for hz in v.frame_hz:
        rates = v.rates(problem, hz)
        bad = [f"{m} ({note or 'diverged'})" for m, s, note in zip(rates["method"].tolist(), rates["stable"],
                                                                   rates["note"].tolist()) if not s]
        good = [m for m, s in zip(rates["method"].tolist(), rates["stable"]) if s]
        rows.append([f"{hz:g}", ", ".join(good) or "none", ", ".join(bad) or "none"])
    doc.table(["rate [Hz]", "stable at one step a frame", "not stable"], rows,
              caption="Our fixed-step methods at one step a frame (dt = 1 / rate):")
    rows = []
    for t in v.targets:
        row = [target_text(t)]
        for hz in v.frame_hz:
            a = v.answer(problem, hz, t)
            row.append(f"{a['method']} x{int(a['substeps'])}: {frame_cost_text(kind, a)}"
                       if a is not None and a["method"] else "none within 64 substeps")
        rows.append(row)
    doc.table([f"target [{unit}]"] + [f"{hz:g} Hz" for hz in v.frame_hz], rows,
              caption="The cheapest of them with n substeps a frame (x n) within each target, its cost per frame "
                      "(in brackets, in a timed study: its share of the frame):")


# --- summary.json, --markdown, --readme ----------------------------------------------------------

def _plain(v):
    if isinstance(v, (np.floating, float)):
        return float(v) if np.isfinite(v) else None
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, bytes):
        return v.decode()
    return v


def _records(rows):
    return [{name: _plain(r[name]) for name in rows.dtype.names} for r in rows]


def summary(study):
    """summary.json: the verdict tables as stored, and where the study ran."""
    a = study.attrs
    out = {"study": study.path, "git_commit": a["git_commit"], "cpu": a["cpu"], "created_utc": a["created_utc"],
           "timed": study.timed, "verdict": None}
    v = study.verdict
    if v is not None:
        out["verdict"] = {"metric": v.attrs["metric"], "cost_kind": v.cost_kind, "rule": v.attrs["rule"],
                          "targets": v.targets, "frame_hz": v.frame_hz, "findings": v.findings,
                          "equal_error": _records(v.equal_error), "frame_rate": _records(v.frame_rate),
                          "frame_answer": _records(v.frame_answer)}
        if v.plugin_equal_error is not None:
            out["verdict"]["plugin_equal_error"] = _records(v.plugin_equal_error)
    return out


def provenance(study):
    """Where and when the study ran, in one line."""
    a = study.attrs
    how = (f"timed by Google Benchmark ({a['benchmark_mode']})" if study.timed
           else "untimed (costs are force evaluations)")
    return (f"study `{study.path}`, {how}, stepbench {a['version']} at commit {a['git_commit']}, "
            f"{a['cpu']} ({int(a['cores'])} cores), {a['created_utc']}")


def results_doc(study, command):
    """--markdown: the answer-first tables as Markdown (docs/results.md)."""
    from .render import Doc
    doc = Doc("stepbench results: which integrator for which need")
    doc.p(f"From the {provenance(study)}. Written by `{command}`; do not edit, run it again.")
    opening(doc, study.verdict)
    if getattr(study, "challenge", None) is not None:
        from . import challenge
        challenge.answer(doc, study.challenge)
    orders = xpbd_orders(study)
    if orders:
        doc.p("xpbd's observed order over the substep ladder (the study's fit, its levels in brackets): "
              + "; ".join(orders) + ".")
    answers = _range_answers(study)
    if answers:
        doc.h(2, "A scene's range")
        doc.p("The range answer of each scan of the study at its tolerance, as `stepbench advise --scan FILE --tol X` "
              "prints it: the cheapest method and substeps that stay stable and within the tolerance over the whole "
              "range at each rate, and where each method diverges at one step a frame.")
        for name, text in answers:
            doc.h(3, f"Scan {name}")
            doc.pre(text)
    return doc


def _range_answers(study):
    from . import range_answer
    try:
        return range_answer.range_answers(study.path)
    except (OSError, KeyError):
        return []


def xpbd_orders(study):
    """'pendulum 0.990 (levels 10-18)' for each problem xpbd ran on, as the C++ fit wrote it."""
    out = []
    for p in study.problems:
        m = next((m for m in p.methods if m.name == "xpbd"), None)
        if m is None:
            continue
        levels = m.fit_levels
        order = float(m.attrs["observed_order"])
        span = f"levels {levels[0]}-{levels[-1]}" if levels else "no fit"
        out.append(f"{p.name} {order:.3f} ({span})" if np.isfinite(order) else f"{p.name} n/a ({m.attrs['fit_note']})")
    return out


BEGIN, END = "<!-- results:begin -->", "<!-- results:end -->"


def rewrite_block(text, block):
    """`text` with only what lies between the markers replaced by `block`; ValueError
    when the markers are absent or out of order."""
    start, end = text.find(BEGIN), text.find(END)
    if start < 0 or end < 0 or end < start:
        raise ValueError(f"no '{BEGIN}' ... '{END}' block")
    return text[:start + len(BEGIN)] + "\n" + block.rstrip("\n") + "\n" + text[end:]
