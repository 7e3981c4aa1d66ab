// `stepbench scan`: a problem over a grid of its parameters, at frame rates and substeps
// (study/scan.hpp), into a study file under /scan/<name>, then the range answer.
#include "judge/scan.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "core/text.hpp"
#include "parts/study.hpp"
#include "render/scan.hpp"
#include "run/scan.hpp"
#include "store/study_file.hpp"
#include "study/scan.hpp"

namespace stepbench::cli {

nlohmann::json scan_answer_json(const scan_answer& a) {
  nlohmann::json out = {{"problem", a.problem},
                        {"unit", a.unit},
                        {"range", a.range},
                        {"tol", a.tol},
                        {"points", a.points},
                        {"grid_points", a.grid_points},
                        {"untrusted_points", a.untrusted},
                        {"cost_kind", a.cost_kind},
                        {"cost_source", a.cost_source},
                        {"ns_per_force_eval", a.ns_per_force_eval},
                        {"uncosted", a.uncosted},
                        {"choices", nlohmann::json::array()},
                        {"one_step_a_frame", nlohmann::json::array()}};
  for (const auto& c : a.choices)
    out["choices"].push_back({{"hz", c.hz},
                              {"method", c.method.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.method)},
                              {"substeps", c.substeps},
                              {"worst_err_pos_max", c.worst_err},
                              {"max_force_evals_per_frame", c.max_force_evals_per_frame},
                              {"max_cost_per_frame", c.max_cost_per_frame}});
  for (const auto& b : a.breaks)
    out["one_step_a_frame"].push_back({{"hz", b.hz},
                                       {"method", b.method},
                                       {"unstable_points", b.unstable},
                                       {"points", b.points},
                                       {"where", b.where}});
  return out;
}

void take_costs(scan_options& o, const study& s, const std::string& path) {
  o.ns_per_force_eval = measured_eval_costs(s, o.problem);
  o.cost_source = o.ns_per_force_eval.empty() ? "" : path;
}

namespace {

struct scan_args {
  std::string problem, hz_text, dt_text, substeps_text, tol_text = "1e-3", name, out = "results/scan.h5";
  std::string reference_budget_text, work_budget_text, shard;  // shard: K/N
  std::string costs;  // a timed study's ns per force evaluation ("": results/study.h5 when it exists; "none")
  std::vector<std::string> params, sets, methods;
  int jobs = 0;
  bool json = false, quiet = false;
};

std::vector<double> number_list(const std::string& text, std::string_view what) {
  std::vector<double> out;
  for (const auto piece : split(text, ',')) out.push_back(parse_number(piece, what));
  return out;
}

int run_scan_command(const scan_args& a) {
  scan_options o;
  o.problem = a.problem;
  o.name = a.name;
  make_problem(a.problem);  // an unknown problem is named before the axes are read
  for (const auto& p : a.params) o.axes.push_back(parse_scan_axis(p, a.problem));
  if (!a.hz_text.empty() && !a.dt_text.empty()) throw std::invalid_argument("give --hz or --dt, not both");
  if (!a.hz_text.empty()) o.hz = number_list(a.hz_text, "--hz");
  if (!a.dt_text.empty()) {
    o.hz.clear();
    for (double dt : number_list(a.dt_text, "--dt")) {
      if (!(dt > 0.0)) throw std::invalid_argument(fmt::format("--dt {:g} is not positive", dt));
      o.hz.push_back(1.0 / dt);  // a frame of dt: the runs take 1, 2, 4 ... substeps of it
    }
  }
  if (!a.substeps_text.empty()) {
    o.substeps.clear();
    for (double n : number_list(a.substeps_text, "--substeps")) {
      if (!(n >= 1 && n == std::floor(n) && n <= (1 << 20)))
        throw std::invalid_argument(fmt::format("--substeps {:g} is not a whole number from 1 to 2^20", n));
      o.substeps.push_back(static_cast<int>(n));
    }
  }
  o.tol = parse_number(a.tol_text, "--tol");
  if (!a.work_budget_text.empty()) {
    o.limits.work_budget = parse_number(a.work_budget_text, "--work-budget");
    if (!(o.limits.work_budget > 0.0))
      throw std::invalid_argument(fmt::format("--work-budget {} is not positive", o.limits.work_budget));
  }
  if (!a.reference_budget_text.empty()) {
    o.reference_budget = a.reference_budget_text == "inf" ? std::numeric_limits<double>::infinity()
                                                          : parse_number(a.reference_budget_text, "--reference-budget");
    if (!(o.reference_budget > 0.0))
      throw std::invalid_argument(fmt::format(
          "--reference-budget {} is not positive (inf: run the references everywhere)", o.reference_budget));
  }
  if (!a.shard.empty()) parse_shard(a.shard, o.shard_index, o.shard_count);
  o.methods = a.methods;
  o.jobs = a.jobs;
  parameter_overrides sets;
  for (const auto& s : a.sets) add_override(sets, s, std::vector<std::string>{a.problem});
  if (auto it = sets.find(a.problem); it != sets.end()) o.fixed = it->second;
  validate(o);
  check_writable(a.out);
  const std::string costs =
      a.costs.empty() && std::filesystem::exists("results/study.h5") ? "results/study.h5" : a.costs;
  if (!costs.empty() && costs != "none") take_costs(o, read_study(costs), costs);
  // Progress on stderr: a line every 5 s (the scan's answer is what stdout carries).
  // Written with fputs, which does not throw: a closed stderr must not end a scan.
  const auto start = std::chrono::steady_clock::now();
  auto last = start;
  o.on_progress = [&](std::size_t done, std::size_t total) {
    const auto now = std::chrono::steady_clock::now();
    if (a.quiet || (done < total && now - last < std::chrono::seconds(5))) return;
    last = now;
    const double elapsed = std::chrono::duration<double>(now - start).count();
    std::fputs(fmt::format("scan: {} of {} points, {:.0f} s elapsed{}\n", done, total, elapsed,
                           done < total ? fmt::format(", about {:.0f} s left", elapsed / done * (total - done)) : "")
                   .c_str(),
               stderr);
  };
  study s;
  s.options.parts = {"scans"};
  const auto& scan = s.results.put(std::vector<scan_result>{run_scan(o)}).front();
  s.wall_seconds = scan.wall_seconds;
  judge_study(s);
  write_study(s, a.out);
  const scan_answer answer = answer_scan(scan, o.tol);
  print_answer(a.json, scan_answer_json(answer), format_scan_answer(answer));
  if (!a.quiet)
    std::fputs(fmt::format("wrote {} (/scan/{}: {} points, {} runs) in {:.2f} s; `stepbench advise --scan {} --tol X` "
                           "answers at another tolerance\n",
                           a.out, o.name.empty() ? o.problem : o.name, scan.points.size(), scan.runs.size(),
                           s.wall_seconds, a.out)
                   .c_str(),
               stderr);
  return 0;
}

}  // namespace

