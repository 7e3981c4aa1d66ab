"""The report's tables, formatted from what the study file holds. Nothing here ranks,
fits or selects: the cheapest methods come from `equal_error`, the fronts from
`front_*`, the orders and their verdicts from each method's attributes (all computed
in C++, core/work_precision.hpp and core/convergence_fit.hpp)."""
import numpy as np

from .formatting import fmt_count, fmt_num, fmt_sci, fmt_seconds, fmt_time_ns, label
from .render import Cell, esc
from .study import SUMMARY_TARGETS

SUMMARY_METRICS = (("err_pos_final", "by final error"), ("err_pos_max", "by max error over the run"))


def fmt_param(method, value):
    return f"tol = {value:.3g}" if method.adaptive else f"dt = {value:.6g} s"


def fmt_cost(cost_kind, cost):
    return fmt_time_ns(cost) if cost_kind == "time_ns" else f"{int(cost)} force evals"


def _fit_range(method):
    levels = method.fit_levels
    if not levels:
        return ""
    p = method.param
    return f"{p[max(levels)]:.3g} - {p[min(levels)]:.3g}"


def observed_text(method):
    status = method.attrs["fit_status"]
    if status == "exact":
        return "exact for this problem"
    if status == "fitted":
        return f"{method.attrs['fit_slope']:.3f}"
    return f"not fitted: {method.attrs['fit_note']}"


def holds_text(method):
    """`declared_order_holds` as the table says it: 1 yes, 0 no (with the figures), -1
    cannot be said (exact, not fitted, or no declared order)."""
    holds = int(method.attrs["declared_order_holds"])
    if holds == 1:
        return "yes"
    if holds == 0:
        return f"NO: declares {method.declared_order:g}, achieves {method.attrs['observed_order']:.2f}"
    return "n/a"


def order_rows(problem):
    """Declared versus observed order of every fixed-step method (ours, peers, baseline)."""
    rows = []
    for m in problem.methods:
        if m.adaptive:
            continue
        fitted = m.attrs["fit_status"] == "fitted"
        rows.append([label(m), "n/a" if not np.isfinite(m.declared_order) else f"{m.declared_order:g}",
                     observed_text(m), ",".join(map(str, m.fit_levels)), _fit_range(m),
                     fmt_num(m.attrs["fit_residual_log10"], 2) if fitted else "", holds_text(m),
                     ladder_end_text(m)])
    return rows


def ladder_end_text(method):
    """Why the fixed-step ladder stopped, in a word (the study file has the sentence):
    round-off, the work budget, its last level, divergence, an exact method."""
    why = str(method.attrs.get("ladder_end", ""))  # absent in files before the ladder went on to round-off
    steps = int(method.runs["steps"].max()) if len(method.runs) else 0
    short = why.split(":")[0].split(" (")[0].removeprefix("the ")
    return f"{len(method.runs)} levels, {steps} steps: {short}" if why else ""


ORDER_HEAD = ["method", "declared order", "observed order", "fit levels", "fit dt range [s]", "fit residual (log10)",
              "declared order holds", "ladder stops at"]


def adaptive_rows(problem):
    """The adaptive methods' fit of error against tolerance: a slope near 1 means the
    error follows the tolerance asked for."""
    rows = []
    for m in problem.methods:
        if not m.adaptive:
            continue
        fitted = m.attrs["fit_status"] == "fitted"
        completed = m.completed
        rows.append([label(m), m.attrs["library"], fmt_num(m.attrs["fit_slope"]) if fitted else observed_text(m),
                     ",".join(map(str, m.fit_levels)), _fit_range(m), str(int(completed.sum())) + f" of {len(m.runs)}",
                     str(int(m.runs["rejected_steps"].sum()))])
    return rows


ADAPTIVE_HEAD = ["method", "library", "error-per-tolerance slope", "fit levels", "fit tolerance range",
                 "runs completed", "rejected steps (all runs)"]


def summary_rows(problem, metric):
    """The answer of `equal_error` for each summary target: the cheapest method that is
    not the baseline, and (where the baseline reached the target too) the baseline for
    scale."""
    rows = []
    table = problem.equal_error[problem.equal_error["metric"] == metric]
    has_baseline = bool(problem.by_origin("baseline"))
    for target in SUMMARY_TARGETS:
        at = table[np.isclose(table["target"], target, rtol=1e-9, atol=0)]
        answer = at[at["is_answer"] == 1]
        if len(answer):
            a = answer[0]
            m = problem.method(a["method"])
            at_run = m.row_at(a["param"])
            note = ""
            if at_run is None:  # an interpolated row: between two runs, its error is the target's
                errors = {metric: a["error"]}
                note = "interpolated between two runs"
            else:
                run = m.runs[at_run]
                errors = {"err_pos_final": run["err_pos_final"], "err_pos_max": run["err_pos_max"]}
                if metric == "err_pos_final" and run["err_pos_max"] > 10 * target:
                    note = (f"small at the horizon only: the max error over the run is "
                            f"{fmt_num(run['err_pos_max'])} {problem.unit}")
            row = [f"{target:g}", label(m), fmt_param(m, a["param"]), fmt_cost(a["cost_kind"], a["cost"]),
                   fmt_num(errors.get("err_pos_final")), fmt_num(errors.get("err_pos_max")), note]
        else:
            row = [f"{target:g}", "none reaches it", "", "", "", "", ""]
        if has_baseline:
            base = at[at["origin"] == "baseline"]
            row.append("; ".join(f"{b['method']} {fmt_param(problem.method(b['method']), b['param'])}: "
                                 f"{fmt_cost(b['cost_kind'], b['cost'])}" for b in base) or "does not reach it")
        rows.append(row)
    head = [f"target {metric} [{problem.unit}]", "cheapest method", "dt or tolerance", "cost",
            f"err_pos_final [{problem.unit}]", f"err_pos_max [{problem.unit}]", "note"]
    if has_baseline:
        head.append("hand-written floor (baseline, for scale)")
    return head, rows


