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
// when a step does not descend, or when h changes. A step that does not reduce the
// residual is halved (backtracking on |r|, Dennis & Schnabel, Numerical Methods for
// Unconstrained Optimization, sec. 6.3), which keeps the iteration on track when a large
// step makes the force strongly nonlinear (a pendulum near the top).
// Solved to round-off, so that the error a study reports is the method's and not the
// solver's: iterated until the Newton update is a few ulps of the velocity terms
// (4 eps (|v1| + |v0| + h |F| / m); that last update applied), or until the update stops
// decreasing once it is small (the rounding floor of the residual: x1 = x0 + h v1
// cancels when h^2 |dF/dx| >> m, a stiff spring at a large step), or until the residual
// is subnormal (a decayed state), or, where no iterate reduces the residual, until the
// update moves x1 by a few of its ulps (a motion decayed about an equilibrium away from
// the origin: position_floor). No tolerance relative to the residual's size: a test
// like |r| < 1e-12 (m |v1| + h |F|) is met by small steps after one update, and its error
// accumulates over the steps.
//
// For a large step the relations may have several solutions (a pendulum near the top:
// v1 - v0 + h (g/L) sin(x0 + h v1) = 0), and Newton from v0 may fail or find the wrong
// one. The right one continues from h = 0, so a failed solve is retried by continuation
// in the step: solve for h/2 (recursively, up to 2^-8 h), then start h from the linear
// extrapolation v0 + 2 (v1(h/2) - v0). Where that path ends in a fold (its root merges
// with another as h grows), the explicit Euler predictor v0 + (h/m) F(t0, x0, v0), the
// same with the force at the predicted end, v0 + (h/m) F(t1, x0 + h v0, v0), and rest
// (v1 = 0) are tried last. The step is still one backward-Euler step of h; only the
// starting guess changes, and its work is counted.
// Coulomb friction, where the problem declares it set-valued (has_set_valued_friction,
// core/concepts.hpp), is resolved by projection onto the friction cone, as a game
// engine's solver clamps the friction impulse (solve_with_friction): the step with the
// smooth forces and kinetic friction against the motion while that keeps its direction;
// else the friction that ends the step at rest, if within mu_s |F_n|; else the slide the
// other way. Each case is one Newton solve of the relations above, with the smooth force
// plus a constant friction force, so the step is still implicit in every smooth force.
// Everything is counted: force and Jacobian evaluations by the system, and here the
// Newton iterations and the linear solves.
#include <Eigen/Core>
#include <algorithm>
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
  // Converged: an update of at most round_off times the velocity terms (a few ulps).
  static constexpr double round_off = 4.0 * std::numeric_limits<double>::epsilon();
  // An update this small (relative) that stops decreasing, or that no longer reduces the
  // residual with a fresh Jacobian, is at the residual's rounding floor.
  static constexpr double floor_update = 1e-8;
  static constexpr double subnormal_floor = 1e-290;
  static constexpr int max_continuation_depth = 8;

  jacobian dfdx, dfdv;
  newton_matrix<jacobian> a;
  double h_factored = 0.0;  // the h of the factored matrix; 0: none
  Vec x1, v1, f, r, delta, v_try, x_try, f_try, r_try, v_pred;
  // While resolving friction: the force is the smooth force plus this constant friction.
  bool smooth_only = false;
  Vec f_friction;

  void resize(const Sys& sys, const Vec& like) {
    dfdx = sys.make_jacobian();
    dfdv = sys.make_jacobian();
    a.resize(dfdx);
    size_like(like, x1, v1, f, r, delta, v_try, x_try, f_try, r_try, v_pred, f_friction);
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
    eval_force(sys, t1 - h, x0, v0, f);
    v_pred = v0 + (h / sys.mass()) * f;
    if (newton(sys, t1, h, x0, v0, v_pred)) return true;
    // The explicit step's force at its predicted end (a step past a fold of the path from
    // h = 0 may still reach the root the end of the step sees).
    x_try = x0 + h * v0;
    eval_force(sys, t1, x_try, v0, f);
    v_pred = v0 + (h / sys.mass()) * f;
    if (newton(sys, t1, h, x0, v0, v_pred)) return true;
    v_pred.setZero();
    return newton(sys, t1, h, x0, v0, v_pred);
  }

  // A method's stage: solve() from v0, or with set-valued friction solve_with_friction(),
  // whose step ends at rest where v1 = rest_fraction v0.
  bool solve_stage(const Sys& sys, double t1, double h, const Vec& x0, const Vec& v0, double rest_fraction) {
    if constexpr (has_set_valued_friction<Sys>)
      return solve_with_friction(sys, t1, h, x0, v0, rest_fraction);
    else
      return solve(sys, t1, h, x0, v0, v0);
  }

  // One step's solve with Coulomb friction resolved by projection onto the friction cone
  // (see has_set_valued_friction): the unknown v1 ends the step at rest where
  // v1 = rest_fraction v0 (implicit Euler: 0; the midpoint rule's midpoint velocity,
  // whose step ends at 2 v1 - v0: one half). On return f is the force the step applied
  // (the smooth force plus the friction).
  bool solve_with_friction(const Sys& sys, double t1, double h, const Vec& x0, const Vec& v0,
                           double rest_fraction) requires has_set_valued_friction<Sys> {
    static_assert(Vec::RowsAtCompileTime == 1, "friction along the problem's one coordinate");
    struct smooth_force_scope {
      bool& on;
      explicit smooth_force_scope(bool& b) : on(b) { on = true; }
      ~smooth_force_scope() { on = false; }
    } scope(smooth_only);
    const double m = sys.mass(), v_rest = rest_fraction * v0[0];
    const friction_limits cone = sys.friction(t1, x0);
    // Sliding: kinetic friction against the motion, kept while the step keeps the direction.
    if (const double moving = v0[0] - v_rest; moving != 0.0) {
      const double dir = moving > 0.0 ? 1.0 : -1.0;
      f_friction[0] = -dir * cone.kinetic;
      if (solve(sys, t1, h, x0, v0, v0) && dir * (v1[0] - v_rest) >= 0.0) return true;  // f includes it
    }
    // At rest at the end of the step: the friction that holds it there, m (v1 - v0) / h
    // minus the smooth force, if the cone allows it.
    if (hold_at_rest(sys, t1, h, x0, v0, m, v_rest, cone.static_max)) return true;
    // Static friction cannot hold it: it slides the way the unbalanced force pushes, with
    // kinetic friction against it.
    const double dir = f_friction[0] < 0.0 ? 1.0 : -1.0;  // hold_at_rest left the friction it needed
    f_friction[0] = -dir * cone.kinetic;
    if (solve(sys, t1, h, x0, v0, v0) && dir * (v1[0] - v_rest) >= 0.0) return true;  // f includes it
    // Kinetic friction above the static limit (mu_k > mu_s) stops what static friction
    // could not hold: at rest, with the friction it needs (the exact motion's rest,
    // problems/exact/sliding_block.hpp).
    return hold_at_rest(sys, t1, h, x0, v0, m, v_rest, std::max(cone.static_max, cone.kinetic));
  }

 private:
  // The force the Newton iteration sees: the problem's, or while resolving friction the
  // smooth force plus the friction of the case being solved.
  void eval_force(const Sys& sys, double t, const Vec& x, const Vec& v, Vec& out) const {
    if constexpr (has_set_valued_friction<Sys>) {
      if (smooth_only) {
        sys.smooth_force(t, x, v, out);
        out += f_friction;
        return;
      }
    }
    sys.force(t, x, v, out);
  }
  // v1 at rest; true when the friction that needs is at most `limit`. Leaves the needed
  // friction in f_friction either way, and in f the smooth force plus it.
  bool hold_at_rest(const Sys& sys, double t1, double h, const Vec& x0, const Vec& v0, double m, double v_rest,
                    double limit) {
    v1[0] = v_rest;
    x1 = x0 + h * v1;
    sys.smooth_force(t1, x1, v1, f);
    f_friction[0] = m * (v_rest - v0[0]) / h - f[0];
    if (std::abs(f_friction[0]) > limit) return false;
    f += f_friction;
    return true;
  }

  bool newton(const Sys& sys, double t1, double h, const Vec& x0, const Vec& v0, const Vec& v_guess) {
    const double m = sys.mass();
    v1 = v_guess;
    x1 = x0 + h * v1;
    eval_force(sys, t1, x1, v1, f);
    r = m * (v1 - v0) - h * f;
    double r_norm = r.template lpNorm<Eigen::Infinity>();
    double last_update = std::numeric_limits<double>::infinity();
    bool refresh = h != h_factored;
    for (int k = 0; k < max_iterations; ++k) {
      if (!std::isfinite(r_norm)) return false;
      if (r_norm <= subnormal_floor) return true;
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
      const double update = delta.template lpNorm<Eigen::Infinity>(), scale = velocity_scale(m, h, v0);
      // At round-off: the update is a few ulps of the velocity terms. It is applied (with
      // the force at the result): left out, an update of one sign step after step would
      // add up over 10^4 steps to a bias far above round-off.
      if (update <= round_off * scale) {
        v1 += delta;
        x1 = x0 + h * v1;
        eval_force(sys, t1, x1, v1, f);
        return true;
      }
      // The update stopped decreasing once small: the rounding floor of the residual.
      if (update >= last_update && update <= floor_update * scale) return true;
      // The full step first, halved while the residual does not fall; with a stale
      // Jacobian, refresh it before shortening the step.
      double lambda = 1.0, r_try_norm = std::numeric_limits<double>::infinity();
      bool decreased = false;
      for (int halvings = 0; halvings < 10; ++halvings, lambda *= 0.5) {
        v_try = v1 + lambda * delta;
        x_try = x0 + h * v_try;
        eval_force(sys, t1, x_try, v_try, f_try);
        r_try = m * (v_try - v0) - h * f_try;
        r_try_norm = r_try.template lpNorm<Eigen::Infinity>();
        decreased = r_try_norm < (1.0 - 1e-4 * lambda) * r_norm;
        if (decreased || !fresh) break;
      }
      if (!decreased) {
        // No descent: converged if the update is at the residual's rounding floor (where
        // no matrix makes the residual fall); else, with a fresh Jacobian, no root from
        // here, and with a stale one, retry from the same iterate with a fresh one.
        if (update <= floor_update * scale || update <= position_floor(h)) return true;
        if (fresh) return false;
        refresh = true;
        continue;
      }
      // Slow contraction: refresh the Jacobian at the new iterate; not once the update is
      // down at the residual's rounding floor, where the residual no longer contracts
      // whatever the matrix (the chain's large spring forces cancel).
      refresh = r_try_norm > 0.25 * r_norm && update > floor_update * scale;
      v1.swap(v_try);
      x1.swap(x_try);
      f.swap(f_try);
      r.swap(r_try);
      r_norm = r_try_norm;
      last_update = update;  // the full Newton step: the distance to the root it estimates
    }
    return last_update <= floor_update * velocity_scale(m, h, v0) || last_update <= position_floor(h);
  }

  // The velocity update that moves x1 = x0 + h v1 by a few of x1's own ulps: below it the
  // residual is x1's rounding, whatever the velocities. A motion decayed about an
  // equilibrium away from the origin (a mass at rest on a spring at x = 1.5 m) has
  // velocities far below it, and the tests on the velocity terms alone would never pass.
  double position_floor(double h) const { return round_off * x1.template lpNorm<Eigen::Infinity>() / h; }

  // The size of the velocity terms of the equation, for the round-off tests.
  double velocity_scale(double m, double h, const Vec& v0) const {
    return v1.template lpNorm<Eigen::Infinity>() + v0.template lpNorm<Eigen::Infinity>() +
           (h / m) * f.template lpNorm<Eigen::Infinity>() + std::numeric_limits<double>::min();
  }
};

}  // namespace stepbench
