#pragma once
// The registry's type erasure: our integrators and the peers as method entries of one
// shape, and problem_model<P>, the problem_instance of a problem type. Included by
// study/registry.cpp (the method entries) and by the problem units CMake generates from
// study/problem_unit.cpp.in, one per problem, each with its own problem's header only
// (problem_model<P>, whose instantiations are most of the build: one problem a unit, so
// that they compile in parallel and in less memory, and an edit rebuilds one unit).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <charconv>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string_view>

#include "core/drive.hpp"
#include "core/first_order.hpp"
#include "core/game_loop.hpp"
#include "core/type_list.hpp"
#include "integrators/all.hpp"
#include "peers/all.hpp"
#include "study/registry.hpp"

namespace stepbench::registry_detail {

// Our integrators as registry entries: the same shape as a peer's (info, applies,
// prepare), so that every method is run and measured by the same code.
// What every one of our integrators declares (its name, description, order and
// capabilities), as a registry entry of the given kind.
template <class I>
constexpr double evals_per_step_of() {
  if constexpr (requires { I::force_evals_per_step; })
    return I::force_evals_per_step;
  else
    return std::numeric_limits<double>::quiet_NaN();
}
template <class I>
method_info ours_info(method_kind kind) {
  return {.name = std::string(I::name),
          .description = std::string(I::description),
          .origin = method_origin::ours,
          .kind = kind,
          .declared_order = static_cast<double>(I::order),
          .evals_per_step = evals_per_step_of<I>(),
          .traits = I::traits,
          .library = "stepbench"};
}

template <integrator I>
struct ours_fixed {
  static method_info info() { return ours_info<I>(method_kind::fixed_step); }
  template <problem P>
  static auto prepare(const P& p, double dt, double horizon, std::span<const double> times, const run_limits&) {
    return [p, dt, horizon, plan = plan_records(horizon, dt, times)] { return drive(p, I{}, dt, horizon, plan); };
  }
};

template <adaptive_integrator I>
struct ours_adaptive {
  static method_info info() { return ours_info<I>(method_kind::adaptive); }
  template <problem P>
  static auto prepare(const P& p, double tol, double horizon, std::span<const double> times, const run_limits& limits) {
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

// Our loops resolve contacts (core/drive.hpp); the peers' and the baseline's do not, so
// on a problem with contacts only our methods run (a library stepping through a ground
// plane would be measured falling through it).
template <class M>
inline constexpr bool is_ours = false;
template <class I>
inline constexpr bool is_ours<ours_fixed<I>> = true;
template <class I>
inline constexpr bool is_ours<ours_adaptive<I>> = true;
template <class M, class P>
inline constexpr bool runs_on = method_applies<M, P>() && (!has_contacts<P> || is_ours<M>);

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
  out.stop_reason = r.stop_reason;
  out.skipped = r.over_budget;
  out.sample_t = r.sample_t;
  for (std::size_t j = 0; j < r.sample_t.size(); ++j) {
    const auto col = r.samples.col(static_cast<Eigen::Index>(j));
    out.sample_y.emplace_back(col.data(), col.data() + col.size());
  }
  out.final_y = flatten(r.final_state.x, r.final_state.v);
  out.contacts = r.contacts;
  out.tunnelled = r.tunnelled;
  out.max_penetration = r.max_penetration;
  out.contact_times = r.contact_times;
  for (std::size_t k = 0; k < r.contact_times.size() && r.contact_x.size() > 0; ++k) {
    const auto col = r.contact_x.col(static_cast<Eigen::Index>(k));
    out.contact_positions.emplace_back(col.data(), col.data() + col.size());
  }
  return out;
}

[[noreturn]] inline void not_applicable(std::string_view method, std::string_view problem) {
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
      if constexpr (runs_on<M, P>)
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

  std::vector<param_value> params() const override { return declared_params(p_); }
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
  std::string validate() const override { return stepbench::validate(p_); }
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
  bool has_angular_momentum() const override { return stepbench::has_angular_momentum<P>; }
  double angular_momentum(std::span<const double> y) const override {
    if constexpr (stepbench::has_angular_momentum<P>)
      return p_.angular_momentum(unflatten(y, 0), unflatten(y, p_.dim()));
    else
      return std::numeric_limits<double>::quiet_NaN();
  }
  double period() const override {
    if constexpr (stepbench::has_period<P>)
      return p_.period();
    else
      return std::numeric_limits<double>::quiet_NaN();
  }
  std::string_view contact_mode() const override {
    if constexpr (stepbench::has_contacts<P>)
      return p_.locate_contacts() ? "locate" : "end_of_step";
    else
      return "none";
  }
  bool has_exact_contacts() const override { return stepbench::has_exact_contacts<P>; }
  exact_contact_list exact_contacts(double t_end) const override {
    if constexpr (stepbench::has_exact_contacts<P>)
      return p_.exact_contacts(t_end);
    else
      throw std::logic_error(fmt::format("problem {} has no exact contacts", P::name));
  }
  std::vector<double> initial() const override {
    const auto s = p_.initial();
    return flatten(s.x, s.v);
  }
  ode_system ode() const override {
    ode_system sys = make_ode_system(p_);
    if constexpr (stepbench::has_contacts<P>) {
      // The gap and the response for CVODE's root finding, on the problem's own functions.
      struct workspace {
        P p;
        typename P::vec x, v;
      };
      auto w = std::make_shared<workspace>(workspace{p_, p_.initial().x, p_.initial().v});
      sys.contact_gap = [w](double t, std::span<const double> y) {
        const auto d = static_cast<Eigen::Index>(y.size() / 2);
        w->x = Eigen::Map<const typename P::vec>(y.data(), d);
        w->v = Eigen::Map<const typename P::vec>(y.data() + d, d);
        return w->p.contact_gap(t, w->x, w->v);
      };
      sys.resolve_contacts = [w](double t, std::span<double> y) {
        const auto d = static_cast<Eigen::Index>(y.size() / 2);
        w->x = Eigen::Map<const typename P::vec>(y.data(), d);
        w->v = Eigen::Map<const typename P::vec>(y.data() + d, d);
        const contact_outcome c = w->p.resolve_contacts(t, w->x, w->v);
        Eigen::Map<typename P::vec>(y.data(), d) = w->x;
        Eigen::Map<typename P::vec>(y.data() + d, d) = w->v;
        return c.resolved;
      };
    }
    return sys;
  }

  std::vector<method_info> methods() const override {
    std::vector<method_info> out;
    for_each_method([&]<class M>() {
      if constexpr (runs_on<M, P>) out.push_back(info_of<M>());
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
        out.stop_reason = e.what();
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

  loop_result loop(std::string_view method, const loop_config& config) const override {
    const method_info& m = find_method(method);  // throws for an unknown name
    if (m.origin != method_origin::ours || m.kind != method_kind::fixed_step)
      throw std::invalid_argument(fmt::format(
          "the game loop runs our fixed-step integrators; {} is {}", method,
          m.origin == method_origin::ours ? std::string("adaptive") : fmt::format("a {} method", to_string(m.origin))));
    if (auto err = loop_config_error(config); !err.empty()) throw std::invalid_argument(err);
    loop_result out;
    for_each_type(all_integrators{}, [&]<class I>() {
      if constexpr (integrator<I>)
        if (I::name == method) out = simulate_loop(p_, I{}, config);
    });
    return out;
  }
};

// One problem of the registry: its name and its problem_model's factory. Each problem's
// unit defines its entry; generated/registry/problem_entries.hpp lists them in order.
struct problem_entry {
  std::string_view name;
  std::unique_ptr<problem_instance> (*make)();
};

}  // namespace stepbench::registry_detail
