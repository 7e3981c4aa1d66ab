#include "study/registry.hpp"

#include <limits>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/drive.hpp"
#include "core/first_order.hpp"
#include "core/type_list.hpp"
#include "integrators/all.hpp"
#include "peers/all.hpp"
#include "problems/all.hpp"

namespace stepbench {
namespace {

// Our integrators as registry entries: the same shape as a peer's (info, applies,
// prepare), so that every method is run and measured by the same code.
template <integrator I>
struct ours_fixed {
  static method_info info() {
    return {std::string(I::name), std::string(I::description), method_origin::ours, method_kind::fixed_step,
            static_cast<double>(I::order), I::traits, "stepbench"};
  }
  template <problem P>
  static constexpr bool applies = true;
  template <problem P>
  static auto prepare(const P& p, double dt, double horizon, std::span<const double> times, const run_limits&) {
    return [p, dt, horizon, plan = plan_records(horizon, dt, times)] { return drive(p, I{}, dt, horizon, plan); };
  }
};

template <adaptive_integrator I>
struct ours_adaptive {
  static method_info info() {
    return {std::string(I::name), std::string(I::description), method_origin::ours, method_kind::adaptive,
            static_cast<double>(I::order), I::traits, "stepbench"};
  }
  template <problem P>
  static constexpr bool applies = true;
  template <problem P>
  static auto prepare(const P& p, double tol, double horizon, std::span<const double> times,
                      const run_limits& limits) {
    // The budget in steps: the work budget over the coordinates and the method's force
    // evaluations a step.
    const long max_steps = limits.adaptive_steps(p.dim(), I::force_evals_per_step);
    return [p, tol, horizon, max_steps, t = std::vector<double>(times.begin(), times.end())] {
      return drive_adaptive(p, I(tol), horizon, t, max_steps);
    };
  }
};

template <class I>
struct entry_for;
template <class I>
  requires integrator<I>
struct entry_for<I> {
  using type = ours_fixed<I>;
};
template <class I>
  requires adaptive_integrator<I>
struct entry_for<I> {
  using type = ours_adaptive<I>;
};

// Calls f.template operator()<Entry>() for every method entry: ours, then the peers.
template <class F>
void for_each_method(F&& f) {
  for_each_type(all_integrators{}, [&]<class I>() { f.template operator()<typename entry_for<I>::type>(); });
  for_each_type(all_peers{}, [&]<class M>() { f.template operator()<M>(); });
}

template <class M>
const method_info& info_of() {
  static const method_info info = M::info();
  return info;
}

template <class Vec>
std::vector<double> flatten(const Vec& x, const Vec& v) {
  std::vector<double> y(x.data(), x.data() + x.size());
  y.insert(y.end(), v.data(), v.data() + v.size());
  return y;
}

template <class Vec>
run_result to_run_result(const drive_result<Vec>& r, double param, double horizon) {
  run_result out;
  out.param = param;
  out.horizon = horizon;
  out.steps = r.steps;
  out.rejected_steps = r.rejected_steps;
  out.work = r.work;
  out.non_finite = r.non_finite;
  out.failure = r.failure;
  out.skipped = r.over_budget;
  out.sample_t = r.sample_t;
  for (std::size_t j = 0; j < r.sample_t.size(); ++j) {
    const auto col = r.samples.col(static_cast<Eigen::Index>(j));
    out.sample_y.emplace_back(col.data(), col.data() + col.size());
  }
  out.final_y = flatten(r.final_state.x, r.final_state.v);
  return out;
}

[[noreturn]] void not_applicable(std::string_view method, std::string_view problem) {
  throw std::invalid_argument(fmt::format("method {} does not run on problem {}", method, problem));
}

template <problem P>
class problem_model final : public problem_instance {
  using vec = typename P::vec;
  P p_;

  vec unflatten(std::span<const double> y, int offset) const {
    vec out(p_.dim());
    for (int i = 0; i < p_.dim(); ++i) out[i] = y[offset + i];
    return out;
  }

  // Calls f.template operator()<M>() for the entry named `method` that applies to P.
  template <class F>
  void with_method(std::string_view method, F&& f) const {
    find_method(method);  // throws for an unknown name
    bool found = false;
    for_each_method([&]<class M>() {
      if (found || info_of<M>().name != method) return;
      found = true;
      if constexpr (M::template applies<P>)
        f.template operator()<M>();
      else
        not_applicable(method, P::name);
    });
  }

 public:
  std::string_view name() const override { return P::name; }
  std::string_view description() const override { return P::description; }
  int dim() const override { return p_.dim(); }
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
  bool has_jacobian() const override { return stepbench::has_jacobian<P>; }

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
      return p_.energy(unflatten(y, 0), unflatten(y, p_.dim()));
    else
      return std::numeric_limits<double>::quiet_NaN();
  }
  std::vector<double> initial() const override {
    const auto s = p_.initial();
    return flatten(s.x, s.v);
  }
  ode_system ode() const override { return make_ode_system(p_); }

  std::vector<method_info> methods() const override {
    std::vector<method_info> out;
    for_each_method([&]<class M>() {
      if constexpr (M::template applies<P>) out.push_back(info_of<M>());
    });
    return out;
  }

  run_result run(std::string_view method, double param, double horizon, std::span<const double> times,
                 const run_limits& limits) const override {
    run_result out;
    with_method(method, [&]<class M>() {
      auto run_once = M::prepare(p_, param, horizon, times, limits);  // throws std::invalid_argument for bad times
      try {
        out = to_run_result(run_once(), param, horizon);
      } catch (const std::invalid_argument&) {
        throw;
      } catch (const std::exception& e) {
        // A solver error is the run's outcome, recorded with its reason; the study goes on.
        out = {};
        out.param = param;
        out.horizon = horizon;
        out.failure = e.what();
      }
    });
    return out;
  }

  std::function<double()> timed_run(std::string_view method, double param, double horizon,
                                    std::span<const double> times, const run_limits& limits) const override {
    std::function<double()> out;
    with_method(method, [&]<class M>() {
      out = [run_once = M::prepare(p_, param, horizon, times, limits)] { return run_once().final_state.x[0]; };
    });
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

const std::vector<method_info>& all_methods() {
  static const std::vector<method_info> all = [] {
    std::vector<method_info> out;
    for_each_method([&]<class M>() { out.push_back(info_of<M>()); });
    return out;
  }();
  return all;
}

std::vector<method_info> integrators() {
  std::vector<method_info> out;
  for (const auto& m : all_methods())
    if (m.origin == method_origin::ours) out.push_back(m);
  return out;
}

const method_info& find_method(std::string_view name) {
  for (const auto& m : all_methods())
    if (m.name == name) return m;
  std::vector<std::string> known;
  for (const auto& m : all_methods()) known.push_back(m.name);
  throw std::invalid_argument(fmt::format("unknown method '{}' (known: {})", name, fmt::join(known, ", ")));
}

}  // namespace stepbench
