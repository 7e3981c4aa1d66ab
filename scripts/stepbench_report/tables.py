"""The numbers behind the report's tables, computed from the study file alone."""
import math

import numpy as np

THRESHOLDS = (1e-2, 1e-4, 1e-6)  # the "final errors of 1e-2, 1e-4 and 1e-6"
SUMMARY_METRIC = "err_pos_final"


def fmt_num(x, digits=3):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    return f"{x:.{digits}g}"


def fmt_time_ns(ns):
    if ns is None or not np.isfinite(ns):
        return "n/a"
    for scale, unit in ((1e9, "s"), (1e6, "ms"), (1e3, "us")):
        if ns >= scale:
            return f"{ns / scale:.3g} {unit}"
    return f"{ns:.3g} ns"


def fmt_param(method, value):
    return f"rtol = {value:.3g}" if method.adaptive else f"dt = {value:.6g} s"


def order_rows(problem, peers=False):
    """Expected versus observed order, one dict per method (integrators, or fixed-step peers)."""
    rows = []
    for m in (problem.peers if peers else problem.integrators):
        if peers and m.adaptive:
            continue
        a = m.attrs
        status = a.get("fit_status", "")
        observed = a.get("observed_order", float("nan"))
        if int(a.get("exact_for_problem", 0) or 0) == 1 or status == "exact":
            text = "exact for this problem"
        elif status == "fitted" and np.isfinite(observed):
            text = f"{observed:.3f}"
        else:
            text = "not fitted" + (f" ({a['fit_note']})" if a.get("fit_note") else "")
        levels = [int(k) for k in np.atleast_1d(a.get("fit_levels", []))] if a.get("fit_levels") is not None else []
        dt = m.param
        dt_range = f"{dt[max(levels)]:.3g} - {dt[min(levels)]:.3g}" if levels and len(dt) > max(levels) else ""
        expected = m.expected_order
        rows.append({
            "method": m.name,
            "expected": "n/a" if not np.isfinite(expected) else f"{expected:g}",
            "observed": text,
            "levels": ",".join(str(k) for k in levels),
            "dt_range": dt_range,
            "residual": fmt_num(a.get("fit_residual_log10"), 2) if status == "fitted" else "",
            "observed_value": observed,
        })
    return rows


def reference_rows(problem):
    rows = []
    for src, a in sorted(problem.references.items()):
        rows.append({
            "source": src,
            "truth": "yes" if int(a.get("is_truth", 0) or 0) else "",
            "steps": a.get("steps"), "failed": a.get("failed_steps"),
            "rhs_evals": a.get("rhs_evals"), "lin_rhs_evals": a.get("lin_rhs_evals"),
            "rhs_evals_counted": a.get("rhs_evals_counted"),
            "compared_with": a.get("compared_with", ""),
            "err_pos_rel": a.get("err_pos_rel"), "err_vel_rel": a.get("err_vel_rel"),
        })
    return rows


def candidates(problem, metric, timings):
    """Every (method, row) of the problem that could answer "cheapest for an error":
    integrator rows and peer rows, as flat records."""
    out = []
    for m in problem.methods:
        err = m.col(metric)
        if not m.has(metric):
            continue
        div, cut, t, fe, par = m.diverged, m.cut, m.col("time_ns"), m.col("force_evals"), m.param
        for i in range(len(m.rows)):
            out.append({"method": m, "i": i, "param": par[i], "err": err[i], "diverged": bool(div[i]),
                        "cut": bool(cut[i]) and timings, "time_ns": t[i], "force_evals": fe[i],
                        "err_pos_max": m.col("err_pos_max")[i], "err_final": m.col("err_pos_final")[i]})
    return out


def cheapest(problem, tol, timings, metric=SUMMARY_METRIC):
    """The cheapest row meeting `metric <= tol`, by the same rule as `stepbench advise`:
    a row qualifies when it did not diverge, meets the tolerance and (timed study) was
    not cut by the time budget; the cost is time_ns when every qualifying row has one,
    else force_evals. Ties go to the lower error, then the method name. Returns (row or None, cost_name, best)."""
    rows = candidates(problem, metric, timings)
    ok = [r for r in rows if not r["diverged"] and np.isfinite(r["err"]) and r["err"] <= tol and not r["cut"]]
    all_timed = timings and all(np.isfinite(r["time_ns"]) and r["time_ns"] > 0 for r in ok)
    cost = "time_ns" if all_timed else "force_evals"
    best_err = min((r for r in rows if not r["diverged"] and np.isfinite(r["err"])), key=lambda r: r["err"],
                   default=None)
    if not ok:
        return None, cost, best_err
    win = min(ok, key=lambda r: (r[cost], r["err"], r["method"].name))
    return win, cost, best_err


def pareto_mask(cost, err, rel=1e-6):
    """Points no other point beats in both cost and error. Going up in cost, a point
    joins the front only if its error is lower than every cheaper point's by more than
    `rel` (relative): the same method run by two libraries gives errors equal up to
    round-off, and the slower one does not beat the faster."""
    cost, err = np.asarray(cost, float), np.asarray(err, float)
    n = len(cost)
    mask = np.zeros(n, bool)
    order = np.lexsort((err, cost))  # by cost, then error
    best = np.inf
    for i in order:
        if err[i] < best * (1 - rel):  # best starts at inf, so the cheapest finite point joins
            mask[i] = True
            best = err[i]
    return mask


def work_points(problem, x_field, timings, err_field="err_pos_max"):
    """Per method: (x, err) arrays of the rows usable on a work-precision plot."""
    pts = {}
    for m in problem.methods:
        if not m.has(err_field):
            continue
        # "time_s": the median wall time, converted from the file's nanoseconds.
        x = m.col("time_ns") * 1e-9 if x_field == "time_s" else m.col(x_field)
        e = m.col(err_field)
        ok = ~m.diverged & np.isfinite(x) & (x > 0) & np.isfinite(e)
        if timings:
            ok &= ~m.cut
        if ok.any():
            pts[m.name] = (x[ok], e[ok], m.param[ok], m)
    return pts


def pareto_front(points):
    """[(method name, x, err, param, Method)] on the front of all methods' points."""
    flat = [(name, x, e, p, m) for name, (xs, es, ps, m) in points.items() for x, e, p in zip(xs, es, ps)]
    if not flat:
        return []
    mask = pareto_mask([f[1] for f in flat], [f[2] for f in flat])
    return sorted((f for f, keep in zip(flat, mask) if keep), key=lambda f: f[1])
