#include "core/study_file.hpp"

#include <H5Cpp.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "build_info.hpp"

namespace stepbench {
namespace {

// One row of /<problem>/<integrator>/convergence. Field names are the public format.
struct convergence_record {
  double dt;
  std::int64_t steps;
  std::int64_t force_evals;
  double err_pos_final;
  double err_vel_final;
  double err_pos_max;
  double err_pos_rms;
  double energy_drift;
  double energy_err_max;
  std::int8_t diverged;
  double time_ns;
  std::int64_t repetitions;
  std::int8_t cut;
};

// One row of /<problem>/<peer>/work_precision.
struct peer_record {
  double param;
  std::int64_t steps;
  std::int64_t force_evals;
  double err_pos_final;
  double err_pos_max;
  std::int8_t diverged;
  double time_ns;
  std::int64_t repetitions;
  std::int8_t cut;
};

// The timing fields are written only for a timed study, so an untimed file does not
// carry columns of NaN that a reader could mistake for measurements. This is the memory
// type (the struct's full size, whatever members are chosen); the file gets it packed.
H5::CompType convergence_type(bool timed) {
  H5::CompType t(sizeof(convergence_record));
#define STEPBENCH_FIELD(name, type) t.insertMember(#name, HOFFSET(convergence_record, name), type)
  STEPBENCH_FIELD(dt, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(steps, H5::PredType::NATIVE_INT64);
  STEPBENCH_FIELD(force_evals, H5::PredType::NATIVE_INT64);
  STEPBENCH_FIELD(err_pos_final, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(err_vel_final, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(err_pos_max, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(err_pos_rms, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(energy_drift, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(energy_err_max, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(diverged, H5::PredType::NATIVE_INT8);
  if (timed) {
    STEPBENCH_FIELD(time_ns, H5::PredType::NATIVE_DOUBLE);
    STEPBENCH_FIELD(repetitions, H5::PredType::NATIVE_INT64);
    STEPBENCH_FIELD(cut, H5::PredType::NATIVE_INT8);
  }
#undef STEPBENCH_FIELD
  return t;
}

H5::CompType peer_type() {
  H5::CompType t(sizeof(peer_record));
#define STEPBENCH_FIELD(name, type) t.insertMember(#name, HOFFSET(peer_record, name), type)
  STEPBENCH_FIELD(param, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(steps, H5::PredType::NATIVE_INT64);
  STEPBENCH_FIELD(force_evals, H5::PredType::NATIVE_INT64);
  STEPBENCH_FIELD(err_pos_final, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(err_pos_max, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(diverged, H5::PredType::NATIVE_INT8);
  STEPBENCH_FIELD(time_ns, H5::PredType::NATIVE_DOUBLE);
  STEPBENCH_FIELD(repetitions, H5::PredType::NATIVE_INT64);
  STEPBENCH_FIELD(cut, H5::PredType::NATIVE_INT8);
#undef STEPBENCH_FIELD
  return t;
}

void attr(H5::H5Object& obj, const std::string& name, const std::string& value) {
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  obj.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, value);
}
void attr(H5::H5Object& obj, const std::string& name, const char* value) { attr(obj, name, std::string(value)); }
void attr(H5::H5Object& obj, const std::string& name, double value) {
  obj.createAttribute(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace(H5S_SCALAR))
      .write(H5::PredType::NATIVE_DOUBLE, &value);
}
void attr(H5::H5Object& obj, const std::string& name, long value) {
  const std::int64_t v = value;
  obj.createAttribute(name, H5::PredType::NATIVE_INT64, H5::DataSpace(H5S_SCALAR)).write(H5::PredType::NATIVE_INT64, &v);
}
void attr(H5::H5Object& obj, const std::string& name, int value) { attr(obj, name, static_cast<long>(value)); }
void attr(H5::H5Object& obj, const std::string& name, const std::vector<int>& values) {
  const hsize_t n = values.size();
  H5::DataSpace space = n ? H5::DataSpace(1, &n) : H5::DataSpace(H5S_NULL);
  auto a = obj.createAttribute(name, H5::PredType::NATIVE_INT, space);
  if (n) a.write(H5::PredType::NATIVE_INT, values.data());
}

void dataset(H5::Group& g, const std::string& name, const std::vector<double>& v) {
  const hsize_t n = v.size();
  g.createDataSet(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, &n)).write(v.data(), H5::PredType::NATIVE_DOUBLE);
}
void dataset(H5::Group& g, const std::string& name, const std::vector<std::vector<double>>& rows) {
  const hsize_t dims[2] = {rows.size(), rows.empty() ? 0 : rows.front().size()};
  std::vector<double> flat;
  for (const auto& r : rows) flat.insert(flat.end(), r.begin(), r.end());
  g.createDataSet(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace(2, dims)).write(flat.data(), H5::PredType::NATIVE_DOUBLE);
}

void write_reference(H5::Group& parent, const reference_check& ref, const std::string& truth_source, int dim) {
  const auto& sol = ref.solution;
  H5::Group g = parent.createGroup(sol.source);
  const auto& y = sol.y.back();
  dataset(g, "position", std::vector<double>(y.begin(), y.begin() + dim));
  dataset(g, "velocity", std::vector<double>(y.begin() + dim, y.end()));
  dataset(g, "state", sol.y);  // [x; v] at the problem's sample_times
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
  attr(g, "err_pos_rel", ref.vs.pos_rel);
  attr(g, "err_vel_rel", ref.vs.vel_rel);
  attr(g, "is_truth", static_cast<int>(sol.source == truth_source));
}

void write_fit(H5::Group& g, const fit_result& fit) {
  attr(g, "observed_order", fit.order);
  attr(g, "fit_status", to_string(fit.state));
  attr(g, "fit_metric", "err_pos_max");
  attr(g, "fit_levels", fit.levels);
  attr(g, "fit_residual_log10", fit.residual);
  attr(g, "fit_note", fit.note);
}

void write_integrator(H5::Group& parent, const integrator_study& is, bool timed) {
  H5::Group g = parent.createGroup(is.info.name);
  attr(g, "expected_order", is.info.order);
  attr(g, "exact_for_problem", static_cast<int>(is.fit.state == fit_result::status::exact));
  write_fit(g, is.fit);
  attr(g, "description", is.info.description);
  std::vector<convergence_record> rows;
  for (const auto& r : is.rows) {
    const auto& m = r.metrics;
    rows.push_back({r.dt, r.steps, r.force_evals, m.err_pos_final, m.err_vel_final, m.err_pos_max, m.err_pos_rms,
                    m.energy_drift, m.energy_err_max, static_cast<std::int8_t>(m.diverged), r.time.time_ns,
                    r.time.repetitions, static_cast<std::int8_t>(r.time.cut)});
  }
  const hsize_t n = rows.size();
  const auto memory_type = convergence_type(timed);
  H5::CompType file_type;  // a copy (H5Tcopy): CompType's copy constructor shares the id
  file_type.copy(memory_type);
  file_type.pack();
  g.createDataSet("convergence", file_type, H5::DataSpace(1, &n)).write(rows.data(), memory_type);
}

void write_peer(H5::Group& parent, const peer_study& ps) {
  H5::Group g = parent.createGroup(ps.name);
  attr(g, "kind", ps.kind);
  attr(g, "description", ps.description);
  attr(g, "declared_order", ps.declared_order);
  write_fit(g, ps.fit);
  std::vector<peer_record> rows;
  for (const auto& r : ps.rows)
    rows.push_back({r.param, r.steps, r.force_evals, r.err_pos_final, r.err_pos_max, static_cast<std::int8_t>(r.diverged),
                    r.time.time_ns, r.time.repetitions, static_cast<std::int8_t>(r.time.cut)});
  const hsize_t n = rows.size();
  const auto memory_type = peer_type();
  H5::CompType file_type;  // a copy (H5Tcopy): CompType's copy constructor shares the id
  file_type.copy(memory_type);
  file_type.pack();
  g.createDataSet("work_precision", file_type, H5::DataSpace(1, &n)).write(rows.data(), memory_type);
}

void write_problem(H5::H5File& file, const problem_study& ps, bool timed) {
  const auto& p = *ps.problem;
  H5::Group g = file.createGroup(std::string(p.name()));
  for (const auto& param : p.params()) attr(g, param.name, param.value);
  attr(g, "horizon", ps.horizon);
  attr(g, "dim", p.dim());
  attr(g, "position_unit", std::string(p.position_unit()));
  attr(g, "description", std::string(p.description()));
  attr(g, "has_closed_form", static_cast<int>(p.has_closed_form()));
  attr(g, "has_energy", static_cast<int>(p.has_energy()));
  attr(g, "truth_source", ps.truth.source);
  attr(g, "pos_scale", ps.truth.pos_scale);
  attr(g, "vel_scale", ps.truth.vel_scale);
  attr(g, "energy_scale", ps.truth.energy_scale);
  dataset(g, "sample_times", ps.truth.times);
  dataset(g, "truth_state", ps.truth.y);
  H5::Group refs = g.createGroup("reference");
  for (const auto& ref : ps.truth.references) write_reference(refs, ref, ps.truth.source, p.dim());
  for (const auto& is : ps.integrators) write_integrator(g, is, timed);
  for (const auto& peer : ps.peers) write_peer(g, peer);
}

std::string temp_path_for(const std::string& path) { return fmt::format("{}.tmp.{}", path, ::getpid()); }

}  // namespace

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  return "unknown";
}

std::string utc_now_iso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
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

void write_study(const study& s, const std::string& path) {
  check_writable(path);
  const std::string tmp = temp_path_for(path);
  H5::Exception::dontPrint();
  try {
    H5::H5File file(tmp, H5F_ACC_TRUNC);
    attr(file, "format_version", study_format_version);
    attr(file, "version", build_info::version);
    attr(file, "git_commit", build_info::git_commit);
    attr(file, "compiler", build_info::compiler);
    attr(file, "build_type", build_info::build_type);
    attr(file, "created_utc", utc_now_iso8601());
    attr(file, "cpu", cpu_model());
    attr(file, "cores", static_cast<int>(std::thread::hardware_concurrency()));
    attr(file, "levels", s.options.levels);
    attr(file, "base_steps", s.options.base_steps);
    attr(file, "sample_count", s.options.sample_count);
    attr(file, "reference_rtol", s.options.tol.rtol);
    attr(file, "reference_atol", s.options.tol.atol);
    attr(file, "fit_metric", "err_pos_max");
    attr(file, "divergence_factor", blowup_factor);
    attr(file, "wall_seconds", s.wall_seconds);
    attr(file, "timing", static_cast<int>(s.timed.has_value()));
    if (s.timed) {
      const auto& t = *s.timed;
      attr(file, "benchmark_mode", t.mode);
      attr(file, "benchmark_min_time_s", t.min_time_s);
      attr(file, "benchmark_repetitions", t.repetitions);
      attr(file, "benchmark_case_budget_s", t.case_budget_s);
      attr(file, "benchmark_wall_seconds", t.wall_seconds);
      attr(file, "cpu_scaling_enabled", t.cpu_scaling_enabled);
      attr(file, "num_cpus", t.num_cpus);
      attr(file, "mhz_per_cpu", t.mhz_per_cpu);
    }
    for (const auto& ps : s.problems) write_problem(file, ps, s.timed.has_value());
    file.close();
  } catch (const H5::Exception& e) {
    std::remove(tmp.c_str());
    throw std::runtime_error(fmt::format("cannot write results file '{}': HDF5: {}", path, e.getDetailMsg()));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw std::runtime_error(fmt::format("cannot write results file '{}': {}", path, ec.message()));
  }
}

}  // namespace stepbench
