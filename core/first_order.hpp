#pragma once
// y' = [v; F / m] for first-order solvers (the references, the first-order peers), with
// the same arithmetic as the step loop: the force model times 1 / m computed once. It
// keeps its own x, v, F workspace (sized once), so a call allocates nothing.
#include <Eigen/Core>

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

// The problem as a reference solver sees it (type erasure at the edge: the solvers call
// the right-hand side through std::function).
template <problem P>
ode_system make_ode_system(const P& p) {
  ode_system sys;
  sys.n = 2 * p.dim();
  const auto s0 = p.initial();
  sys.y0.assign(s0.x.data(), s0.x.data() + s0.x.size());
  sys.y0.insert(sys.y0.end(), s0.v.data(), s0.v.data() + s0.v.size());
  sys.rhs = [f = first_order_form<P>(p)](double t, std::span<const double> y, std::span<double> dydt) {
    f(t, y.data(), dydt.data());
  };
  return sys;
}

}  // namespace stepbench
