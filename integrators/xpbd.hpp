#pragma once
// Extended position-based dynamics (XPBD) with small steps, what shipping engines step
// ropes, cloth and ragdolls with: Macklin, Mueller & Chentanez, "XPBD: Position-Based
// Simulation of Compliant Constrained Dynamics", MIG 2016 (the solve), and Macklin,
// Storey, Lu, Terdiman, Chentanez, Jeschke & Mueller, "Small Steps in Physics
// Simulation", SCA 2019 (Algorithm 1: many substeps, one constraint iteration each).
// A step of h (one substep) on the scene's constraint view (core/constraints.hpp):
//   v += h a_ext;  x_prev = x;  x += h v                     (predict, external forces)
//   lambda = 0; for each constraint j in turn (one Gauss-Seidel pass, `iterations` times):
//     dlambda = (-C_j - a~ lambda_j - g_j grad C_j (x - x_prev))
//               / ((1 + g_j) sum_i w_i |grad_i C_j|^2 + a~),            (XPBD eq. 18, 26)
//     x_i += w_i grad_i C_j dlambda,  lambda_j += dlambda,
//   with a~ = alpha / h^2 (alpha the compliance) and g_j = a~ beta~ / h = alpha beta / h
//   (beta~ = h^2 beta, beta the damping);
//   v = (x - x_prev) / h.
// For a rigid link (alpha = 0) the pass projects onto the constraint; for one linear
// constraint and one iteration the pass solves the backward Euler equation exactly
// (tests/test_xpbd.cpp), with or without the damper.
//
// `xpbd` takes one iteration a step and is stepped over the dt ladder: at a 60 Hz frame,
// halving dt doubles the substeps. `xpbd_iterations` is the alternative the Small Steps
// paper argues against: one step of h with 10 iterations accumulating lambda, the same
// counted work as `xpbd` at h / 10. A pass over the constraints visits each spring once,
// as a force evaluation does, and is counted as one (the external acceleration is constant).
#include <string>

#include "core/constraints.hpp"
#include "core/method.hpp"

namespace stepbench {

// One XPBD step of h on a particle system, allocation-free (lambda sized once).
struct xpbd_solver {
  particle_system s;
  Eigen::Matrix3Xd x_prev;
  Eigen::VectorXd lambda;
  long passes = 0;  // constraint passes: the counted work

  explicit xpbd_solver(particle_system system)
      : s(std::move(system)),
        x_prev(s.x),
        lambda(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(s.constraints.size()))) {}

  void step(double h, int iterations) {
    const Eigen::Index n = s.x.cols();
    for (Eigen::Index i = 0; i < n; ++i)
      if (s.inverse_mass[i] > 0.0) s.v.col(i) += h * s.acceleration;
    x_prev = s.x;
    s.x += h * s.v;
    lambda.setZero();
    const double inv_h2 = 1.0 / (h * h);
    for (int it = 0; it < iterations; ++it, ++passes)
      for (std::size_t j = 0; j < s.constraints.size(); ++j)
        project(s.constraints[j], lambda[static_cast<Eigen::Index>(j)], h, inv_h2);
    s.v = (s.x - x_prev) * (1.0 / h);
  }

 private:
  void project(const distance_constraint& c, double& lambda_j, double h, double inv_h2) {
    const double wa = c.a < 0 ? 0.0 : s.inverse_mass[c.a], wb = s.inverse_mass[c.b];
    const Eigen::Vector3d pa = c.a < 0 ? c.anchor : Eigen::Vector3d(s.x.col(c.a));
    const Eigen::Vector3d d = s.x.col(c.b) - pa;
    const double len = d.norm();
    if (!(len > 0.0) || wa + wb == 0.0) return;
    const Eigen::Vector3d n = d / len;  // grad_b C = n, grad_a C = -n
    const double alpha_tilde = c.compliance * inv_h2;
    const double gamma = c.compliance * c.damping / h;
    // grad C (x - x_prev): the constraint's rate times h.
    double moved = n.dot(s.x.col(c.b) - x_prev.col(c.b));
    if (c.a >= 0) moved -= n.dot(s.x.col(c.a) - x_prev.col(c.a));
    const double dlambda =
        (-(len - c.rest_length) - alpha_tilde * lambda_j - gamma * moved) / ((1.0 + gamma) * (wa + wb) + alpha_tilde);
    lambda_j += dlambda;
    s.x.col(c.b) += (wb * dlambda) * n;
    if (c.a >= 0) s.x.col(c.a) -= (wa * dlambda) * n;
  }
};

// The method on the fixed-step loop (core/step_adapter.hpp's descriptor and adapter
// shape): the solver on the problem's constraint view, the state read back in the
// problem's coordinates.
template <int Iterations>
struct xpbd_method {
  static method_info describe() {
    const bool small_steps = Iterations == 1;
    return {.name = small_steps ? "xpbd" : "xpbd_iterations",
            // What `stepbench list` says of its behaviour on rigid links, as far as it was
            // tried: 1 to 500 substeps a 60 Hz frame for 10 s, energy checked at every step
            // (tests/test_xpbd.cpp: rigid_*_is_stable_at_every_substep_count).
            .description = small_steps ? "XPBD small steps: one constraint pass a substep (Macklin et al. 2019); "
                                         "rigid links: stable, energy never above its start, at every substep "
                                         "count tried (1 to 500 a frame)"
                                       : "XPBD: " + std::to_string(Iterations) +
                                             " constraint passes a step, lambda accumulated (Macklin et al. 2016); "
                                             "the design Small Steps argues against; rigid links: stable, energy "
                                             "never above its start, at every step count tried (1 to 500 a frame)",
            .origin = method_origin::ours,
            .declared_order = 1.0,
            .evals_per_step = static_cast<double>(Iterations),
            .traits = {.small_steps = small_steps},
            .library = "stepbench"};
  }
  template <problem P>
  static constexpr bool applies = has_constraint_view<P>;

  template <problem P>
  struct adapter {
    const P& p;
    xpbd_solver solver;
    explicit adapter(const P& problem)
        : p(problem), solver(problem.particles(problem.initial().x, problem.initial().v)) {}
    void step(double, double h) { solver.step(h, Iterations); }
    // Called at each recorded sample and at the end: the links are checked there, not in
    // the step (which is what is timed).
    template <class Vec>
    void state_into(Vec& x, Vec& v) const {
      p.from_particles(solver.s, x, v);
      worst_violation = std::max(worst_violation, stepbench::constraint_violation(solver.s));
    }
    // The positions the particles draw, [X; V] (run_record's drawn_samples): on a problem
    // that observes its positions (n_pendulum's bobs), the error is measured on these.
    void drawn_into(std::vector<double>& y) const requires has_drawn_particles<P> {
      Eigen::VectorXd pos(p.observed_dim()), vel(p.observed_dim());
      p.observe_particles(solver.s, pos, vel);
      y = stacked(pos, vel);
    }
    long force_evals() const { return solver.passes; }
    double constraint_violation() const { return worst_violation; }
    mutable double worst_violation = 0.0;
  };
};

using xpbd = xpbd_method<1>;
// One registered iteration count (the registry's names are unique); the Small Steps
// experiment (study/challenge.cpp) sweeps the count on xpbd_solver directly.
using xpbd_iterations = xpbd_method<10>;

}  // namespace stepbench
