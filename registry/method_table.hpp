#pragma once
// A problem's methods as a table of slots: for each method that runs on P, its info and
// the functions that run it, time it and (ours at a fixed step) run it in the game loop.
// The slots are filled in the unit CMake generates for each problem from
// registry/problem_unit.cpp.in, from the method groups that run on it (integrators/group_*.hpp,
// peers/group_*.hpp); problem_model<P> (registry/problem_model.hpp) reads the table.

#include <exception>
#include <functional>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/drive.hpp"
#include "core/game_loop.hpp"
#include "core/method.hpp"
#include "core/problem_instance.hpp"
#include "core/type_list.hpp"
#include "registry/method_entry.hpp"

namespace stepbench::registry_detail {

template <class P>
struct method_slot {
  const method_info* info = nullptr;
  run_result (*run)(const P&, double param, double horizon, std::span<const double> times, const run_limits&) = nullptr;
  std::function<double()> (*timed_run)(const P&, double param, double horizon, std::span<const double> times,
                                       const run_limits&) = nullptr;
  loop_result (*loop)(const P&, const loop_config&) = nullptr;  // ours at a fixed step only
};
template <class P>
using method_table = std::vector<method_slot<P>>;

template <class Vec>
run_result to_run_result(const drive_result<Vec>& r, double param, double horizon) {
  run_result out;
  static_cast<run_record&>(out) = r;
  out.param = param;
  out.horizon = horizon;
  for (std::size_t j = 0; j < r.sample_t.size(); ++j) {
    const auto col = r.samples.col(static_cast<Eigen::Index>(j));
    out.sample_y.emplace_back(col.data(), col.data() + col.size());
  }
  out.final_y = stacked(r.final_state);
  for (std::size_t k = 0; k < r.contact_times.size() && r.contact_x.size() > 0; ++k) {
    const auto col = r.contact_x.col(static_cast<Eigen::Index>(k));
    out.contact_positions.emplace_back(col.data(), col.data() + col.size());
  }
  return out;
}

// One run of a prepared method (`run_once`, from a prepare that threw
// std::invalid_argument for bad times) in plain vectors.
template <class RunOnce>
run_result run_prepared(const RunOnce& run_once, double param, double horizon) {
  try {
    return to_run_result(run_once(), param, horizon);
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    // A solver error is the run's outcome, recorded with its reason; the study goes on.
    run_result out;
    out.param = param;
    out.horizon = horizon;
    out.stop_reason = e.what();
    return out;
  }
}

template <class M, problem P>
run_result run_method(const P& p, double param, double horizon, std::span<const double> times,
                      const run_limits& limits) {
  return run_prepared(M::prepare(p, param, horizon, times, limits), param, horizon);
}

// A prepared run as the benchmark times it (what it returns keeps the run from being
// optimised away).
template <class RunOnce>
std::function<double()> timed_prepared(RunOnce run_once) {
  return [run_once = std::move(run_once)] { return run_once().final_state.x[0]; };
}

template <class M, problem P>
std::function<double()> timed_method(const P& p, double param, double horizon, std::span<const double> times,
                                     const run_limits& limits) {
  return timed_prepared(M::prepare(p, param, horizon, times, limits));
}

// Appends a slot for each method of the group that runs on P, in the group's order.
template <problem P, class... Ms>
void append_group(type_list<Ms...>, method_table<P>& table) {
  for_each_type(type_list<entry_t<Ms>...>{}, [&]<class M>() {
    if constexpr (runs_on<M, P>) {
      method_slot<P> slot{.info = &info_of<M>(), .run = &run_method<M, P>, .timed_run = &timed_method<M, P>};
      if constexpr (requires { typename M::integrator_type; })
        slot.loop = [](const P& p, const loop_config& c) { return simulate_loop(p, typename M::integrator_type{}, c); };
      table.push_back(slot);
    }
  });
}

}  // namespace stepbench::registry_detail
