// stepbench_bench: Google Benchmark timing of every (problem, integrator, dt) of the
// sweep ladder and of the peers, each case one whole integration over the horizon.
//
// Cases are registered at run time from the registries: <problem>/<integrator>/dt:<v>,
// <problem>/<peer>/dt:<v> for fixed-step peers, <problem>/<peer>/tol:<v> for adaptive
// ones. Every standard --benchmark_* flag works. Our own flags:
//   --quick              short minimum time, 8-level ladder, thinned tolerances (CI)
//   --study_out=PATH     run the accuracy sweep too and write the study file with each
//                        timing next to its accuracy row
//   --case_budget=S      cut a family's finer cases once one iteration would exceed S s
//   --set=P.NAME=VALUE   a problem parameter, as `stepbench sweep --set` (repeatable)
// After the run it prints the performance ratios (docs in README).
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <unistd.h>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench/peers.hpp"
#include "core/drive.hpp"
#include "core/parse.hpp"
#include "core/study_file.hpp"
#include "core/sweep.hpp"
#include "integrators/all.hpp"
#include "problems/all.hpp"

using namespace stepbench;

namespace {

struct bench_options {
  bool quick = false;
  std::string study_out;
  double case_budget_s = 0.5;
  double min_time_s = 0.025;
  int repetitions = 3;
  bool list_only = false;
  std::map<std::string, std::map<std::string, double>> overrides;  // problem -> parameter -> value
};

std::string dt_label(double dt) { return fmt::format("dt:{:.6g}", dt); }
std::string tol_label(double tol) { return fmt::format("tol:{:.0e}", tol); }

// Relative tolerances of the adaptive peers: 1e-2 .. 1e-12 (every other one in quick mode).
std::vector<double> tolerance_ladder(bool quick) {
  std::vector<double> out;
  for (int e = 2; e <= 12; e += quick ? 2 : 1) out.push_back(std::pow(10.0, -e));
  return out;
}

// Per-iteration wall time of each finished case, and which families the budget cut.
struct timing_book {
  std::map<std::string, std::vector<double>> ns_per_iteration;  // one entry per repetition
  std::map<std::string, std::string> errors;                    // SkipWithError messages
  // Per family, the last case that ran and its slowest iteration.
  std::map<std::string, std::pair<std::string, double>> family_last;
  double case_budget_s = 0.5;

  // Called before a case runs: true when its family's previous (coarser) case already took
  // more than half the budget per iteration, so this one (twice the work) would exceed it.
  // Google Benchmark calls a case several times while it sizes the iteration count; those
  // calls of the same case do not count against it.
  bool over_budget(const std::string& family, const std::string& name) const {
    auto it = family_last.find(family);
    return it != family_last.end() && it->second.first != name && 2.0 * it->second.second > case_budget_s * 1e9;
  }
  void record(const std::string& family, const std::string& name, double ns) {
    auto& last = family_last[family];
    last.second = last.first == name ? std::max(last.second, ns) : ns;
    last.first = name;
  }
};

timing_book book;

// Forwards everything to the display reporter the user asked for and keeps the timings.
class collecting_reporter : public benchmark::BenchmarkReporter {
 public:
  explicit collecting_reporter(std::unique_ptr<benchmark::BenchmarkReporter> inner) : inner_(std::move(inner)) {}
  bool ReportContext(const Context& context) override {
    cpu_scaling = context.cpu_info.scaling == benchmark::CPUInfo::ENABLED    ? 1
                  : context.cpu_info.scaling == benchmark::CPUInfo::DISABLED ? 0
                                                                             : -1;
    num_cpus = context.cpu_info.num_cpus;
    mhz = context.cpu_info.cycles_per_second / 1e6;
    return inner_->ReportContext(context);
  }
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& r : runs) {
      if (r.run_type != Run::RT_Iteration) continue;
      const std::string name = r.run_name.function_name;
      if (r.error_occurred)
        book.errors[name] = r.error_message;
      else if (r.iterations > 0)
        book.ns_per_iteration[name].push_back(r.real_accumulated_time * 1e9 / static_cast<double>(r.iterations));
    }
    inner_->ReportRuns(runs);
  }
  void Finalize() override { inner_->Finalize(); }
  int cpu_scaling = -1;
  int num_cpus = 0;
  double mhz = 0.0;

 private:
  std::unique_ptr<benchmark::BenchmarkReporter> inner_;
};

