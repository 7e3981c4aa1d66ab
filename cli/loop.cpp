// `stepbench loop`: the game loop around an integrator (study/loop.hpp). Two forms:
//   loop --problem P --integrator I [--out FILE]
//     the whole loop study of the pair (every design, clock, physics rate, clamp on and
//     off for the stall), with the pair's accuracy sweep, into a study file;
//   loop --problem P --integrator I --design D [--display-hz H] [--physics-hz H]
//        [--clamp S|off] [--jitter SEED] [--stall-at T] [--step-cost NS] [--json]
//     one configuration: its figures, printed.
#include "judge/loop.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "core/work_precision.hpp"
#include "judge/outcome.hpp"
#include "parts/study.hpp"
#include "render/table_render.hpp"
#include "run/loop.hpp"
#include "run/sweep.hpp"
#include "store/study_file.hpp"
#include "study/loop.hpp"

namespace stepbench {
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(loop_row, clock, frames, physics_steps, force_evals, shown_err_max, shown_err_rms,
                                   final_shown_err, clock_dependence, physics_clock_dependence, judder, lag_s,
                                   lag_clock_s, steps_per_frame_mean, steps_per_frame_max, stall_burst_steps,
                                   clamp_hits, alpha_min, alpha_max, diverged, note)
}  // namespace stepbench

