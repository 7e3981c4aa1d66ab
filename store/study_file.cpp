#include "store/study_file.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "build_info.hpp"
#include "judge/rows.hpp"
#include "registry/plugins.hpp"
#include "registry/registry.hpp"
#include "registry/scenes.hpp"
#include "run/machine.hpp"
#include "run/sweep.hpp"
#include "store/h5.hpp"
#include "store/temp_file_guard.hpp"
#include "study/energy.hpp"
#include "study/loop.hpp"
#include "study/stability.hpp"
#include "study/substeps.hpp"
#include "study/verdict.hpp"

namespace stepbench {
namespace {

using h5::attr;

void write_reference(H5::Group& parent, const reference_check& ref, const std::string& truth_source, int dim) {
  H5::Group g = parent.createGroup(ref.source);
  attr(g, "status", ref.status);
  attr(g, "reason", ref.reason);
  attr(g, "is_truth", static_cast<int>(ref.source == truth_source));
  const auto& sol = ref.solution;
  if (ref.status != "failed" && !sol.y.empty()) {
    const auto& y = sol.y.back();
    h5::dataset(g, "position", std::vector<double>(y.begin(), y.begin() + dim));
    h5::dataset(g, "velocity", std::vector<double>(y.begin() + dim, y.end()));
    h5::dataset(g, "state", sol.y);  // [x; v] at the problem's sample_times
  }
  attr(g, "steps", sol.stats.steps);
  attr(g, "failed_steps", sol.stats.failed_steps);
  attr(g, "rhs_evals", sol.stats.rhs_evals);
  attr(g, "lin_rhs_evals", sol.stats.lin_rhs_evals);
  attr(g, "jac_evals", sol.stats.jac_evals);
  attr(g, "rhs_evals_counted", sol.stats.rhs_evals_counted);
  attr(g, "rtol", sol.stats.rtol);
  attr(g, "atol", sol.stats.atol);
  attr(g, "wall_seconds", sol.stats.wall_seconds);
  attr(g, "compared_with", ref.compared_with);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  attr(g, "err_pos_rel", ref.compared_with.empty() ? nan : ref.vs.pos_rel);
  attr(g, "err_vel_rel", ref.compared_with.empty() ? nan : ref.vs.vel_rel);
}

void write_method(H5::Group& parent, const method_study& ms, bool timed) {
  H5::Group g = parent.createGroup(ms.info.name);
  const auto& info = ms.info;
  attr(g, "origin", std::string(to_string(info.origin)));
  attr(g, "kind", std::string(to_string(info.kind)));
  attr(g, "param_kind", std::string(param_name(info.kind)));
  attr(g, "declared_order", info.declared_order);
  attr(g, "description", info.description);
  attr(g, "library", info.library);
  attr(g, "symplectic", static_cast<int>(info.traits.symplectic));
  attr(g, "reuses_last_force", static_cast<int>(info.traits.reuses_last_force));
  attr(g, "needs_jacobian", static_cast<int>(info.traits.needs_jacobian));
  attr(g, "error_estimate", static_cast<int>(info.traits.error_estimate));
  attr(g, "dense_output", static_cast<int>(info.traits.dense_output));
  // The fit: observed order against dt for fixed-step methods; for adaptive ones the
  // slope of the error against the tolerance (1: the error follows the tolerance).
  attr(g, "fit_status", to_string(ms.fit.state));
  attr(g, "fit_metric", "err_pos_max");
  attr(g, "fit_param", std::string(param_name(info.kind)));
  attr(g, "fit_slope", ms.fit.order);
  attr(g, "observed_order",
       info.kind == method_kind::fixed_step ? ms.fit.order : std::numeric_limits<double>::quiet_NaN());
  attr(g, "fit_levels", ms.fit.levels);
  attr(g, "fit_residual_log10",
       ms.fit.state == fit_result::status::fitted ? ms.fit.residual : std::numeric_limits<double>::quiet_NaN());
  attr(g, "fit_note", ms.fit.note);
  attr(g, "exact_for_problem", static_cast<int>(ms.fit.state == fit_result::status::exact));
  attr(g, "declared_order_holds", ms.declared_order_holds);
  attr(g, "ladder_end", ms.ladder_end);

  runs_columns().write(g, "runs", ms.rows, timed);
}

// A row of the equal-error table: a method's cost at a metric's target, ranked.
struct equal_error_row {
  std::string metric;
  double target = 0.0;
  long rank = 0;
  std::string method, origin, kind;
  wp_pick pick;
  std::string cost_kind;
  bool is_answer = false;
};

const auto ranked_equal_error_columns = column_map<equal_error_row>("equal_error", "/problems/<p>/equal_error")
                                            .member("metric", &equal_error_row::metric)
                                            .member("target", &equal_error_row::target)
                                            .member("rank", &equal_error_row::rank)
                                            .member("method", &equal_error_row::method)
                                            .member("origin", &equal_error_row::origin)
                                            .member("kind", &equal_error_row::kind)
                                            .member("param", &equal_error_row::pick, &wp_pick::param)
                                            .member("error", &equal_error_row::pick, &wp_pick::error)
                                            .member("cost_kind", &equal_error_row::cost_kind)
                                            .member("cost", &equal_error_row::pick, &wp_pick::cost)
                                            .member("cost_lo", &equal_error_row::pick, &wp_pick::cost_lo)
                                            .member("cost_hi", &equal_error_row::pick, &wp_pick::cost_hi)
                                            .member("time_ns", &equal_error_row::pick, &wp_pick::time_ns)
                                            .member("force_evals", &equal_error_row::pick, &wp_pick::force_evals)
                                            .member("interpolated", &equal_error_row::pick, &wp_pick::interpolated)
                                            .member("is_answer", &equal_error_row::is_answer);

// The equal-error table: for each metric and target, every method that reaches it with
// its cost at equal error interpolated on its measured curve, ranked (core/work_precision.hpp).
void write_equal_error(H5::Group& g, const problem_study& ps, bool timed) {
  std::vector<equal_error_row> rows;
  for (const char* m : {"err_pos_max", "err_pos_final"}) {
    const auto methods = work_precision_input(ps, m);
    for (double tgt : equal_error_targets()) {
      const auto r = cheapest(methods, tgt, timed, m, ps.unit);
      const auto answer = r.answer(methods);
      for (std::size_t k = 0; k < r.ranked.size(); ++k) {
        const auto& p = r.ranked[k];
        const auto& wm = methods[p.method];
        rows.push_back({m, tgt, static_cast<long>(k + 1), wm.name, std::string(to_string(wm.origin)),
                        std::string(to_string(wm.kind)), p, r.cost, answer && answer->method == p.method});
      }
    }
  }
  ranked_equal_error_columns.write(g, "equal_error", rows);
}

struct front_row {
  std::string method;
  double param = 0.0, cost = 0.0, err_pos_max = 0.0;
};

const auto front_columns = column_map<front_row>("front", "/problems/<p>/front_force_evals, /problems/<p>/front_time")
                               .member("method", &front_row::method)
                               .member("param", &front_row::param)
                               .member("cost", &front_row::cost)
                               .member("err_pos_max", &front_row::err_pos_max);

void write_front(H5::Group& g, const problem_study& ps, bool by_time, bool timed) {
  const auto methods = work_precision_input(ps, "err_pos_max");
  std::vector<front_row> rows;
  for (const auto& p : pareto_front(methods, by_time, timed))
    rows.push_back({methods[p.method].name, methods[p.method].rows[p.row].param, p.cost, p.error});
  front_columns.write(g, by_time ? "front_time" : "front_force_evals", rows);
}

void write_problem(H5::Group& parent, const problem_study& ps, const std::optional<timing_settings>& timing) {
  const bool timed = timing.has_value();
  const auto& p = *ps.problem;
  H5::Group g = parent.createGroup(std::string(p.name()));
  // The machine that ran (and timed) this problem: the root's in a study run on one
  // machine; in a merge of shards, each problem keeps its shard's (stepbench merge).
  write_machine(g, timing);
  parameters_columns().write(g, "parameters", p.params());
  attr(g, "horizon", ps.horizon);
  attr(g, "dim", p.dim());
  attr(g, "position_unit", std::string(p.position_unit()));
  attr(g, "description", std::string(p.description()));
  attr(g, "has_closed_form", static_cast<int>(p.has_closed_form()));
  attr(g, "has_energy", static_cast<int>(p.has_energy()));
  attr(g, "has_jacobian", static_cast<int>(p.has_jacobian()));
  attr(g, "has_angular_momentum", static_cast<int>(p.has_angular_momentum()));
  attr(g, "angmom_scale", ps.truth.angmom_scale);
  // Contacts: the mode, and the exact contacts up to the horizon (-1 and empty without).
  attr(g, "contact_mode", std::string(p.contact_mode()));
  attr(g, "contacts_exact", ps.truth.contact_count);
  if (!ps.truth.contact_times.empty()) h5::dataset(g, "contact_times", ps.truth.contact_times);
  // Every method that runs on the problem, so a reader can tell a method that does not
  // apply (the baseline off its two problems) from one missing from a damaged file.
  std::string applies;
  for (const auto& m : p.methods()) applies += (applies.empty() ? "" : ",") + m.name;
  attr(g, "methods", applies);
  attr(g, "truth_source", ps.truth.source);
  attr(g, "truth_trusted", static_cast<int>(ps.truth.trusted));
  attr(g, "truth_note", ps.truth.note);
  attr(g, "agreement_limit", ps.truth.agreement_limit);
  attr(g, "pos_scale", ps.truth.pos_scale);
  attr(g, "vel_scale", ps.truth.vel_scale);
  attr(g, "energy_scale", ps.truth.energy_scale);
  h5::dataset(g, "sample_times", ps.truth.times);
  h5::dataset(g, "truth_state", ps.truth.y);
  H5::Group refs = g.createGroup("reference");
  for (const auto& ref : ps.truth.references) write_reference(refs, ref, ps.truth.source, p.dim());
  H5::Group methods = g.createGroup("methods");
  for (const auto& ms : ps.methods) write_method(methods, ms, timed);
  write_equal_error(g, ps, timed);
  write_front(g, ps, false, timed);
  if (timed) write_front(g, ps, true, timed);
}

// A method's group as write_method (store/study_file.cpp) writes it.
method_study read_method(const H5::Group& g, const std::string& name) {
  method_study m;
  // The build's own declaration where it has the method (capabilities, evaluations a
  // step), the file's figures over it.
  if (const method_info* known = registered_method(name)) m.info = *known;
  m.info.name = name;
  m.info.origin = parse_enum(h5::string_attr(g, "origin"),
                             {method_origin::ours, method_origin::peer, method_origin::baseline, method_origin::plugin},
                             "method origin");
  m.info.kind = parse_enum(h5::string_attr(g, "kind"), {method_kind::fixed_step, method_kind::adaptive}, "method kind");
  m.info.description = h5::string_attr(g, "description");
  m.info.library = h5::string_attr(g, "library");
  m.info.declared_order = h5::double_attr(g, "declared_order");
  using fit = fit_result::status;
  m.fit.state =
      parse_enum(h5::string_attr(g, "fit_status"), {fit::fitted, fit::exact, fit::insufficient}, "fit_status");
  m.fit.order = h5::double_attr(g, "fit_slope");
  for (long level : h5::int_array_attr(g, "fit_levels")) m.fit.levels.push_back(static_cast<int>(level));
  m.declared_order_holds = static_cast<int>(h5::long_attr(g, "declared_order_holds"));
  m.rows = runs_columns().read(g, "runs");
  return m;
}

// A problem's group as write_problem writes it: its facts, the truth's outcome and
// scales (not its states), the references' outcomes and every method.
problem_study read_problem(const H5::Group& g, const std::string& name) {
  problem_study p;
  p.name = name;
  p.unit = h5::string_attr(g, "position_unit");
  p.horizon = h5::double_attr(g, "horizon");
  p.dim = static_cast<int>(h5::double_attr(g, "dim"));
  p.truth.source = h5::string_attr(g, "truth_source");
  p.truth.trusted = h5::long_attr(g, "truth_trusted") != 0;
  p.truth.pos_scale = h5::double_attr(g, "pos_scale");
  p.truth.vel_scale = h5::double_attr(g, "vel_scale");
  for (const auto& q : parameters_columns().read(g, "parameters")) p.params[q.name] = q.value;
  if (h5::is_group(g, "reference")) {
    const H5::Group refs = g.openGroup("reference");
    for (const auto& src : h5::children(refs)) {
      const H5::Group r = refs.openGroup(src);
      reference_check ref;
      ref.source = src;
      ref.status = h5::string_attr(r, "status");
      ref.reason = h5::string_attr(r, "reason");
      ref.compared_with = h5::string_attr(r, "compared_with");
      ref.vs.pos_rel = h5::double_attr(r, "err_pos_rel");
      ref.vs.vel_rel = h5::double_attr(r, "err_vel_rel");
      p.truth.references.push_back(std::move(ref));
    }
  }
  if (!h5::is_group(g, "methods"))
    throw std::runtime_error(fmt::format("missing group 'methods' in {}", g.getObjName()));
  const H5::Group methods = g.openGroup("methods");
  for (const auto& m : h5::children(methods)) p.methods.push_back(read_method(methods.openGroup(m), m));
  return p;
}

}  // namespace

void write_problems(H5::Group& root, const study& s) {
  H5::Group problems = root.createGroup("problems");
  for (const auto& ps : s.problems) write_problem(problems, ps, s.timed);
}

void read_problems(const H5::Group& root, study& s) {
  const H5::Group problems = root.openGroup("problems");
  for (const auto& name : h5::children(problems)) s.problems.push_back(read_problem(problems.openGroup(name), name));
}

void write_machine(H5::H5Object& obj, const std::optional<timing_settings>& timing) {
  attr(obj, "cpu", cpu_model());
  attr(obj, "cores", core_count());
  if (timing) {
    attr(obj, "num_cpus", timing->num_cpus);
    attr(obj, "mhz_per_cpu", timing->mhz_per_cpu);
    attr(obj, "cpu_scaling_enabled", timing->cpu_scaling_enabled);
  }
}

namespace {

std::string temp_path_for(const std::string& path) { return fmt::format("{}.tmp.{}", path, ::getpid()); }

// Writes `bytes` to a new file at `path`; 0, or the errno of the call that failed
// (ENOSPC, EDQUOT, EFBIG under temp_file_guard).
int write_whole(const std::string& path, const std::vector<unsigned char>& bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) return errno;
  const int error = write_bytes(fd, bytes.data(), bytes.size());
  return ::close(fd) == 0 || error ? error : errno;
}

}  // namespace