struct case_counters {
  double err_pos_final = 0, err_pos_max = 0;
  long steps = 0, force_evals = 0;
};

// Registers one timed case. `run` performs one whole integration and returns something
// to keep alive; the counters come from the accuracy run done before timing.
template <class F>
void register_case(const std::string& name, const std::string& family, case_counters c, F run) {
  benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& state) {
    if (book.over_budget(family, name)) {
      state.SkipWithError("cut: the previous case of this family used over half the per-case budget");
      return;
    }
    const auto start = std::chrono::steady_clock::now();
    for (auto _ : state) {
      auto r = run();
      benchmark::DoNotOptimize(r);
      benchmark::ClobberMemory();
    }
    const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count() /
                      static_cast<double>(std::max<benchmark::IterationCount>(1, state.iterations()));
    book.record(family, name, ns);
    state.counters["err_pos_final"] = c.err_pos_final;
    state.counters["err_pos_max"] = c.err_pos_max;
    state.counters["steps"] = static_cast<double>(c.steps);
    state.counters["force_evals"] = static_cast<double>(c.force_evals);
    // Wall time, like the study's time_ns (a rate counter would use CPU time).
    state.counters["ns_per_step"] = ns / static_cast<double>(std::max(1L, c.steps));
  })->Unit(benchmark::kMicrosecond);
}

