"""/stability cross-checked against a symbolic computation (what scripts/stepbench_report/
theory.py computed for the report before the C++ did; it now exists only here, as a test
of the compiled steps' figures in the file).

Each method's step is written here as in integrators/*.hpp and applied to the linear
test systems with exact rational arithmetic (fractions.Fraction), so one step is a 2x2
matrix M(y) whose entries are polynomials in y:
  oscillator  a(x, v) = -x (omega = 1, y = omega dt),
  decay       a(x, v) = -v (the damper F = -m lambda v, lambda = 1, y = lambda dt).
The iteration stays bounded iff both eigenvalues of M lie in the closed unit disk (none
repeated on the circle). With T = trace M and D = det M the eigenvalues can leave the
disk only where D = 1 (a complex pair, |l|^2 = D), where a real eigenvalue hits +1
(1 - T + D = 0) or -1 (1 + T + D = 0): the limit is one of the positive roots of those
polynomials (numpy roots, polished with scipy brentq), checked by the eigenvalues
between them. The same step code applied to complex numbers with a(x, v) = z v gives
R(z) on the damper with a complex rate, which is what /stability/regions holds.
"""
import json
import subprocess
from fractions import Fraction
from math import factorial

import h5py
import numpy as np
import pytest
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
        out = []
        for r in np.roots([float(x) for x in reversed(self.c)]):
            if abs(r.imag) > 1e-7 * max(1.0, abs(r)) or r.real <= 1e-9:
                continue
            x = r.real
            lo, hi = x * (1 - 1e-6), x * (1 + 1e-6)
            if np.sign(self(lo)) != np.sign(self(hi)):
                x = brentq(self, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps)
            if all(abs(x - o) > 1e-9 * x for o in out):
                out.append(x)
        return sorted(out)


# --- the steps, as in integrators/*.hpp (m = 1: the maps do not depend on m) -----------------

def _euler(x, v, h, a):
    acc = a(x, v)
    return x + h * v, v + h * acc


def _semi_implicit_euler(x, v, h, a):
    v1 = v + h * a(x, v)
    return x + h * v1, v1


def _momentum(x, v, h, a):
    p = v + h * a(x, v)  # p += F dt, v = p / m, x += v dt
    return x + h * p, p


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


def _velocity_verlet(x, v, h, a, velocity_dependent):
    # Kick-drift-kick; with a velocity-dependent force the new acceleration is taken at
    # the Euler-predicted velocity (integrators/velocity_verlet.hpp), otherwise at v_half
    # (the force ignores it).
    half = h / 2
    a_n = a(x, v)
    v_half = v + half * a_n
    x1 = x + h * v_half
    v_new = v_half + half * a_n if velocity_dependent else v_half
    return x1, v_half + half * a(x1, v_new)


def _adaptive_euler(x, v, h, a):
    # The accepted step: two explicit Euler steps of h/2 (integrators/adaptive_euler.hpp).
    half = h / 2
    x, v = _euler(x, v, half, a)
    return _euler(x, v, half, a)


STEPS = {
    "euler": _euler,
    "semi_implicit_euler": _semi_implicit_euler,
    "momentum": _momentum,
    "midpoint": _midpoint,
    "rk4": _rk4,
    "adaptive_euler": _adaptive_euler,
}
TESTS = {"oscillator": (lambda x, v: -1 * x, False), "decay": (lambda x, v: -1 * v, True)}


def step(name, velocity_dependent):
    if name == "velocity_verlet":
        return lambda x, v, h, a: _velocity_verlet(x, v, h, a, velocity_dependent)
    return STEPS[name]


def step_matrix(name, test):
    """M(y) for one of the test systems, as 2x2 nested lists of Poly."""
    a, velocity_dependent = TESTS[test]
    y = Poly([0, 1])
    f = step(name, velocity_dependent)
    col_x = f(Poly([1]), Poly([0]), y, a)
    col_v = f(Poly([0]), Poly([1]), y, a)
    return [[col_x[0], col_v[0]], [col_x[1], col_v[1]]]


def _bounded(m, y, tol=1e-9):
    """Power-bounded at y: eigenvalues in the unit disk, none repeated on the circle."""
    lam = np.linalg.eigvals(np.array([[m[0][0](y), m[0][1](y)], [m[1][0](y), m[1][1](y)]]))
    if max(abs(lam)) > 1 + tol:
        return False
    on_circle = abs(abs(lam) - 1) <= tol
    return not (on_circle.all() and abs(lam[0] - lam[1]) <= 1e-6)


def limit(name, test):
    """The largest y* with the method stable for every 0 < y < y*: 0.0 when it is unstable
    for every y, inf when stable for every y."""
    m = step_matrix(name, test)
    t = m[0][0] + m[1][1]
    d = m[0][0] * m[1][1] - m[0][1] * m[1][0]
    candidates = sorted(set((d - 1).positive_roots() + (1 - t + d).positive_roots() + (1 + t + d).positive_roots()))
    edges = [0.0] + candidates
    for i in range(len(edges)):
        lo = edges[i]
        hi = edges[i + 1] if i + 1 < len(edges) else (lo * 2 if lo > 0 else 1.0)
        if not _bounded(m, 0.5 * (lo + hi)):
            return lo
    return float("inf")


# --- the checks ---------------------------------------------------------------------------------

METHODS = ["euler", "semi_implicit_euler", "momentum", "midpoint", "rk4", "velocity_verlet", "adaptive_euler"]


