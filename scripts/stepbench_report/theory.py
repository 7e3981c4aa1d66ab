"""Linear stability theory of our six methods, computed, not quoted.

Each method's step is written here exactly as in integrators/*.hpp and applied to the
linear test system x'' = -w^2 x - c x' (the damped_spring force per unit mass). In
scaled time (w = 1, y = w dt, c' = c / w = 2 zeta) one step is a 2x2 matrix M(y) whose
entries are polynomials in y; they are built with exact rational coefficients
(fractions.Fraction), so cancellations are exact. The iteration x_{n+1} = M x_n stays
bounded iff both eigenvalues lie in the closed unit disk and any on the circle are
distinct. With T = trace M and D = det M, the eigenvalues (roots of l^2 - T l + D) can
leave the disk only where D = 1 (complex pair, |l|^2 = D) or where a real eigenvalue
hits +1 (1 - T + D = 0) or -1 (1 + T + D = 0); so the stability limit is one of the
positive real roots of those three polynomials, found with numpy.roots and polished with
scipy.optimize.brentq, and checked by evaluating the eigenvalues on either side.

For the Runge-Kutta methods the same numbers follow from the stability function R(z)
(Hairer & Wanner, Solving ODEs II, sec. IV.2): on the undamped oscillator the
eigenvalues of M are R(+-i y), so D(y) = |R(i y)|^2; the script asserts that identity
as a cross-check of the step code.
"""
from fractions import Fraction
from math import factorial

import numpy as np
from scipy.optimize import brentq


class Poly:
    """Polynomial in y with exact rational coefficients, lowest degree first."""

    def __init__(self, coeffs):
        c = [Fraction(x) for x in coeffs]
        while len(c) > 1 and c[-1] == 0:
            c.pop()
        self.c = c or [Fraction(0)]

    @staticmethod
    def lift(x):
        return x if isinstance(x, Poly) else Poly([x])

    def __add__(self, o):
        o = Poly.lift(o)
        n = max(len(self.c), len(o.c))
        return Poly([(self.c[i] if i < len(self.c) else 0) + (o.c[i] if i < len(o.c) else 0) for i in range(n)])

    __radd__ = __add__

    def __neg__(self):
        return Poly([-x for x in self.c])

    def __sub__(self, o):
        return self + (-Poly.lift(o))

    def __rsub__(self, o):
        return Poly.lift(o) - self

    def __mul__(self, o):
        o = Poly.lift(o)
        out = [Fraction(0)] * (len(self.c) + len(o.c) - 1)
        for i, a in enumerate(self.c):
            for j, b in enumerate(o.c):
                out[i + j] += a * b
        return Poly(out)

    __rmul__ = __mul__

    def __truediv__(self, k):
        return Poly([x / Fraction(k) for x in self.c])

    def is_zero(self):
        return all(x == 0 for x in self.c)

    def __call__(self, y):
        return np.polynomial.polynomial.polyval(y, [float(x) for x in self.c])

    def positive_roots(self):
        """Positive real roots, polished by bisection where the sign changes."""
        if self.is_zero() or len(self.c) == 1:
            return []
        coeffs = [float(x) for x in reversed(self.c)]
        out = []
        for r in np.roots(coeffs):
            if abs(r.imag) > 1e-7 * max(1.0, abs(r)) or r.real <= 1e-9:
                continue
            x = r.real
            lo, hi = x * (1 - 1e-6), x * (1 + 1e-6)
            if np.sign(self(lo)) != np.sign(self(hi)):
                x = brentq(self, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps)
            if all(abs(x - o) > 1e-9 * x for o in out):
                out.append(x)
        return sorted(out)

    def __str__(self):
        terms = []
        for k, a in enumerate(self.c):
            if a == 0:
                continue
            mag = abs(a)
            num, den = mag.numerator, mag.denominator
            mono = "" if k == 0 else ("y" if k == 1 else f"y^{k}")
            if k == 0:
                body = f"{num}" + (f"/{den}" if den != 1 else "")
            else:
                body = ("" if num == 1 else f"{num} ") + mono + (f"/{den}" if den != 1 else "")
            terms.append(("-" if a < 0 else "+", body))
        if not terms:
            return "0"
        s = ("-" if terms[0][0] == "-" else "") + terms[0][1]
        for sign, body in terms[1:]:
            s += f" {sign} {body}"
        return s


