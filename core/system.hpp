#pragma once
// The problem as the integrators see it during one run: the force model with every
// evaluation counted, 1 / m computed once, the force Jacobians (the problem's own, or
// forward differences), and the counters of the work an implicit method does.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/concepts.hpp"

namespace stepbench {

namespace detail {
template <problem P>
struct jacobian_type {
  using type = Eigen::Matrix<double, P::vec::RowsAtCompileTime, P::vec::RowsAtCompileTime>;
};
template <problem P>
requires has_jacobian<P>
struct jacobian_type<P> {
  using type = typename P::jacobian_matrix;
};
}  // namespace detail

template <problem P>
struct counted_system {
  using vec = typename P::vec;
  using jacobian_matrix = typename detail::jacobian_type<P>::type;
  static constexpr bool force_depends_on_velocity = P::force_depends_on_velocity;

  const P& problem;
  double inv_mass = 1.0 / problem.mass();
  mutable work_counters work{};

  explicit counted_system(const P& p) : problem(p) {
    if constexpr (!has_jacobian<P> && vec::RowsAtCompileTime == Eigen::Dynamic)
      for (vec* w : {&fd_f0, &fd_y, &fd_f1}) w->resize(p.dim());
  }

  int dim() const { return problem.dim(); }
  double mass() const { return problem.mass(); }
  double inverse_mass() const { return inv_mass; }
  void force(double t, const vec& x, const vec& v, vec& f) const {
    ++work.force_evals;
    problem.force(t, x, v, f);
  }
  // The smooth part of the force and the friction cone, where the problem declares its
  // friction set-valued (has_set_valued_friction); counted like any force evaluation.
  void smooth_force(double t, const vec& x, const vec& v, vec& f) const requires has_set_valued_friction<P> {
    ++work.force_evals;
    problem.smooth_force(t, x, v, f);
  }
  friction_limits friction(double t, const vec& x) const requires has_set_valued_friction<P> {
    return problem.friction(t, x);
  }

  // A zeroed Jacobian of the right shape (workspace for the implicit methods).
  jacobian_matrix make_jacobian() const {
    if constexpr (has_jacobian<P>)
      return problem.make_jacobian();
    else
      return jacobian_matrix::Zero(dim(), dim());
  }

  // dF/dx and dF/dv at (t, x, v). Without analytic Jacobians: one-sided differences
  // with the step sqrt(eps) max(|y_j|, 1) (Dennis & Schnabel, Numerical Methods for
  // Unconstrained Optimization, sec. 5.4), 1 + dim (+ dim with a velocity-dependent
  // force) evaluations, counted like any other.
  void jacobian(double t, const vec& x, const vec& v, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    ++work.jacobian_evals;
    if constexpr (has_jacobian<P>) {
      problem.jacobian(t, x, v, dfdx, dfdv);
    } else {
      vec &f0 = fd_f0, &y = fd_y, &f1 = fd_f1;
      force(t, x, v, f0);
      // dF/dz for z = x or v: `force_at(y)` evaluates F into f1 with y in z's place.
      const auto differences = [&](const vec& z, jacobian_matrix& dfdz, auto&& force_at) {
        const double root_eps = std::sqrt(std::numeric_limits<double>::epsilon());
        y = z;
        for (int j = 0; j < dim(); ++j) {
          const double h = root_eps * std::max(std::abs(z[j]), 1.0);
          y[j] = z[j] + h;
          force_at(y);
          dfdz.col(j) = (f1 - f0) / (y[j] - z[j]);  // the step as represented, not as intended
          y[j] = z[j];
        }
      };
      differences(x, dfdx, [&](const vec& xj) { force(t, xj, v, f1); });
      if constexpr (force_depends_on_velocity)
        differences(v, dfdv, [&](const vec& vj) { force(t, x, vj, f1); });
      else
        dfdv.setZero();
    }
  }

 private:
  mutable vec fd_f0, fd_y, fd_f1;  // forward-difference workspace, sized once
};

}  // namespace stepbench