@pytest.fixture(scope="module")
def stability(plain_study):
    with h5py.File(plain_study, "r") as f:
        g = f["stability"]
        limits = g["limits"][()]
        regions = {name: g["regions"][name][()] for name in g["regions"]}
        yield {"limits": limits, "re": g["region_re"][()], "im": g["region_im"][()], "regions": regions}


def file_row(stability, name, test):
    rows = [r for r in stability["limits"]
            if r["integrator"].decode() == name and r["test"].decode() == test]
    assert len(rows) == 1, (name, test)
    return rows[0]


@pytest.mark.parametrize("test", ["oscillator", "decay"])
@pytest.mark.parametrize("name", METHODS)
def test_limits_match_the_symbolic_steps(stability, name, test):
    y = limit(name, test)
    r = file_row(stability, name, test)
    if y == 0.0:
        assert r["unstable_for_all_dt"] == 1 and np.isnan(r["theory"])
    elif np.isinf(y):
        assert r["unconditionally_stable"] == 1 and np.isnan(r["theory"])
    else:
        assert r["unstable_for_all_dt"] == 0 and r["unconditionally_stable"] == 0
        assert r["theory"] == pytest.approx(y, rel=1e-9), (name, test)
        assert r["measured"] == pytest.approx(y, rel=0.01), (name, test)


def test_published_values_symbolically():
    assert limit("rk4", "oscillator") == pytest.approx(2 * np.sqrt(2), rel=1e-12)
    assert limit("rk4", "decay") == pytest.approx(2.785293563405282, rel=1e-12)
    for name in ("semi_implicit_euler", "momentum", "velocity_verlet"):
        assert limit(name, "oscillator") == pytest.approx(2.0, rel=1e-12)
    assert limit("euler", "oscillator") == 0.0 and limit("midpoint", "oscillator") == 0.0
    assert limit("adaptive_euler", "decay") == pytest.approx(4.0, rel=1e-12)
    # det M - 1 on the oscillator: y^2 for explicit Euler, y^4/4 for midpoint (growth at
    # every dt); exactly 0 for the symplectic methods.
    det = {n: (lambda m: m[0][0] * m[1][1] - m[0][1] * m[1][0] - 1)(step_matrix(n, "oscillator")) for n in STEPS}
    assert det["euler"].c == [0, 0, 1]
    assert det["midpoint"].c == [0, 0, 0, 0, Fraction(1, 4)]
    assert det["semi_implicit_euler"].is_zero() and det["momentum"].is_zero()


def test_rk_oscillator_determinant_is_the_stability_function():
    """For the Runge-Kutta methods the eigenvalues of M on the oscillator are R(+-iy), so
    det M(y) = |R(iy)|^2 (R the truncated exponential series)."""
    ys = np.linspace(0.1, 3.0, 7)
    for name, order in (("euler", 1), ("midpoint", 2), ("rk4", 4)):
        m = step_matrix(name, "oscillator")
        d = m[0][0] * m[1][1] - m[0][1] * m[1][0]
        r = np.polynomial.Polynomial([1.0 / factorial(k) for k in range(order + 1)])
        assert np.allclose(d(ys), abs(r(1j * ys)) ** 2, rtol=1e-12), name


@pytest.mark.parametrize("name", METHODS)
def test_regions_match_the_steps_on_the_complex_damper(stability, name):
    """The same step code on complex numbers, a(x, v) = z v, dt = 1, from v = 1: R(z)."""
    zr, zi = np.meshgrid(stability["re"], stability["im"])
    z = zr + 1j * zi
    _, v1 = step(name, True)(np.zeros_like(z), np.ones_like(z), 1.0, lambda x, v: z * v)
    grid = stability["regions"][name]
    assert grid.shape == z.shape
    # The regions are stored as float32 (a figure's resolution): equal to float32 rounding.
    assert np.allclose(grid, abs(v1), rtol=2 ** -23, atol=1e-14), name


def test_the_command_prints_the_files_limits(stepbench, stability):
    """`stepbench stability --json`: one record per integrator and test, null where a value
    does not apply, the same figures as the study file's /stability/limits."""
    out = json.loads(subprocess.run([stepbench, "stability", "--json"], check=True, capture_output=True,
                                    text=True).stdout)
    assert len(out) == len(stability["limits"]) == 2 * len(stability["regions"])
    for rec in out:
        r = file_row(stability, rec["integrator"], rec["test"])
        for key in ("theory", "measured"):
            if np.isnan(r[key]):
                assert rec[key] is None, (rec, key)
            else:
                assert rec[key] == pytest.approx(r[key], rel=1e-12), (rec, key)
        assert rec["unstable_for_all_dt"] == bool(r["unstable_for_all_dt"])
        assert rec["unconditionally_stable"] == bool(r["unconditionally_stable"])
        if rec["unstable_for_all_dt"] or rec["unconditionally_stable"]:
            assert rec["theory"] is None and rec["measured"] is None
    table = subprocess.run([stepbench, "stability"], check=True, capture_output=True, text=True).stdout
    rows = {tuple(line.split()[:2]): line for line in table.splitlines() if len(line.split()) > 2}
    assert "2.828427" in rows[("rk4", "oscillator")] and "2.785294" in rows[("rk4", "decay")]
    assert "unstable" in rows[("euler", "oscillator")] and "uncond." in rows[("implicit_euler", "decay")]