# --- the steps, as in integrators/*.hpp, for a(x, v) = -x - c v (scaled, w = 1) ----------

def _euler(x, v, h, a):
    acc = a(x, v)
    return x + h * v, v + h * acc


def _semi_implicit_euler(x, v, h, a):
    v1 = v + h * a(x, v)
    return x + h * v1, v1


def _momentum(x, v, h, a):
    # p += F dt, v = p / m, x += v dt; with m = 1 (the map does not depend on m: F/m = a).
    p = v + h * a(x, v)
    v1 = p
    return x + h * v1, v1


def _midpoint(x, v, h, a):
    half = h / 2
    xm, vm = x + half * v, v + half * a(x, v)
    return x + h * vm, v + h * a(xm, vm)


def _rk4(x, v, h, a):
    half = h / 2
    dv1 = a(x, v)
    x2, v2 = x + half * v, v + half * dv1
    dv2 = a(x2, v2)
    x3, v3 = x + half * v2, v + half * dv2
    dv3 = a(x3, v3)
    x4, v4 = x + h * v3, v + h * dv3
    dv4 = a(x4, v4)
    return x + (h / 6) * (v + 2 * (v2 + v3) + v4), v + (h / 6) * (dv1 + 2 * (dv2 + dv3) + dv4)


def _velocity_verlet(x, v, h, a):
    # Kick-drift-kick; with a velocity-dependent force the new acceleration is taken at
    # the Euler-predicted velocity (integrators/velocity_verlet.hpp). Without damping
    # a(x1, v_pred) = a(x1, v_half), i.e. the textbook method.
    half = h / 2
    a_n = a(x, v)
    v_half = v + half * a_n
    x1 = x + h * v_half
    v_pred = v_half + half * a_n
    return x1, v_half + half * a(x1, v_pred)


STEPS = {
    "euler": _euler,
    "semi_implicit_euler": _semi_implicit_euler,
    "momentum": _momentum,
    "midpoint": _midpoint,
    "velocity_verlet": _velocity_verlet,
    "rk4": _rk4,
}

# Stability functions R(z) of the Runge-Kutta methods (z = h lambda): truncated
# exponential series, sum_{k<=s} z^k / k! for the explicit s-stage methods of order s.
RK_ORDER = {"euler": 1, "midpoint": 2, "rk4": 4}


def stability_function(name):
    """Coefficients of R(z), lowest degree first."""
    return [1.0 / factorial(k) for k in range(RK_ORDER[name] + 1)]


def step_matrix(name, damping=Fraction(0)):
    """M(y) for the scaled system x'' = -x - damping x', as 2x2 nested lists of Poly."""
    y = Poly([0, 1])
    c = Fraction(damping)

    def a(x, v):
        return -1 * x - c * v

    step = STEPS[name]
    col_x = step(Poly([1]), Poly([0]), y, a)
    col_v = step(Poly([0]), Poly([1]), y, a)
    return [[col_x[0], col_v[0]], [col_x[1], col_v[1]]]


def _spectral_radius(m, y):
    mat = np.array([[m[0][0](y), m[0][1](y)], [m[1][0](y), m[1][1](y)]])
    return max(abs(np.linalg.eigvals(mat)))


def _bounded(m, y, tol=1e-9):
    """Power-bounded at y: eigenvalues in the unit disk, none repeated on the circle."""
    mat = np.array([[m[0][0](y), m[0][1](y)], [m[1][0](y), m[1][1](y)]])
    lam = np.linalg.eigvals(mat)
    if max(abs(lam)) > 1 + tol:
        return False
    on_circle = abs(abs(lam) - 1) <= tol
    return not (on_circle.all() and abs(lam[0] - lam[1]) <= 1e-6)