// Errors of a peer against the truth at the sample times (same definitions as ours).
peer_row peer_errors(const peers::peer_run& r, const truth_table& truth, int dim, double param) {
  peer_row row;
  row.param = param;
  row.steps = r.steps;
  row.force_evals = r.force_evals;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (r.non_finite || r.sample_count() != truth.y.size()) {
    row.diverged = true;
    row.err_pos_final = row.err_pos_max = nan;
    return row;
  }
  auto pos_err = [&](std::span<const double> a, std::span<const double> b) {
    double s = 0;
    for (int i = 0; i < dim; ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(s);
  };
  for (size_t j = 0; j < truth.y.size(); ++j) row.err_pos_max = std::max(row.err_pos_max, pos_err(r.sample(j), truth.y[j]));
  row.err_pos_final = pos_err(r.final_y, truth.y.back());
  row.diverged = !(row.err_pos_max <= blowup_factor * truth.pos_scale);
  return row;
}

peers::peer_run from_solution(const reference_solution& s) {
  peers::peer_run r;
  r.steps = s.stats.steps;
  r.force_evals = s.stats.rhs_evals_counted;
  r.start(static_cast<int>(s.y.front().size()), s.y.size());
  for (const auto& y : s.y) r.record(y.begin(), y.end());
  r.final_y = s.y.back();
  return r;
}

// Registers every case of one problem type; fills the study's peer tables (accuracy now,
// timings after the run). The timed lambdas run after this returns: everything they use
// is captured by value.
template <problem P>
void register_problem(problem_study& ps, const bench_options& opts) {
  // The parameters the sweep used (checked there): defaults plus --set.
  const P p = [&] {
    P q{};
    if (auto it = opts.overrides.find(std::string(P::name)); it != opts.overrides.end())
      for (const auto& [name, value] : it->second)
        for (const auto& param : P::parameters())
          if (param.name == name) q.*param.member = value;
    return q;
  }();
  const double horizon = ps.horizon;
  const int samples = static_cast<int>(ps.truth.times.size());
  const std::string pname(P::name);

  for (auto& is : ps.integrators) {
    for (const auto& row : is.rows) {
      const auto record = sample_steps(horizon, row.dt, samples);
      const double dt = row.dt;
      for_each_type(all_integrators{}, [&]<class I>() {
        if (I::name != is.info.name) return;
        register_case(fmt::format("{}/{}/{}", pname, I::name, dt_label(dt)), pname + "/" + std::string(I::name),
                      {row.metrics.err_pos_final, row.metrics.err_pos_max, row.steps, row.force_evals},
                      [=] { return drive(p, I{}, dt, horizon, record).final_state.x[0]; });
      });
    }
  }

  std::vector<double> ladder;  // the same dt as our rows
  for (const auto& row : ps.integrators.front().rows) ladder.push_back(row.dt);
  auto add_fixed_peer = [&](const std::string& name, const std::string& description, double declared, auto runner) {
    peer_study peer{name, "fixed_step", description, declared, {}, {}};
    for (double dt : ladder) {
      const auto record = sample_steps(horizon, dt, samples);
      const auto run = runner(dt, record);
      peer.rows.push_back(peer_errors(run, ps.truth, P::dim, dt));
      const auto& row = peer.rows.back();
      register_case(fmt::format("{}/{}/{}", pname, name, dt_label(dt)), pname + "/" + name,
                    {row.err_pos_final, row.err_pos_max, row.steps, row.force_evals},
                    [=] { return runner(dt, record).final_y[0]; });
    }
    ps.peers.push_back(std::move(peer));
  };
  const struct {
    const char* name;
    const gsl_odeiv2_step_type* type;
    const char* description;
  } gsl_steppers[] = {
      {"gsl_rk4", gsl_odeiv2_step_rk4, "GSL rk4 at fixed dt (gsl_odeiv2_step_apply; error estimate by step doubling)"},
      {"gsl_rk2", gsl_odeiv2_step_rk2, "GSL rk2 (Heun) at fixed dt, with its embedded error estimate"},
      {"gsl_rkf45", gsl_odeiv2_step_rkf45, "GSL rkf45 at fixed dt (Fehlberg 4(5), error estimate unused)"},
  };
  for (const auto& g : gsl_steppers) {
    std::unique_ptr<gsl_odeiv2_step, peers::gsl_step_deleter> probe(gsl_odeiv2_step_alloc(g.type, 2 * P::dim));
    const double declared = gsl_odeiv2_step_order(probe.get());
    const auto* type = g.type;
    add_fixed_peer(g.name, g.description, declared,
                   [p, type, horizon](double dt, std::span<const long> record) {
                     return peers::gsl_fixed(p, type, dt, horizon, record);
                   });
  }
#if STEPBENCH_HAVE_ODEINT
  add_fixed_peer("odeint_rk4", "Boost.Odeint runge_kutta4 on std::array", peers::odeint_declared_order_rk4(),
                 [p, horizon](double dt, std::span<const long> record) { return peers::odeint_rk4(p, dt, horizon, record); });
  add_fixed_peer("odeint_velocity_verlet", "Boost.Odeint velocity_verlet on std::array (declares order 1)",
                 peers::odeint_declared_order_velocity_verlet(), [p, horizon](double dt, std::span<const long> record) {
                   return peers::odeint_velocity_verlet(p, dt, horizon, record);
                 });
#endif
  if constexpr (peers::has_baseline<P>)
    add_fixed_peer("baseline_rk4", "hand-written RK4 on plain doubles, fully inlined: the speed-of-light step", 4,
                   [p, horizon](double dt, std::span<const long> record) {
                     return peers::baseline_rk4(p, dt, horizon, record);
                   });

  // Adaptive peers over a ladder of tolerances (rtol = atol = tol), outputs at the same
  // sample times. They go through std::function, as the references do: the per-call cost
  // is an indirect call, small beside what these solvers do per step.
  const ode_system sys = ps.problem->ode();
  const std::vector<double> times = ps.truth.times;
  const struct {
    const char* name;
    const char* description;
    std::function<reference_solution(double)> solve;
  } adaptive[] = {
      {"gsl_rkf45_adaptive", "GSL driver, rkf45 with y_new control",
       [sys, times](double tol) { return solve_gsl(sys, times, gsl_method::rkf45, {tol, tol}); }},
      {"gsl_rk8pd_adaptive", "GSL driver, rk8pd with y_new control",
       [sys, times](double tol) { return solve_gsl(sys, times, gsl_method::rk8pd, {tol, tol}); }},
      {"cvode_adams", "CVODE Adams-Moulton, fixed-point iteration",
       [sys, times](double tol) { return solve_cvode(sys, times, cvode_method::adams, {tol, tol}); }},
      {"cvode_bdf", "CVODE BDF, Newton with dense difference-quotient Jacobian",
       [sys, times](double tol) { return solve_cvode(sys, times, cvode_method::bdf, {tol, tol}); }},
  };
  for (const auto& a : adaptive) {
    peer_study peer{a.name, "adaptive", a.description, std::numeric_limits<double>::quiet_NaN(), {}, {}};
    for (double tol : tolerance_ladder(opts.quick)) {
      peer.rows.push_back(peer_errors(from_solution(a.solve(tol)), ps.truth, P::dim, tol));
      const auto& row = peer.rows.back();
      auto solve = a.solve;
      register_case(fmt::format("{}/{}/{}", pname, a.name, tol_label(tol)), pname + "/" + a.name,
                    {row.err_pos_final, row.err_pos_max, row.steps, row.force_evals},
                    [solve, tol] { return solve(tol).y.back()[0]; });
    }
    ps.peers.push_back(std::move(peer));
  }
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

timing timing_of(const std::string& name) {
  timing t;
  if (auto it = book.ns_per_iteration.find(name); it != book.ns_per_iteration.end() && !it->second.empty()) {
    t.time_ns = median(it->second);
    t.repetitions = static_cast<long>(it->second.size());
  } else if (auto e = book.errors.find(name); e != book.errors.end()) {
    t.cut = e->second.rfind("cut", 0) == 0;
  }
  return t;
}

void merge_timings(study& s) {
  for (auto& ps : s.problems) {
    const std::string pname(ps.problem->name());
    for (auto& is : ps.integrators)
      for (auto& row : is.rows) row.time = timing_of(fmt::format("{}/{}/{}", pname, is.info.name, dt_label(row.dt)));
    for (auto& peer : ps.peers)
      for (auto& row : peer.rows)
        row.time = timing_of(fmt::format("{}/{}/{}", pname, peer.name,
                                         peer.kind == "adaptive" ? tol_label(row.param) : dt_label(row.param)));
  }
}

void fit_peers(study& s) {
  for (auto& ps : s.problems)
    for (auto& peer : ps.peers) {
      if (peer.kind != "fixed_step") continue;
      fit_input in;
      in.scale = ps.truth.pos_scale;
      for (const auto& r : peer.rows) {
        in.dt.push_back(r.param);
        in.error.push_back(r.err_pos_max);
        in.steps.push_back(r.steps);
        in.diverged.push_back(r.diverged);
      }
      peer.fit = fit_order(in);
    }
}

// ---- The performance ratios ---------------------------------------------------------

const problem_study* find_problem(const study& s, std::string_view name) {
  for (const auto& ps : s.problems)
    if (ps.problem->name() == name) return &ps;
  return nullptr;
}

// ns per step of a fixed-step method at the finest dt where every named method was timed.
std::map<std::string, double> ns_per_step_at_common_dt(const problem_study& ps, const std::vector<std::string>& names,
                                                       double& dt_out) {
  std::map<std::string, double> out;
  const auto& ladder = ps.integrators.front().rows;
  for (auto it = ladder.rbegin(); it != ladder.rend(); ++it) {
    out.clear();
    for (const auto& name : names) {
      const auto t = timing_of(fmt::format("{}/{}/{}", ps.problem->name(), name, dt_label(it->dt)));
      if (std::isfinite(t.time_ns)) out[name] = t.time_ns / static_cast<double>(it->steps);
    }
    if (out.size() == names.size()) {
      dt_out = it->dt;
      return out;
    }
  }
  return {};
}

// Time to reach `target` error: the cheapest measured row at or below it, or the
// log-log interpolation between two consecutive rows of the ladder that bracket it,
// whichever is less; NaN when no row reaches it. Rows are (error, time) in ladder order.
double time_at_error(const std::vector<std::pair<double, double>>& rows, double target) {
  auto usable = [](const std::pair<double, double>& r) {
    return std::isfinite(r.first) && std::isfinite(r.second) && r.first > 0 && r.second > 0;
  };
  double best = std::numeric_limits<double>::quiet_NaN();
  for (const auto& r : rows)
    if (usable(r) && r.first <= target && !(r.second >= best)) best = r.second;
  for (size_t i = 0; i + 1 < rows.size(); ++i) {
    const auto [e1, t1] = rows[i];
    const auto [e2, t2] = rows[i + 1];
    if (!usable(rows[i]) || !usable(rows[i + 1]) || !(e1 > target && e2 < target)) continue;
    const double w = std::log(target / e1) / std::log(e2 / e1);
    const double t = std::exp(std::log(t1) + w * (std::log(t2) - std::log(t1)));
    if (!(t >= best)) best = t;
  }
  return best;
}

// Which of our methods and which peer reach `target` error on a problem cheapest in
// measured time, and by how much.
void equal_error_table(const problem_study& ps, double target, const std::string& metric, bool list_all) {
  const bool use_max = metric == "err_pos_max";
  std::vector<std::tuple<double, std::string, bool>> costs;  // time, name, ours
  for (const auto& is : ps.integrators) {
    std::vector<std::pair<double, double>> rows;
    for (const auto& r : is.rows)
      rows.emplace_back(use_max ? r.metrics.err_pos_max : r.metrics.err_pos_final, r.time.time_ns);
    costs.emplace_back(time_at_error(rows, target), is.info.name, true);
  }
  for (const auto& peer : ps.peers) {
    std::vector<std::pair<double, double>> rows;
    for (const auto& r : peer.rows) rows.emplace_back(use_max ? r.err_pos_max : r.err_pos_final, r.time.time_ns);
    costs.emplace_back(time_at_error(rows, target), peer.name, false);
  }
  std::erase_if(costs, [](auto& c) { return !std::isfinite(std::get<0>(c)); });
  std::sort(costs.begin(), costs.end());
  fmt::print("  {}: time to {} = {:.0e} (log-log interpolation between ladder rows)\n", ps.problem->name(), metric,
             target);
  if (list_all)
    for (const auto& [t, name, ours] : costs) fmt::print("    {:<24} {:>10.1f} us {}\n", name, t / 1e3, ours ? "(ours)" : "");
  const auto best_ours = std::find_if(costs.begin(), costs.end(), [](auto& c) { return std::get<2>(c); });
  const auto best_peer = std::find_if(costs.begin(), costs.end(),
                                      [](auto& c) { return !std::get<2>(c) && std::get<1>(c) != "baseline_rk4"; });
  if (best_ours != costs.end() && best_peer != costs.end())
    fmt::print("    cheapest of ours: {} ({:.1f} us); cheapest peer: {} ({:.1f} us); peer / ours = {:.2f}\n",
               std::get<1>(*best_ours), std::get<0>(*best_ours) / 1e3, std::get<1>(*best_peer),
               std::get<0>(*best_peer) / 1e3, std::get<0>(*best_peer) / std::get<0>(*best_ours));
  else
    fmt::print("    no method of ours or no peer reached it in this run\n");
}

void print_ratios(const study& s) {
  fmt::print("\nPerformance ratios (measured in this run; lower time is better)\n");
  if (const auto* spring = find_problem(s, "damped_spring")) {
    double dt = 0;
    const std::vector<std::string> names{"rk4", "baseline_rk4", "gsl_rk4", "odeint_rk4"};
    std::vector<std::string> present;
    for (const auto& n : names)
      if (n == "rk4" || std::any_of(spring->peers.begin(), spring->peers.end(), [&](auto& p) { return p.name == n; }))
        present.push_back(n);
    const auto ns = ns_per_step_at_common_dt(*spring, present, dt);
    if (ns.count("rk4")) {
      fmt::print("  damped_spring, dt = {:.6g} s, ns per step: ", dt);
      for (const auto& [n, v] : ns) fmt::print("{} {:.2f}  ", n, v);
      fmt::print("\n");
      auto ratio = [&](const char* a, const char* b, const char* target, bool ok) {
        fmt::print("  {:<44} {:>7.2f}   target {} {}\n", fmt::format("{} / {}", a, b), ns.at(a) / ns.at(b), target,
                   ok ? "met" : "NOT MET");
      };
      if (ns.count("baseline_rk4"))
        ratio("rk4", "baseline_rk4", "<= 1.15", ns.at("rk4") / ns.at("baseline_rk4") <= 1.15);
      if (ns.count("gsl_rk4")) {
        ratio("gsl_rk4", "rk4", ">= 6", ns.at("gsl_rk4") / ns.at("rk4") >= 6.0);
        fmt::print("    (GSL's rk4 step also estimates its error by step doubling: {:.2f} force evaluations a step against our 4)\n",
                   [&] {
                     for (const auto& p : spring->peers)
                       if (p.name == "gsl_rk4") return static_cast<double>(p.rows.back().force_evals) / p.rows.back().steps;
                     return 0.0;
                   }());
      }
      if (ns.count("odeint_rk4")) ratio("rk4", "odeint_rk4", "<= 0.85", ns.at("rk4") / ns.at("odeint_rk4") <= 0.85);
    } else {
      fmt::print("  damped_spring rk4 and its peers were not all timed (filtered out?)\n");
    }
  }
  if (const auto* pend = find_problem(s, "pendulum")) {
    // Primary: the largest position error over the run. The final error alone flatters
    // symplectic methods here: the horizon is a whole number of periods, the pendulum is
    // at a turning point, and a phase error barely moves the position there (semi-implicit
    // Euler's final error falls like dt^3 while its error over the run falls like dt).
    equal_error_table(*pend, 1e-6, "err_pos_max", true);
    equal_error_table(*pend, 1e-6, "err_pos_final", false);
  }
}

// Our flags are taken out of argv before Google Benchmark sees it; quick and full mode
// supply defaults for --benchmark_min_time and --benchmark_repetitions unless given.
bench_options take_own_flags(int& argc, char** argv, std::vector<std::string>& extra) {
  bench_options o;
  bool min_time_given = false, reps_given = false, budget_given = false;
  int out = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      o.quick = true;
    } else if (a.rfind("--set=", 0) == 0) {
      const auto [name, value] = parse_assignment(a.substr(6));
      const auto dot = name.find('.');
      if (dot == std::string::npos || dot == 0 || dot + 1 == name.size())
        throw std::invalid_argument("--set=" + a.substr(6) + ": name the problem, --set=problem.name=value");
      o.overrides[name.substr(0, dot)][name.substr(dot + 1)] = value;
    } else if (a == "--study_out" || a == "--case_budget" || a == "--set") {
      throw std::invalid_argument(a + " takes its value after '=': " + a + "=VALUE");
    } else if (a.rfind("--study_out=", 0) == 0) {
      o.study_out = a.substr(12);
      if (o.study_out.empty()) throw std::invalid_argument("--study_out needs a path");
    } else if (a.rfind("--case_budget=", 0) == 0) {
      o.case_budget_s = parse_number(a.substr(14), "--case_budget");
      if (!(o.case_budget_s > 0)) throw std::invalid_argument("--case_budget must be > 0");
      budget_given = true;
    } else {
      if (a.rfind("--benchmark_min_time=", 0) == 0) {
        min_time_given = true;
        o.min_time_s = parse_number(a.substr(21), "--benchmark_min_time");
      }
      if (a.rfind("--benchmark_repetitions=", 0) == 0) {
        reps_given = true;
        const double reps = parse_number(a.substr(24), "--benchmark_repetitions");
        if (!(reps >= 1 && reps <= 1000 && reps == std::floor(reps)))
          throw std::invalid_argument("--benchmark_repetitions must be a whole number from 1 to 1000");
        o.repetitions = static_cast<int>(reps);
      }
      if (a == "--benchmark_list_tests" || a == "--benchmark_list_tests=true") o.list_only = true;
      argv[out++] = argv[i];
    }
  }
  argc = out;
  if (o.quick) {
    if (!min_time_given) o.min_time_s = 0.002;
    if (!reps_given) o.repetitions = 1;
    if (!budget_given) o.case_budget_s = 0.05;
  }
  if (!min_time_given) extra.push_back(fmt::format("--benchmark_min_time={}", o.min_time_s));
  if (!reps_given) extra.push_back(fmt::format("--benchmark_repetitions={}", o.repetitions));
  return o;
}

