#pragma once
// y' = [v; F / m] for first-order solvers (the references, the first-order peers), with
// the same arithmetic as the step loop: the force model times 1 / m computed once. It
// keeps its own x, v, F workspace (sized once), so a call allocates nothing.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/band_matrix.hpp"
#include "core/concepts.hpp"
#include "references/reference.hpp"

namespace stepbench {

template <problem P>
struct first_order_form {
  using vec = typename P::vec;
  P problem;
  double inv_mass = 1.0 / problem.mass();
  mutable vec x = vec::Zero(problem.dim()), v = x, f = x;

  explicit first_order_form(const P& p) : problem(p) {}
  int size() const { return 2 * problem.dim(); }
  void operator()(double t, const double* y, double* dydt) const {
    const int d = problem.dim();
    x = Eigen::Map<const vec>(y, d);
    v = Eigen::Map<const vec>(y + d, d);
    problem.force(t, x, v, f);
    Eigen::Map<vec>(dydt, d) = v;
    Eigen::Map<vec>(dydt + d, d) = f * inv_mass;
  }
};

// Every stored entry of a Jacobian: f(i, j, value).
template <int N, int Options, int MaxRows, int MaxCols, class F>
void for_each_entry(const Eigen::Matrix<double, N, N, Options, MaxRows, MaxCols>& m, F&& f) {
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = 0; i < m.rows(); ++i) f(static_cast<int>(i), static_cast<int>(j), m(i, j));
}
template <class F>
void for_each_entry(const band_matrix& m, F&& f) {
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = std::max<Eigen::Index>(0, j - m.ku()); i <= std::min(m.rows() - 1, j + m.kl()); ++i)
      f(static_cast<int>(i), static_cast<int>(j), m(i, j));
}
inline int coupling_bandwidth(const band_matrix& m) { return static_cast<int>(std::max(m.kl(), m.ku())); }
template <class M>
int coupling_bandwidth(const M& m) {
  return static_cast<int>(m.rows()) - 1;
}

// The fastest natural frequency of the motion at the start, bounded by Gershgorin's
// theorem on dF/dx / m: w_max <= sqrt(max_i sum_j |dF_i/dx_j| / m) (rad/s). Problems with
// a Jacobian; 0 otherwise (nothing is known about their stiffness).
template <problem P>
double fastest_frequency(const P& p) {
  if constexpr (has_jacobian<P>) {
    auto dfdx = p.make_jacobian(), dfdv = p.make_jacobian();
    const auto s0 = p.initial();
    p.jacobian(0.0, s0.x, s0.v, dfdx, dfdv);
    std::vector<double> row_sum(static_cast<std::size_t>(p.dim()), 0.0);
    for_each_entry(dfdx, [&](int i, int, double v) { row_sum[static_cast<std::size_t>(i)] += std::abs(v); });
    return std::sqrt(*std::max_element(row_sum.begin(), row_sum.end()) / p.mass());
  } else {
    return 0.0;
  }
}

// The references' step budget between two of `outputs` output times. Stiffness: an
// explicit solver needs steps of about 1 / w_max (its stability limit is a few units of
// w h), so the budget is at least 20 w_max T / outputs (w_max: fastest_frequency), and
// at least 2e5. Size: a run may not spend more than 4e9 coordinate evaluations of f
// (13 evaluations a step for rk8pd), so a problem too large for a reference fails in
// bounded time (minutes at most) with the solver's message. At least 1000.
template <problem P>
long reference_step_budget(const P& p, int outputs) {
  const double stiff = 20.0 * fastest_frequency(p) * p.horizon() / outputs;
  const double size_cap = 4e9 / (13.0 * 2.0 * p.dim() * outputs);
  return static_cast<long>(std::max(1000.0, std::min(std::max(2e5, stiff), size_cap)));
}

// The problem as a reference solver sees it (type erasure at the edge: the solvers call
// the right-hand side through std::function), with its force Jacobian where it has one.
template <problem P>
ode_system make_ode_system(const P& p, int outputs = 32) {
  ode_system sys;
  sys.n = 2 * p.dim();
  const auto s0 = p.initial();
  sys.y0 = stacked(s0);
  sys.rhs = [f = first_order_form<P>(p)](double t, std::span<const double> y, std::span<double> dydt) {
    f(t, y.data(), dydt.data());
  };
  sys.max_steps_per_output = reference_step_budget(p, outputs);
  if constexpr (has_jacobian<P>) {
    sys.coupling_bandwidth = coupling_bandwidth(p.make_jacobian());
    struct workspace {
      typename P::jacobian_matrix dfdx, dfdv;
      typename P::vec x, v;
    };
    auto w = std::make_shared<workspace>(workspace{p.make_jacobian(), p.make_jacobian(), s0.x, s0.v});
    sys.force_jacobian = [p, w](double t, std::span<const double> y, const ode_system::jacobian_entry& emit) {
      const int d = p.dim();
      const double im = 1.0 / p.mass();
      w->x = Eigen::Map<const typename P::vec>(y.data(), d);
      w->v = Eigen::Map<const typename P::vec>(y.data() + d, d);
      p.jacobian(t, w->x, w->v, w->dfdx, w->dfdv);
      for_each_entry(w->dfdx, [&](int i, int j, double kx) { emit(i, j, kx * im, w->dfdv(i, j) * im); });
    };
  }
  return sys;
}

}  // namespace stepbench