namespace stepbench::cli {
namespace {

using json = nlohmann::json;

struct loop_args {
  std::string problem, method, out, design;
  std::string display_hz, physics_hz, clamp, jitter, stall_at, step_cost, horizon;
  std::vector<std::string> sets;
  bool json = false, quiet = false, strict = false;
};

// The options of one configuration (--design), in --help's order; each text is empty when not given.
constexpr struct {
  const char* name;
  std::string loop_args::*text;
  const char* help;
} one_config_options[] = {
    {"--display-hz", &loop_args::display_hz, "display rate [Hz] (default 60)"},
    {"--physics-hz", &loop_args::physics_hz,
     "physics rate [Hz]: dt = 1 / rate; substeps: ceil(rate / display) a frame (default 60)"},
    {"--clamp", &loop_args::clamp, "frame-time clamp [s], or off (default 0.25)"},
    {"--jitter", &loop_args::jitter, "jitter the frame times +-25 %, from this seed"},
    {"--stall-at", &loop_args::stall_at, "a 1 s stall of the frame that begins at this wall time [s]"},
    {"--step-cost", &loop_args::step_cost, "cost model: wall time of one physics step [ns] (default 1000)"},
    {"--horizon", &loop_args::horizon, "end time [s] (default: the problem's)"}};

loop_design parse_design(const std::string& text) {
  for (loop_design d : all_loop_designs)
    if (to_string(d) == text) return d;
  throw std::invalid_argument(
      fmt::format("unknown --design '{}' (known: variable, fixed, interpolated, substeps)", text));
}

std::uint64_t parse_seed(const std::string& text) {
  std::uint64_t v = 0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end)
    throw std::invalid_argument(fmt::format("--jitter must be a seed (a whole number >= 0), got '{}'", text));
  return v;
}

const method_info& loop_method_info(const std::string& name) {
  const method_info& m = find_method(name);
  const bool offered = offered_as_ours(m.origin);
  if (!offered || m.kind != method_kind::fixed_step)
    throw std::invalid_argument(
        fmt::format("the game loop runs fixed-step integrators, ours and the plugins'; {} is {}", name,
                    offered ? std::string("adaptive") : fmt::format("a {} method", to_string(m.origin))));
  return m;
}

std::string g3(double v) { return std::isfinite(v) ? fmt::format("{:.3g}", v) : "n/a"; }

// A time [s] in the unit that fits it (ns, us, ms or s; core/work_precision.hpp), signed.
std::string time_text(double s) { return s < 0.0 ? "-" + format_time_ns(-s * 1e9) : format_time_ns(s * 1e9); }

// The loop a --design run asks for: the study's defaults, then the command's options.
loop_config one_loop_config(const loop_args& a, const problem_instance& problem, const loop_options& opts) {
  loop_config c;
  c.design = parse_design(a.design);
  c.clamp_s = opts.clamp_s;
  c.jitter = opts.jitter;
  c.stall_s = opts.stall_s;
  if (!a.display_hz.empty()) c.display_hz = parse_number(a.display_hz, "--display-hz");
  if (!a.physics_hz.empty()) c.physics_hz = parse_number(a.physics_hz, "--physics-hz");
  if (!a.clamp.empty()) {
    c.clamp_s = a.clamp == "off" ? 0.0 : parse_number(a.clamp, "--clamp");
    if (a.clamp != "off" && !(c.clamp_s > 0.0))
      throw std::invalid_argument(fmt::format("--clamp must be a time > 0 or off, got {}", a.clamp));
  }
  if (!a.jitter.empty()) c.jitter_seed = parse_seed(a.jitter);
  if (!a.stall_at.empty()) c.stall_at_s = parse_number(a.stall_at, "--stall-at");
  c.horizon = a.horizon.empty() ? problem.horizon() : parse_positive(a.horizon, "--horizon");
  if (auto err = loop_config_error(c); !err.empty()) throw std::invalid_argument(err);
  return c;
}

// The position (offset 0) or velocity (offset dim) part of a state (-0 as 0: printed "0").
std::vector<double> state_part(const std::vector<double>& y, int offset, int dim) {
  std::vector<double> out(y.begin() + offset, y.begin() + offset + dim);
  for (double& x : out) x = x == 0.0 ? 0.0 : x;
  return out;
}

json one_loop_json(const loop_args& a, const problem_instance& problem, const loop_config& c, const loop_options& opts,
                   const loop_row& r, const loop_cost& cost) {
  const int dim = problem.dim();
  json out = r;  // NaN is written as null
  out.update({{"problem", a.problem},
              {"integrator", a.method},
              {"design", to_string(c.design)},
              {"display_hz", c.display_hz},
              {"physics_hz", c.design == loop_design::variable ? json(nullptr) : json(c.physics_hz)},
              {"dt", uses_accumulator(c.design) ? json(c.dt()) : json(nullptr)},
              {"substeps", c.design == loop_design::substeps ? json(c.substeps()) : json(nullptr)},
              {"clamp_s", c.clamp_s > 0.0 ? json(c.clamp_s) : json(nullptr)},
              {"jitter_seed", c.jitter_seed ? json(*c.jitter_seed) : json(nullptr)},
              {"jitter", c.jitter_seed ? json(c.jitter) : json(nullptr)},
              {"stall_at_s", c.stall_at_s},
              {"stall_s", c.stalls() ? json(c.stall_s) : json(nullptr)},
              {"horizon", c.horizon},
              {"position_unit", std::string(problem.position_unit())},
              {"final_physics_t", r.physics_t},
              {"final_physics_position", state_part(r.final_physics, 0, dim)},
              {"final_physics_velocity", state_part(r.final_physics, dim, dim)},
              {"final_shown_position", state_part(r.final_shown, 0, dim)},
              {"reference_display_hz", opts.reference_display_hz},
              {"cost",
               {{"step_cost_ns", cost.step_cost_ns},
                {"source", a.step_cost.empty() ? "stated (default)" : "stated"},
                {"frame_budget_ns", cost.schedule.frame_budget_s * 1e9},
                {"worst_frame_work_ns", cost.schedule.worst_work_s * 1e9},
                {"late_frames", cost.schedule.late_frames},
                {"physics_load", cost.schedule.load},
                {"wall_s", cost.schedule.wall_s},
                {"outcome", to_string(cost.schedule.outcome)},
                {"outcome_without_clamp", to_string(cost.without_clamp)},
                {"clamp_prevented_spiral", cost.clamp_prevented_spiral}}}});
  return out;
}

void print_one_loop(const loop_args& a, const problem_instance& problem, const loop_config& c, const loop_options& opts,
                    const loop_row& r, const loop_cost& cost) {
  const std::string unit(problem.position_unit());
  std::string clock = fmt::format("{:g} Hz display", c.display_hz);
  if (c.jitter_seed) clock += fmt::format(", frame times jittered +-{:g} % (seed {})", 100 * c.jitter, *c.jitter_seed);
  if (c.stalls()) clock += fmt::format(", a {:g} s stall at {:g} s", c.stall_s, c.stall_at_s);
  std::string physics = c.design == loop_design::variable ? "dt = the frame time"
                        : c.design == loop_design::substeps
                            ? fmt::format("{} substeps a frame", c.substeps())
                            : fmt::format("physics {:g} Hz (dt {:.6g} s)", c.physics_hz, c.dt());
  fmt::print("{} with {}, {} loop: {}, {}, clamp {}, to t = {:g} s\n", a.problem, a.method, to_string(c.design), clock,
             physics, c.clamp_s > 0.0 ? fmt::format("{:g} s", c.clamp_s) : "off", c.horizon);
  fmt::print("  frames {}, physics steps {} (mean {:.3g}, max {} a frame), force evaluations {}\n", r.frames,
             r.physics_steps, r.steps_per_frame_mean, r.steps_per_frame_max, r.force_evals);
  fmt::print("  shown error        max {} {}, rms {} {}, at the horizon {} {}\n", g3(r.shown_err_max), unit,
             g3(r.shown_err_rms), unit, g3(r.final_shown_err), unit);
  fmt::print("  clock dependence   {} {} shown, {} {} physics, against the {:g} Hz display at the horizon\n",
             g3(r.clock_dependence), unit, g3(r.physics_clock_dependence), unit, opts.reference_display_hz);
  fmt::print("  judder             {} {}/s (std of shown - exact velocity)\n", g3(r.judder), unit);
  fmt::print("  lag                {} measured ({} from the loop's clocks)\n", time_text(r.lag_s),
             time_text(r.lag_clock_s));
  if (uses_accumulator(c.design)) fmt::print("  alpha              [{:.4g}, {:.4g}]\n", r.alpha_min, r.alpha_max);
  if (c.stalls())
    fmt::print("  stall              {} in the stall frame, {} clamped\n", count_of(r.stall_burst_steps, "step"),
               count_of(r.clamp_hits, "frame"));
  fmt::print(
      "  cost model         {} a step{}: worst frame {} of a {} budget, load {:.3g}, {}: {} (without the clamp: {})\n",
      format_time_ns(cost.step_cost_ns), a.step_cost.empty() ? " (stated default)" : "",
      time_text(cost.schedule.worst_work_s), time_text(cost.schedule.frame_budget_s), cost.schedule.load,
      count_of(cost.schedule.late_frames, "late frame"), to_string(cost.schedule.outcome),
      to_string(cost.without_clamp));
  fmt::print("  final physics      t = {:.10g} s, position {::.12g}\n", r.physics_t,
             state_part(r.final_physics, 0, problem.dim()));
  if (!r.note.empty()) fmt::print("  {}: {}\n", r.diverged ? "DIVERGED" : "NOTE", r.note);
}

int run_one(const loop_args& a) {
  if (!a.out.empty()) throw std::invalid_argument("--out writes the whole loop study: leave out --design");
  make_problem(a.problem);  // an unknown problem is named before an unknown method
  loop_method_info(a.method);
  sweep_options so;
  for (const auto& s : a.sets) add_override(so.overrides, s, std::vector{a.problem});
  const auto problem = configured_problem(a.problem, so);
  const loop_options opts;
  const loop_config c = one_loop_config(a, *problem, opts);
  // The stated cost of one physics step for the cost model [ns].
  const double cost_ns = a.step_cost.empty() ? opts.stated_step_cost_ns : parse_number(a.step_cost, "--step-cost");
  if (!(cost_ns >= 0.0)) throw std::invalid_argument(fmt::format("--step-cost must be >= 0 ns, got {}", a.step_cost));
  const loop_row r = run_loop_config(*problem, a.method, c, opts);
  const loop_cost cost = cost_verdict(c, cost_ns, "stated");
  if (a.json)
    std::cout << one_loop_json(a, *problem, c, opts, r, cost).dump(2) << "\n";
  else
    print_one_loop(a, *problem, c, opts, r, cost);
  const bool trusted = r.note.rfind("no trusted truth", 0) != 0;
  return trusted ? 0 : 1;
}

int run_study(const loop_args& a) {
  const std::string out = a.out.empty() ? "results/loop.h5" : a.out;
  sweep_options so;
  so.problems = {a.problem};
  make_problem(a.problem);  // names an unknown problem first
  so.methods = {loop_method_info(a.method).name};
  for (const auto& s : a.sets) add_override(so.overrides, s, so.problems);
  so.parts = {"sweep", "loop"};  // the loop study reads the sweep's problems and its rows' timings
  so.loop.problems = so.problems;
  so.loop.methods = so.methods;
  so.progress = !a.quiet;
  validate(so);
  check_writable(out);
  const study s = run_sweep(so);
  write_study(s, out);
  const auto& ls = s.results.get<loop_study>();
  if (!a.quiet && !ls.problems.empty()) {
    const auto& lp = ls.problems.front();
    const auto& m = lp.methods.front();
    const auto& o = ls.options;
    fmt::print("{} with {}: max shown error [{}] at a {:g} Hz display (constant clock, clamp {:g} s)\n", lp.name,
               m.info.name, lp.position_unit, o.reference_display_hz, o.clamp_s);
    table grid{{right_column("physics", "Hz")}, {}};
    for (loop_design d : all_loop_designs) grid.columns.push_back(right_column(std::string(to_string(d))));
    for (double ph : o.physics_hz) {
      std::vector<std::string> cells{fmt::format("{:g}", ph)};
      for (loop_design d : all_loop_designs) {
        const auto r = std::find_if(m.rows.begin(), m.rows.end(), [&](const auto& r) {
          return r.clock == "constant" && r.config.display_hz == o.reference_display_hz && r.config.design == d &&
                 (d == loop_design::variable || r.config.physics_hz == ph);
        });
        cells.push_back(r == m.rows.end() ? "-" : fmt::format("{:.3g}", r->shown_err_max));
      }
      grid.add(std::move(cells));
    }
    fmt::print("{}", render_text(grid, ""));
    for (const auto& c : cheapest_designs(m, o))
      if (c.display_hz == o.reference_display_hz)
        fmt::print("cheapest under {:g} {}: {}\n", c.target, lp.position_unit,
                   c.found ? fmt::format("{}{} ({:.3g} steps a frame, error {:.3g})", c.design,
                                         std::isfinite(c.physics_hz) ? fmt::format(" at {:g} Hz", c.physics_hz) : "",
                                         c.steps_per_frame_mean, c.shown_err_max)
                           : std::string("none of the designs at these physics rates"));
  }
  std::fflush(stdout);
  fmt::print(stderr, "wrote {} (the loop study of {} with {}, {:.2f} s)\n", out, a.problem, a.method, ls.wall_seconds);
  return report_study_outcome(s, "stepbench", a.strict);
}

int run_loop_command(const loop_args& a) {
  if (!a.design.empty()) return run_one(a);
  for (const auto& o : one_config_options)
    if (!(a.*o.text).empty())
      throw std::invalid_argument(fmt::format("{} applies to one configuration: give --design", o.name));
  if (a.json) throw std::invalid_argument("--json applies to one configuration: give --design");
  return run_study(a);
}

}  // namespace

