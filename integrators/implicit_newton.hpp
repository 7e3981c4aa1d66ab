#pragma once
// The nonlinear solve shared by the implicit methods (not a method itself): the
// backward-Euler relations over a step of length h that ends at t1,
//   x1 = x0 + h v1,   m (v1 - v0) = h F(t1, x1, v1),
// solved for v1 by Newton's method on
//   r(v1) = m (v1 - v0) - h F(t1, x0 + h v1, v1),   dr/dv1 = m I - h dF/dv - h^2 dF/dx.
// The factored Newton matrix is kept across iterations and steps while the iteration
// contracts quickly and the step size is unchanged (modified Newton, as SUNDIALS'
// nonlinear solvers do: CVODE user guide, sec. 2.1); the Jacobian is re-evaluated at
// the current iterate when the residual falls by less than a factor 4 in an iteration,
// when a step does not descend, or when h changes. A step that does not reduce the residual is halved
// (backtracking on |r|, Dennis & Schnabel, Numerical Methods for Unconstrained
// Optimization, sec. 6.3), which keeps the iteration on track when a large step makes
// the force strongly nonlinear (a pendulum near the top). Converged when the residual
// is at the round-off level of the equation's terms (1e-12 relative to m |v1| + h |F|)
// or when an accepted update changes v1 by less than 1e-12 relative (the residual can
// stall above the first test where F sums large spring forces that cancel), or when
// the residual is below 1e-290 (a state decayed into subnormal numbers).
//
// For a large step the relations may have several solutions (a pendulum near the top:
// v1 - v0 + h (g/L) sin(x0 + h v1) = 0), and Newton from v0 may fail or find the wrong
// one. The right one is the solution that continues from h = 0, so a failed solve is
// retried by continuation in the step: solve for h/2 (recursively, up to 2^-8 h), then
// start h from the linear extrapolation v0 + 2 (v1(h/2) - v0). Where that path ends in
// a fold (the root it follows merges with another as h grows), the explicit Euler
// predictor v0 + (h/m) F(t0, x0, v0) and rest (v1 = 0) are tried last. The step is still
// one backward-Euler step of h; only the starting guess changes, and its work is
// counted.
// Everything is counted: force and Jacobian evaluations by the system, and here the
// Newton iterations and the linear solves.
#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "core/concepts.hpp"
#include "core/linear_solve.hpp"

namespace stepbench {

template <class Sys>
struct backward_euler_newton {
  using Vec = typename Sys::vec;
  using jacobian = typename Sys::jacobian_matrix;
  static constexpr int max_iterations = 50;
  static constexpr double residual_tol = 1e-12;
  static constexpr double update_tol = 1e-12;
  static constexpr double subnormal_floor = 1e-290;
  static constexpr int max_continuation_depth = 8;

  jacobian dfdx, dfdv;
  newton_matrix<jacobian> a;
  double h_factored = 0.0;  // the h of the factored matrix; 0: none
  Vec x1, v1, f, r, delta, v_try, x_try, f_try, r_try, v_pred;

  void resize(const Sys& sys, const Vec& like) {
    dfdx = sys.make_jacobian();
    dfdv = sys.make_jacobian();
    a.resize(dfdx);
    size_like(like, x1, v1, f, r, delta, v_try, x_try, f_try, r_try, v_pred);
  }

  // Solves from the predictor v1 = v_guess (falling back on continuation in h); the
  // solution is left in x1, v1 (and f = F(t1, x1, v1)). Returns false when no solution
  // is found.
  bool solve(const Sys& sys, double t1, double h, const Vec& x0, const Vec& v0, const Vec& v_guess, int depth = 0) {
    if (newton(sys, t1, h, x0, v0, v_guess)) return true;
    if (depth >= max_continuation_depth) return false;
    if (solve(sys, t1 - 0.5 * h, 0.5 * h, x0, v0, v0, depth + 1)) {
      v_pred = 2.0 * v1 - v0;
      if (newton(sys, t1, h, x0, v0, v_pred)) return true;
    }
    if (depth > 0) return false;
    sys.force(t1 - h, x0, v0, f);
    v_pred = v0 + (h / sys.mass()) * f;
    if (newton(sys, t1, h, x0, v0, v_pred)) return true;
    v_pred.setZero();
    return newton(sys, t1, h, x0, v0, v_pred);
  }

 private:
  bool newton(const Sys& sys, double t1, double h, const Vec& x0, const Vec& v0, const Vec& v_guess) {
    const double m = sys.mass();
    v1 = v_guess;
    x1 = x0 + h * v1;
    sys.force(t1, x1, v1, f);
    r = m * (v1 - v0) - h * f;
    double r_norm = r.template lpNorm<Eigen::Infinity>();
    bool refresh = h != h_factored;
    for (int k = 0; k < max_iterations; ++k) {
      if (!std::isfinite(r_norm)) return false;
      if (r_norm <= residual_tol * scale(m, h) + subnormal_floor) return true;
      const bool fresh = refresh;
      if (refresh) {
        sys.jacobian(t1, x1, v1, dfdx, dfdv);
        h_factored = 0.0;
        if (!a.factorize(m, -h, dfdv, -h * h, dfdx)) return false;
        h_factored = h;
        refresh = false;
      }
      delta = -r;
      a.solve_in_place(delta);
      ++sys.work.linear_solves;
      ++sys.work.newton_iterations;
      // The full step first, halved while the residual does not fall; with a stale
      // Jacobian, refresh it before shortening the step.
      double lambda = 1.0, r_try_norm = std::numeric_limits<double>::infinity();
      bool decreased = false;
      for (int halvings = 0; halvings < 10; ++halvings, lambda *= 0.5) {
        v_try = v1 + lambda * delta;
        x_try = x0 + h * v_try;
        sys.force(t1, x_try, v_try, f_try);
        r_try = m * (v_try - v0) - h * f_try;
        r_try_norm = r_try.template lpNorm<Eigen::Infinity>();
        decreased = r_try_norm < (1.0 - 1e-4 * lambda) * r_norm;
        if (decreased || !fresh) break;
      }
      if (!decreased) {
        // A correction at round-off: the residual is at its floor. (x1 = x0 + h v1 cancels
        // when h^2 |dF/dx| >> m, a stiff spring at a large step, and leaves a rounding
        // floor in the residual that the scale of the first test does not include.)
        if (delta.template lpNorm<Eigen::Infinity>() <= update_tol * v1.template lpNorm<Eigen::Infinity>()) return true;
        if (fresh) return false;  // no descent even with a fresh Jacobian
        refresh = true;           // retry from the same iterate with a fresh Jacobian
        continue;
      }
      // Slow contraction: refresh the Jacobian at the new iterate.
      refresh = r_try_norm > 0.25 * r_norm;
      v1.swap(v_try);
      x1.swap(x_try);
      f.swap(f_try);
      r.swap(r_try);
      r_norm = r_try_norm;
      if (lambda * delta.template lpNorm<Eigen::Infinity>() <= update_tol * v1.template lpNorm<Eigen::Infinity>())
        return true;
    }
    return r_norm <= residual_tol * scale(m, h) + subnormal_floor;
  }

  double scale(double m, double h) const {
    return m * v1.template lpNorm<Eigen::Infinity>() + h * f.template lpNorm<Eigen::Infinity>() +
           std::numeric_limits<double>::min();
  }
};

}  // namespace stepbench