// The display reporter Google Benchmark would have made from the flags: JSON or console,
// coloured only on a terminal unless --benchmark_color says otherwise.
std::unique_ptr<benchmark::BenchmarkReporter> display_reporter_for(int argc, char** argv) {
  bool color = ::isatty(STDOUT_FILENO);
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--benchmark_format=json") return std::make_unique<benchmark::JSONReporter>();
    if (a == "--benchmark_color=false" || a == "--benchmark_color=no" || a == "--benchmark_color=0") color = false;
    if (a == "--benchmark_color=true" || a == "--benchmark_color=yes" || a == "--benchmark_color=1") color = true;
  }
  return std::make_unique<benchmark::ConsoleReporter>(color ? benchmark::ConsoleReporter::OO_ColorTabular
                                                            : benchmark::ConsoleReporter::OO_Tabular);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<std::string> extra;
    bench_options opts = take_own_flags(argc, argv, extra);
    // Chosen before Initialize, which removes the --benchmark_* flags from argv.
    collecting_reporter reporter(display_reporter_for(argc, argv));
    std::vector<char*> args(argv, argv + argc);
    for (auto& e : extra) args.push_back(e.data());
    int n = static_cast<int>(args.size());
    args.push_back(nullptr);
    benchmark::Initialize(&n, args.data());
    if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 2;
    book.case_budget_s = opts.case_budget_s;
    if (!opts.study_out.empty() && !opts.list_only) check_writable(opts.study_out);

    // The accuracy sweep first: it gives each case its counters and the study its rows.
    sweep_options sopts;
    if (opts.quick) sopts.levels = 8;
    sopts.overrides = opts.overrides;  // checked by run_sweep's validate()
    const auto start = std::chrono::steady_clock::now();
    study s = run_sweep(sopts);
    for (auto& ps : s.problems)
      for_each_type(all_problems{}, [&]<class P>() {
        if (P::name == ps.problem->name()) register_problem<P>(ps, opts);
      });

    benchmark::RunSpecifiedBenchmarks(&reporter);
    benchmark::Shutdown();
    if (opts.list_only) return 0;

    if (!opts.study_out.empty() && book.ns_per_iteration.empty())
      throw std::runtime_error("no case was timed (does --benchmark_filter match any?); " + opts.study_out +
                               " was not written");
    merge_timings(s);
    fit_peers(s);
    timing_settings ts;
    ts.mode = opts.quick ? "quick" : "full";
    ts.min_time_s = opts.min_time_s;
    ts.repetitions = opts.repetitions;
    ts.case_budget_s = opts.case_budget_s;
    ts.num_cpus = reporter.num_cpus;
    ts.mhz_per_cpu = reporter.mhz;
    ts.cpu_scaling_enabled = reporter.cpu_scaling;
    ts.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    s.timed = ts;
    print_ratios(s);
    for (const auto& ps : s.problems)
      for (const auto& peer : ps.peers)
        if (peer.kind == "fixed_step" && peer.fit.state == fit_result::status::fitted &&
            std::abs(peer.fit.order - peer.declared_order) > 0.5)
          fmt::print("  note: {} on {} declares order {} but achieves {:.2f}\n", peer.name, ps.problem->name(),
                     peer.declared_order, peer.fit.order);
    if (!opts.study_out.empty()) {
      write_study(s, opts.study_out);
      fmt::print("wrote {} (timed, {} mode) in {:.1f} s\n", opts.study_out, ts.mode, ts.wall_seconds);
    } else {
      fmt::print("timed in {:.1f} s ({} mode)\n", ts.wall_seconds, ts.mode);
    }
    return 0;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "stepbench_bench: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stepbench_bench: error: %s\n", e.what());
    return 1;
  }
}