command add_loop(CLI::App& app) {
  auto a = std::make_shared<loop_args>();
  auto* sub = app.add_subcommand(
      "loop", "the game loop around an integrator: what each loop design shows at each displayed frame");
  sub->add_option("--problem", a->problem, "problem name (see list)")->required();
  sub->add_option("--integrator,--method", a->method, "one of our fixed-step integrators")->required();
  sub->add_option("--set", a->sets, "override a parameter, problem.name=value or name=value (repeatable)");
  sub->add_option("--out", a->out, "the whole loop study of the pair into this study file (default results/loop.h5)");
  sub->add_option("--design", a->design, "one configuration: variable, fixed, interpolated or substeps");
  for (const auto& o : one_config_options) sub->add_option(o.name, (*a).*o.text, o.help);
  sub->add_flag("--json", a->json, "print JSON (one configuration)");
  sub->add_flag("--quiet", a->quiet, "study form: print only the summary line");
  sub->add_flag("--strict", a->strict, "study form: exit 3 when a method failed on a case of its sweep");
  sub->footer(
      "exit codes: 0 done (a method's failure on a case is a finding recorded in the study); 1 a file error, or no "
      "trusted truth; 2 bad usage; 3 with --strict, the study was written but a case of its sweep failed\n");
  return {sub, [a] { return run_loop_command(*a); }};
}

}  // namespace stepbench::cli
