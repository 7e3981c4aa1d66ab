"""A second reading of a method's measured work-precision curve, for the tests only (the rule
itself is core/work_precision.cpp's): a figure at an error target, log-log between each pair of
neighbouring rows whose errors bracket it, or, for an upper bound, each row already under it."""
import math


def at_target(rows, target, interpolated, figure="force_evals"):
    """Every value the rule could have read: `rows` a study's runs table (err_pos_max and
    `figure`); `interpolated` as the verdict stored it for the pick."""
    err, y = rows["err_pos_max"], rows[figure].astype(float)
    if not interpolated:
        return [float(v) for v, e in zip(y, err) if e <= target]
    out = []
    for i in range(len(rows) - 1):
        a, b = err[i], err[i + 1]
        if a > 0 and b > 0 and a != b and (a - target) * (b - target) <= 0:
            s = math.log(target / a) / math.log(b / a)
            out.append(math.exp(math.log(y[i]) + s * math.log(y[i + 1] / y[i])))
    return out