command add_scan(CLI::App& app) {
  auto a = std::make_shared<scan_args>();
  auto* sub = app.add_subcommand(
      "scan",
      "a problem over a grid of its parameters, frame rates and substeps: where each method breaks, and the "
      "cheapest that holds over the whole range");
  sub->add_option("--problem", a->problem, "the problem to scan")->required();
  sub->add_option("--param", a->params,
                  "an axis, problem.name=lo:hi:count[:log] (repeatable; none: one point, the problem as --set "
                  "leaves it)");
  sub->add_option("--hz", a->hz_text, "frame rates, comma-separated; each divides the fastest (30,60,120,240)");
  sub->add_option("--dt", a->dt_text, "frame timesteps instead of rates, comma-separated");
  sub->add_option("--substeps", a->substeps_text, "substeps a frame, comma-separated (1,2,4,8,16,32,64)");
  sub->add_option("--integrator,--method", a->methods,
                  "fixed-step methods to run (repeatable; default: our fixed-step methods)");
  sub->add_option("--tol", a->tol_text, "the error tolerance in the problem's unit, err_pos_max")
      ->capture_default_str();
  sub->add_option("--work-budget", a->work_budget_text,
                  "skip a run whose estimated work (steps x force evaluations a step x coordinates) is over this "
                  "(default 2^25, about 0.1 s of force work)");
  sub->add_option("--reference-budget", a->reference_budget_text,
                  "run the references at a point only when their predicted work (coordinates x w_max T) is at most "
                  "this; elsewhere runs are judged on stability alone (default 2e6; inf: everywhere)");
  sub->add_option("--set", a->sets, "fix another parameter, problem.name=value (repeatable)");
  sub->add_option("--name", a->name, "the scan's group under /scan (default: the problem's name)");
  sub->add_option("--costs", a->costs,
                  "a timed study whose benchmark gives each method's ns per force evaluation on the problem, by which "
                  "the answer ranks, as `advise --hz` does on that study (default: results/study.h5 when it exists; "
                  "none: force evaluations)");
  sub->add_option("--jobs", a->jobs, "threads over the grid points (0: one a core)")->check(CLI::NonNegativeNumber);
  sub->add_option("--shard", a->shard,
                  "K/N: run shard K of N, a deterministic share of the grid points (`stepbench merge` joins them)");
  sub->add_option("--out", a->out, "study file to write")->capture_default_str();
  sub->add_flag("--json", a->json, "the answer as JSON on stdout");
  sub->add_flag("--quiet", a->quiet, "no progress or summary on stderr");
  sub->footer(
      "exit codes: 0 written whole (a method that diverges at a point is a finding, recorded there); 1 a file "
      "error; 2 bad usage (an axis outside the parameter's range, an unknown name)\n");
  return {sub, [a] { return run_scan_command(*a); }};
}

}  // namespace stepbench::cli
