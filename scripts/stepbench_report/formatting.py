"""The text forms every part of the report shares (tables, figures' legends, the
sections): numbers, times, a method's label. A leaf: it imports nothing from the
package, so the readers (study.py and the sections it reads with) and the drawing
(figures.py) can use it without importing each other."""
import math

import numpy as np


def fmt_num(x, digits=3):
    if x is None or (isinstance(x, (float, np.floating)) and math.isnan(x)):
        return "n/a"
    return f"{x:.{digits}g}"


def fmt_time_ns(ns):
    """As C++'s format_time_ns: "12.3 us"."""
    if ns is None or not np.isfinite(ns):
        return "n/a"
    for scale, unit in ((1e9, "s"), (1e6, "ms"), (1e3, "us")):
        if ns >= scale:
            return f"{ns / scale:.3g} {unit}"
    return f"{ns:.3g} ns"


def label(method):
    """The method's name as every table and legend shows it: peers and the baseline marked."""
    return method.name + {"ours": "", "peer": " (peer)", "baseline": " (baseline, for scale)"}[method.origin]