int write_bytes(int fd, const void* data, std::size_t size) {
  for (std::size_t done = 0; done < size;) {
    const ssize_t n = ::write(fd, static_cast<const char*>(data) + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n < 0 ? errno : EIO;
    done += static_cast<std::size_t>(n);
  }
  return 0;
}

void write_root_attributes(H5::H5File& file, const study& s, const std::string& described_options) {
  attr(file, "format_version", study_format_version);
  attr(file, "version", build_info::version);
  attr(file, "git_commit", build_info::git_commit);
  attr(file, "compiler", build_info::compiler);
  attr(file, "build_type", build_info::build_type);
  attr(file, "dependencies", build_info::dependencies);
  attr(file, "build_flags", build_info::build_flags);
  attr(file, "created_utc", utc_now_iso8601());
  write_machine(file, s.timed);
  // The plugins whose methods ran (docs/plugins.md), as a JSON array: each one's path as
  // given, the FNV-1a 64-bit hash of its bytes, its ABI version and its methods. Only in
  // a study that loaded any.
  if (!loaded_plugins().empty()) {
    nlohmann::json plugins = nlohmann::json::array();
    for (const auto& p : loaded_plugins())
      plugins.push_back(
          {{"path", p.path}, {"fnv1a_64", p.fnv1a_64}, {"abi_version", p.abi_version}, {"methods", p.methods}});
    attr(file, "plugins", plugins.dump());
  }
  // The scene files whose scenes ran (docs/scenes.md), likewise: each one's name, path as
  // given and FNV-1a 64-bit hash; the file's own text is the scene's definition.
  if (!loaded_scenes().empty()) {
    nlohmann::json scenes = nlohmann::json::array();
    for (const auto& sc : loaded_scenes())
      scenes.push_back({{"name", sc.name}, {"path", sc.path}, {"fnv1a_64", sc.fnv1a_64}});
    attr(file, "scenes", scenes.dump());
  }
  if (s.swept) {
    // Which problems the study selected and which share of them this file holds
    // (sweep --shard K/N, stepbench_bench --shard=K/N); stepbench merge reads these.
    attr(file, "selection", fmt::format("{}", fmt::join(selected_problems(s.options), ",")));
    attr(file, "shard_index", s.options.shard_index);
    attr(file, "shard_count", s.options.shard_count);
    attr(file, "sweep_options", described_options);
  }
  attr(file, "levels", s.options.levels);
  attr(file, "max_levels", s.options.max_levels);
  attr(file, "base_steps", s.options.base_steps);
  attr(file, "sample_count", s.options.sample_count);
  attr(file, "tolerances", s.options.tolerances);
  attr(file, "reference_rtol", s.options.tol.rtol);
  attr(file, "reference_atol", s.options.tol.atol);
  attr(file, "fit_metric", "err_pos_max");
  attr(file, "divergence_factor", blowup_factor);
  attr(file, "work_budget", s.options.limits.work_budget);
  attr(file, "max_adaptive_steps", s.options.limits.max_steps);
  attr(file, "equal_error_targets", equal_error_targets());
  attr(file, "wall_seconds", s.wall_seconds);
  attr(file, "timing", static_cast<int>(s.timed.has_value()));
  if (s.timed) {
    const auto& t = *s.timed;
    attr(file, "benchmark_mode", t.mode);
    attr(file, "benchmark_min_time_s", t.min_time_s);
    attr(file, "benchmark_repetitions", t.repetitions);
    attr(file, "benchmark_case_budget_s", t.case_budget_s);
    attr(file, "benchmark_wall_seconds", t.wall_seconds);
  }
}

const column_map<param_value>& parameters_columns() {
  using R = param_value;
  static const auto columns = column_map<R>("parameters", "/problems/<p>/parameters, /energy/<p>/parameters")
                                  .member("name", &R::name)
                                  .member("value", &R::value)
                                  .member("unit", &R::unit)
                                  .derived("kind", [](const R& q) { return q.kind(); })
                                  .derived("value_name", [](const R& q) { return q.value_name(); })
                                  .member("default", &R::default_value)
                                  .derived("allowed", [](const R& q) { return q.allowed.text(); })
                                  .member("description", &R::description);
  return columns;
}

const column_map<method_row>& runs_columns() {
  using R = method_row;
  using W = work_counters;
  using M = run_metrics;
  using T = timing;
  // One row per ladder entry (the substeps study's runs too).
  static const auto columns = column_map<R>("runs", "/problems/<p>/methods/<m>/runs")
                                  .member("param", &R::param)
                                  .member("steps", &R::steps)
                                  .member("rejected_steps", &R::rejected_steps)
                                  .member("force_evals", &R::work, &W::force_evals)
                                  .member("jacobian_evals", &R::work, &W::jacobian_evals)
                                  .member("newton_iterations", &R::work, &W::newton_iterations)
                                  .member("linear_solves", &R::work, &W::linear_solves)
                                  .member("err_pos_final", &R::metrics, &M::err_pos_final)
                                  .member("err_vel_final", &R::metrics, &M::err_vel_final)
                                  .member("err_pos_max", &R::metrics, &M::err_pos_max)
                                  .member("err_pos_rms", &R::metrics, &M::err_pos_rms)
                                  .member("energy_drift", &R::metrics, &M::energy_drift)
                                  .member("energy_err_max", &R::metrics, &M::energy_err_max)
                                  .member("angmom_drift", &R::metrics, &M::angmom_drift)
                                  .member("angmom_err_max", &R::metrics, &M::angmom_err_max)
                                  // Came within format_version 4 (with xpbd): an older file reads it as NaN, no
                                  // constraint view measured, so an older study still compares with a newer one.
                                  .member("constraint_violation_max", &R::metrics, &M::constraint_violation_max)
                                  .missing_as(std::numeric_limits<double>::quiet_NaN())
                                  .member("contacts", &R::metrics, &M::contacts)
                                  .member("contact_count_err", &R::metrics, &M::contact_count_err)
                                  .member("contact_time_err", &R::metrics, &M::contact_time_err)
                                  .member("contact_pos_err", &R::metrics, &M::contact_pos_err)
                                  .member("tunnelled", &R::metrics, &M::tunnelled)
                                  .member("max_penetration", &R::metrics, &M::max_penetration)
                                  .member("diverged", &R::metrics, &M::diverged)
                                  .member("failed", &R::metrics, &M::failed)
                                  .member("skipped", &R::metrics, &M::skipped)
                                  .member("note", &R::metrics, &M::note)
                                  // Timing fields only in a timed study, so an untimed file does not carry columns
                                  // of NaN that a reader could mistake for measurements.
                                  .timed_only()
                                  .member("time_ns", &R::time, &T::time_ns)
                                  .member("time_ns_min", &R::time, &T::time_ns_min)
                                  .member("time_ns_max", &R::time, &T::time_ns_max)
                                  .member("repetitions", &R::time, &T::repetitions)
                                  .member("cut", &R::time, &T::cut);
  return columns;
}

std::vector<schema::table> problems_tables() {
  return {runs_columns().spec(), parameters_columns().spec(), ranked_equal_error_columns.spec(), front_columns.spec()};
}

void check_writable(const std::string& path) {
  if (path.empty()) throw std::runtime_error("cannot write results file '': empty path");
  if (std::filesystem::is_directory(path))
    throw std::runtime_error(fmt::format("cannot write results file '{}': it is a directory", path));
  const std::string tmp = temp_path_for(path);
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw std::runtime_error(fmt::format("cannot write results file '{}': {}", path, std::strerror(errno)));
  std::fclose(f);
  std::remove(tmp.c_str());
}

namespace {

// A file built in memory (HDF5's core driver, no backing store) and named after a
// temporary path beside `path`.
H5::H5File in_memory_file(const std::string& path) {
  H5::FileAccPropList in_memory;
  in_memory.setCore(std::size_t{1} << 20, false);
  return H5::H5File(temp_path_for(path), H5F_ACC_TRUNC, H5::FileCreatPropList::DEFAULT, in_memory);
}

// The file's image.
std::vector<unsigned char> file_image(H5::H5File& file) {
  file.flush(H5F_SCOPE_GLOBAL);
  const ssize_t size = H5Fget_file_image(file.getId(), nullptr, 0);
  std::vector<unsigned char> image(size > 0 ? static_cast<std::size_t>(size) : 0);
  if (size <= 0 || H5Fget_file_image(file.getId(), image.data(), image.size()) != size)
    throw H5::FileIException("H5Fget_file_image", "cannot take the file's image");
  return image;
}

}  // namespace

void write_study_file(const std::string& path, const std::function<void(H5::H5File&)>& fill, std::string_view failing,
                      const std::function<void()>& before_write) {
  check_writable(path);
  H5::Exception::dontPrint();
  std::vector<unsigned char> image;
  try {
    H5::H5File file = in_memory_file(path);
    fill(file);
    image = file_image(file);
    file.close();
  } catch (const H5::Exception& e) {
    throw std::runtime_error(fmt::format("{} '{}': HDF5: {}", failing, path, e.getDetailMsg()));
  }
  if (before_write) before_write();
  write_image(image, path);
}

void write_image(const std::vector<unsigned char>& image, const std::string& path) {
  const std::string tmp = temp_path_for(path);
  const temp_file_guard guard(tmp);
  if (const int error = write_whole(tmp, image)) {
    std::remove(tmp.c_str());
    throw std::runtime_error(fmt::format("cannot write results file '{}': {}", path, std::strerror(error)));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw std::runtime_error(fmt::format("cannot write results file '{}': {}", path, ec.message()));
  }
}

}  // namespace stepbench
