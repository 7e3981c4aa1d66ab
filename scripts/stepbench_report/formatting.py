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
    ns = float(f"{ns:.3g}")  # rounded before the unit is chosen: 999.7 ns is "1 us"
    for scale, unit in ((1e9, "s"), (1e6, "ms"), (1e3, "us")):
        if ns >= scale:
            return f"{ns / scale:.3g} {unit}"
    return f"{ns:.3g} ns"


def _two_digits(v):
    """Two significant digits, never in exponent form (170, 17, 1.7)."""
    return f"{v:.0f}" if abs(v) >= 100 else f"{v:.2g}"


def fmt_sci(x, digits=2):
    """A compact power of ten: 1e-4, 3.2e-7 (no zero-padded exponent); "n/a" for NaN."""
    if x is None or not np.isfinite(x):
        return "n/a"
    if x == 0:
        return "0"
    mantissa, exponent = f"{float(x):.{digits - 1}e}".split("e")
    mantissa = mantissa.rstrip("0").rstrip(".")
    return f"{mantissa}e{int(exponent)}"


def fmt_seconds(s):
    """A step or a time in seconds with its unit, two significant digits: "2.4 ms"."""
    if s is None or not np.isfinite(s):
        return "n/a"
    for scale, unit in ((1.0, "s"), (1e-3, "ms"), (1e-6, "us")):
        if abs(s) >= scale:
            return f"{_two_digits(s / scale)} {unit}"
    return f"{_two_digits(s / 1e-9)} ns"


def fmt_count(n):
    """A count such as force evaluations, short: 950, 12k, 1.2M."""
    if n is None or not np.isfinite(n):
        return "n/a"
    n = float(f"{n:.3g}")  # rounded before the unit is chosen: 999,700 is "1M", not "1000k"
    for scale, unit in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if n >= scale:
            return f"{_two_digits(n / scale)}{unit}"
    return f"{n:.0f}"


def label(method):
    """The method's name as every table and legend shows it: peers, the baseline and plugins marked."""
    marks = {"ours": "", "peer": " (peer)", "baseline": " (baseline, for scale)", "plugin": " (plugin)"}
    return method.name + marks[method.origin]