def cheapest_cell(problem, target):
    """The opening table of a study without /verdict: the cheapest measured run reaching
    `target` in max error over the run (the `is_answer` row of `equal_error`)."""
    ee = problem.equal_error
    at = ee[(ee["metric"] == "err_pos_max") & np.isclose(ee["target"], target, rtol=1e-9, atol=0)
            & (ee["is_answer"] == 1)]
    if not len(at):
        return Cell("none reaches it", "&ndash;", "none")
    a = at[0]
    m = problem.method(a["method"])
    param = f"tol {fmt_sci(a['param'])}" if m.adaptive else f"dt {fmt_seconds(a['param'])}"
    cost = fmt_time_ns(a["cost"]) if a["cost_kind"] == "time_ns" else f"{fmt_count(a['cost'])} evals"
    return Cell(f"{label(m)} {param}, {cost}", f"<b>{esc(label(m))}</b> {esc(param)} &middot; {esc(cost)}")


def method_rows(problem, curves, shown, front_key):
    """Every method of a work-precision figure, drawn in colour or grey: how it is drawn,
    its kind, the front rows it has, and its lowest error with that run's cost."""
    front = problem.fronts[front_key]["method"].tolist()
    drawn = {m.name: (x, e) for m, x, e in curves}
    cost = fmt_time_ns if front_key == "time" else (lambda n: fmt_count(n))
    to_cost = 1e9 if front_key == "time" else 1.0
    rows = []
    for m in problem.methods:
        if m.name in drawn:
            x, e = drawn[m.name]
            k = int(np.argmin(e))
            best, at = fmt_num(e[k]), cost(x[k] * to_cost)
        else:
            best, at = "no completed run", ""
        how = "labelled" if m.name in shown else "grey"
        rows.append([label(m), m.attrs["kind"], how, str(front.count(m.name)) if m.name in front else "",
                     best, at, f"{int(m.completed.sum())} of {len(m.runs)}"])
    head = ["method", "kind", "in the figure", "front rows", f"lowest err_pos_max [{problem.unit}]",
            "its cost" + (" (time per run)" if front_key == "time" else " (force evals)"), "runs completed"]
    return head, rows


def front_rows(problem, front_key):
    """A Pareto front from the file, consecutive rows of one method merged into one line."""
    front = problem.fronts[front_key]
    groups = []
    for r in front:
        if groups and groups[-1][-1]["method"] == r["method"]:
            groups[-1].append(r)
        else:
            groups.append([r])
    cost = (lambda ns: fmt_time_ns(ns)) if front_key == "time" else (lambda n: str(int(n)))

    def span(a, b, f):
        return f(a) if a == b else f"{f(a)} .. {f(b)}"

    rows = []
    for g in groups:
        m = problem.method(g[0]["method"])
        param = (lambda v: f"{v:.3g}") if m.adaptive else (lambda v: f"{v:.6g}")
        rows.append([label(m), str(len(g)),
                     ("tol " if m.adaptive else "dt ") + span(g[0]["param"], g[-1]["param"], param)
                     + ("" if m.adaptive else " s"),
                     span(g[0]["cost"], g[-1]["cost"], cost), span(g[0]["err_pos_max"], g[-1]["err_pos_max"], fmt_num)])
    head = ["method", "runs", "dt or tolerance", "time per run" if front_key == "time" else "force evals",
            f"err_pos_max [{problem.unit}]"]
    return head, rows


def front_methods(problem, front_key):
    return list(dict.fromkeys(problem.fronts[front_key]["method"]))


def reference_rows(problem):
    rows = []
    for src, a in sorted(problem.references.items()):
        status = a["status"] + (f": {a['reason']}" if a["reason"] else "")
        rows.append([src, status, "yes" if int(a["is_truth"]) else "", str(a["steps"]), str(a["failed_steps"]),
                     str(a["rhs_evals"]), str(a["lin_rhs_evals"]), str(a["rhs_evals_counted"]), a["compared_with"],
                     fmt_num(a["err_pos_rel"], 2), fmt_num(a["err_vel_rel"], 2)])
    return rows


REFERENCE_HEAD = ["source", "status", "is truth", "steps", "failed steps", "rhs_evals", "lin_rhs_evals",
                  "rhs_evals_counted", "compared with", "position agreement (rel.)", "velocity agreement (rel.)"]
