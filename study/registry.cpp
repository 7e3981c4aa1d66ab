#include "core/registry.hpp"

#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/drive.hpp"
#include "integrators/all.hpp"
#include "problems/all.hpp"

namespace stepbench {
namespace {

template <class Vec>
std::vector<double> flatten(const Vec& x, const Vec& v) {
  std::vector<double> y(x.data(), x.data() + x.size());
  y.insert(y.end(), v.data(), v.data() + v.size());
  return y;
}

template <problem P>
class problem_model final : public problem_instance {
  using vec = typename P::vec;
  P p_;

  vec unflatten(std::span<const double> y, int offset) const {
    vec out(P::dim);
    for (int i = 0; i < P::dim; ++i) out[i] = y[offset + i];
    return out;
  }

 public:
  std::string_view name() const override { return P::name; }
  std::string_view description() const override { return P::description; }
  int dim() const override { return P::dim; }
  std::string_view position_unit() const override { return P::position_unit; }

  std::vector<param_value> params() const override {
    std::vector<param_value> out;
    for (const auto& q : P::parameters())
      out.push_back({std::string(q.name), std::string(q.unit), std::string(q.description), p_.*q.member});
    return out;
  }
  void set(std::string_view param, double value) override {
    for (const auto& q : P::parameters())
      if (q.name == param) {
        p_.*q.member = value;
        return;
      }
    std::vector<std::string_view> known;
    for (const auto& q : P::parameters()) known.push_back(q.name);
    throw std::invalid_argument(
        fmt::format("unknown parameter '{}' for problem {} (known: {})", param, P::name, fmt::join(known, ", ")));
  }
  std::string validate() const override { return p_.validate(); }
  double horizon() const override { return p_.horizon(); }
  bool has_closed_form() const override { return stepbench::has_closed_form<P>; }
  bool has_energy() const override { return stepbench::has_energy<P>; }

  std::vector<double> exact(double t) const override {
    if constexpr (stepbench::has_closed_form<P>) {
      const auto s = p_.exact(t);
      return flatten(s.x, s.v);
    } else {
      throw std::logic_error(fmt::format("problem {} has no closed form", P::name));
    }
  }
  double energy(std::span<const double> y) const override {
    if constexpr (stepbench::has_energy<P>)
      return p_.energy(unflatten(y, 0), unflatten(y, P::dim));
    else
      return std::numeric_limits<double>::quiet_NaN();
  }
  std::vector<double> initial() const override {
    const auto s = p_.initial();
    return flatten(s.x, s.v);
  }

  ode_system ode() const override {
    ode_system sys;
    sys.n = 2 * P::dim;
    sys.y0 = initial();
    sys.rhs = [p = p_, inv_mass = 1.0 / p_.mass()](double t, std::span<const double> y, std::span<double> dydt) {
      first_order_rhs(p, inv_mass, t, y.data(), dydt.data());
    };
    return sys;
  }

  run_result run(std::string_view integrator_name, double dt, double horizon,
                 std::span<const long> record_steps) const override {
    find_integrator(integrator_name);  // throws for an unknown name
    run_result out;
    for_each_type(all_integrators{}, [&]<class I>() {
      if (I::name != integrator_name) return;
      const auto r = drive(p_, I{}, dt, horizon, record_steps);
      out.steps = r.steps;
      out.force_evals = r.force_evals;
      out.non_finite = r.non_finite;
      out.position.assign(r.final_state.x.data(), r.final_state.x.data() + P::dim);
      out.velocity.assign(r.final_state.v.data(), r.final_state.v.data() + P::dim);
      out.sample_t = r.sample_t;
      for (const auto& s : r.samples) out.sample_y.push_back(flatten(s.x, s.v));
    });
    out.problem = P::name;
    out.integrator = std::string(integrator_name);
    out.dt = dt;
    out.horizon = horizon;
    out.steps_planned = steps_for(horizon, dt);
    return out;
  }

  std::unique_ptr<problem_instance> clone() const override { return std::make_unique<problem_model>(*this); }
};

}  // namespace

std::vector<std::string> problem_names() {
  std::vector<std::string> names;
  for_each_type(all_problems{}, [&]<class P>() { names.emplace_back(P::name); });
  return names;
}

std::unique_ptr<problem_instance> make_problem(std::string_view name) {
  std::unique_ptr<problem_instance> out;
  for_each_type(all_problems{}, [&]<class P>() {
    if (P::name == name) out = std::make_unique<problem_model<P>>();
  });
  if (!out)
    throw std::invalid_argument(
        fmt::format("unknown problem '{}' (known: {})", name, fmt::join(problem_names(), ", ")));
  return out;
}

std::vector<integrator_info> integrators() {
  std::vector<integrator_info> out;
  for_each_type(all_integrators{},
                [&]<class I>() { out.push_back({std::string(I::name), std::string(I::description), I::order}); });
  return out;
}

const integrator_info& find_integrator(std::string_view name) {
  static const std::vector<integrator_info> all = integrators();
  for (const auto& i : all)
    if (i.name == name) return i;
  std::vector<std::string> known;
  for (const auto& i : all) known.push_back(i.name);
  throw std::invalid_argument(fmt::format("unknown integrator '{}' (known: {})", name, fmt::join(known, ", ")));
}

}  // namespace stepbench