def oscillator_limit(name, damping=Fraction(0)):
    """Largest y* = w dt such that the method is stable for every 0 < w dt < y*.

    Returns (y_star, detail): y_star is 0.0 when the method is unstable for every dt
    (math.inf if stable for all dt); detail holds the exact polynomials used.
    """
    m = step_matrix(name, damping)
    t = m[0][0] + m[1][1]
    d = m[0][0] * m[1][1] - m[0][1] * m[1][0]
    candidates = sorted(set((d - 1).positive_roots() + (1 - t + d).positive_roots() + (1 + t + d).positive_roots()))
    detail = {"trace": t, "det": d, "det_minus_1": d - 1, "candidates": candidates}
    # Stability can change only at a candidate: test inside each interval from 0 on.
    edges = [0.0] + candidates
    for i in range(len(edges)):
        lo = edges[i]
        hi = edges[i + 1] if i + 1 < len(edges) else (lo * 2 if lo > 0 else 1.0)
        if not _bounded(m, 0.5 * (lo + hi)):
            return lo, detail
    return float("inf"), detail


def imaginary_axis_limit(name):
    """Largest y with |R(i y')| <= 1 for all 0 <= y' <= y (0 if none), from R(z)."""
    r = stability_function(name)
    # |R(iy)|^2 - 1 as a polynomial in y with exact coefficients.
    re = Poly([Fraction(1, factorial(k)) * (1 if k % 4 == 0 else -1) if k % 2 == 0 else 0 for k in range(len(r))])
    im = Poly([Fraction(1, factorial(k)) * (1 if k % 4 == 1 else -1) if k % 2 == 1 else 0 for k in range(len(r))])
    excess = re * re + im * im - 1
    roots = excess.positive_roots()
    first = roots[0] if roots else 1.0
    if excess(0.5 * first) > 0:
        return 0.0, excess
    return (roots[0] if roots else float("inf")), excess


def real_axis_limit(name):
    """Most negative x with |R(x')| <= 1 for all x <= x' <= 0 (the real interval's end)."""
    coeffs = stability_function(name)
    r = np.polynomial.Polynomial(coeffs)
    cands = []
    for poly in (r - 1, r + 1):
        for root in poly.roots():
            if abs(root.imag) < 1e-9 and root.real < -1e-9:
                x = root.real
                lo, hi = x * (1 + 1e-6), x * (1 - 1e-6)
                if np.sign(poly(lo)) != np.sign(poly(hi)):
                    x = brentq(poly, lo, hi, xtol=1e-15)
                cands.append(x)
    cands = sorted(set(cands), reverse=True)  # nearest to 0 first
    prev = 0.0
    for x in cands:
        if abs(r(0.5 * (prev + x))) > 1 + 1e-12:
            return prev
        prev = x
    return prev


def check_rk_consistency():
    """D(y) of the step matrix equals |R(iy)|^2 for the RK methods (undamped)."""
    ys = np.linspace(0.1, 3.0, 7)
    for name in RK_ORDER:
        m = step_matrix(name)
        d = m[0][0] * m[1][1] - m[0][1] * m[1][0]
        r = np.polynomial.Polynomial(stability_function(name))
        assert np.allclose(d(ys), abs(r(1j * ys)) ** 2, rtol=1e-12), name


def oscillator_table(methods, w0=None, damping_ratio=None):
    """One dict per method: the undamped limit w dt < y*, and, given the problem's w0
    (and damping ratio zeta), the dt limits for that problem."""
    check_rk_consistency()
    rows = []
    for name in methods:
        if name not in STEPS:
            continue
        y, detail = oscillator_limit(name)
        row = {"method": name, "y_limit": y, "det_minus_1": detail["det_minus_1"], "trace": detail["trace"]}
        if name in RK_ORDER:
            y_rk, _ = imaginary_axis_limit(name)
            assert (y == 0 and y_rk == 0) or abs(y - y_rk) < 1e-9 * max(1, y), (name, y, y_rk)
        if w0:
            row["dt_limit"] = y / w0
            if damping_ratio is not None:
                # Scaled damping c / w0 = k_d / (m w0) = 2 zeta; Fraction(float) is exact.
                yd, _ = oscillator_limit(name, Fraction(2 * damping_ratio))
                row["dt_limit_damped"] = yd / w0
        rows.append(row)
    return rows
