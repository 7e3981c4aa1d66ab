#include "study/study_reader.hpp"

#include <H5Cpp.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "core/measure.hpp"
#include "study/h5.hpp"
#include "study/schema.hpp"
#include "study/study_file.hpp"

namespace stepbench {
namespace {

method_origin parse_origin(const std::string& s) {
  if (s == "ours") return method_origin::ours;
  if (s == "peer") return method_origin::peer;
  if (s == "baseline") return method_origin::baseline;
  throw std::runtime_error(fmt::format("unknown method origin '{}'", s));
}

method_kind parse_kind(const std::string& s) {
  if (s == "fixed_step") return method_kind::fixed_step;
  if (s == "adaptive") return method_kind::adaptive;
  throw std::runtime_error(fmt::format("unknown method kind '{}'", s));
}

study_method read_method(const H5::Group& g, const std::string& name) {
  study_method m;
  m.name = name;
  m.origin = parse_origin(h5::string_attr(g, "origin"));
  m.kind = parse_kind(h5::string_attr(g, "kind"));
  m.description = h5::string_attr(g, "description");
  m.library = h5::string_attr(g, "library");
  m.declared_order = h5::double_attr(g, "declared_order");
  m.fit_status = h5::string_attr(g, "fit_status");
  m.fit_slope = h5::double_attr(g, "fit_slope");
  m.declared_order_holds = static_cast<int>(h5::long_attr(g, "declared_order_holds"));
  m.fit_levels = h5::int_array_attr(g, "fit_levels");
  if (!h5::is_dataset(g, "runs")) throw std::runtime_error(fmt::format("missing dataset 'runs' in {}", g.getObjName()));
  const h5::table_data runs = h5::read_table(g.openDataSet("runs"));
  for (const auto& [field, kind] : runs.fields()) {
    if (kind != h5::table_data::kind::text)
      m.columns[field] = runs.doubles(field);
    else if (field == "note")
      m.notes = runs.strings(field);
  }
  // Every field the schema declares for runs (the timing fields only in a timed study).
  for (const auto& group : schema::find("runs").groups)
    for (const auto& f : group.fields)
      if (!group.timed_only && !runs.has(std::string(f.name)))
        throw std::runtime_error(fmt::format("missing field '{}' in {}/runs", f.name, g.getObjName()));
  return m;
}

study_problem read_problem(const H5::Group& g, const std::string& name) {
  study_problem p;
  p.name = name;
  p.unit = h5::string_attr(g, "position_unit");
  p.truth_source = h5::string_attr(g, "truth_source");
  p.truth_trusted = h5::long_attr(g, "truth_trusted") != 0;
  p.horizon = h5::double_attr(g, "horizon");
  p.pos_scale = h5::double_attr(g, "pos_scale");
  p.vel_scale = h5::double_attr(g, "vel_scale");
  // The declared parameters, apart from the derived attributes (format 3).
  if (!h5::is_dataset(g, "parameters"))
    throw std::runtime_error(fmt::format("missing dataset 'parameters' in {}", g.getObjName()));
  const h5::table_data params = h5::read_table(g.openDataSet("parameters"));
  const auto& names = params.strings("name");
  const auto values = params.doubles("value");
  for (std::size_t i = 0; i < names.size(); ++i) p.params[names[i]] = values[i];
  if (h5::is_group(g, "reference")) {
    const H5::Group refs = g.openGroup("reference");
    for (const auto& src : h5::children(refs)) {
      const H5::Group r = refs.openGroup(src);
      p.references.push_back({src, h5::string_attr(r, "status"), h5::string_attr(r, "reason"),
                              h5::string_attr(r, "compared_with"), h5::double_attr(r, "err_pos_rel"),
                              h5::double_attr(r, "err_vel_rel"), h5::long_attr(r, "is_truth") != 0});
    }
  }
  if (!h5::is_group(g, "methods"))
    throw std::runtime_error(fmt::format("missing group 'methods' in {}", g.getObjName()));
  const H5::Group methods = g.openGroup("methods");
  for (const auto& m : h5::children(methods)) p.methods.push_back(read_method(methods.openGroup(m), m));
  return p;
}

}  // namespace

const std::vector<double>& study_method::col(const std::string& field) const {
  const auto it = columns.find(field);
  if (it == columns.end()) throw std::runtime_error(fmt::format("method {} has no field '{}'", name, field));
  return it->second;
}

const study_method* study_problem::find(const std::string& method) const {
  for (const auto& m : methods)
    if (m.name == method) return &m;
  return nullptr;
}

const study_problem* study_data::find(const std::string& problem) const {
  for (const auto& p : problems)
    if (p.name == problem) return &p;
  return nullptr;
}

namespace {

// The whole file, unchecked for crashes (read_study checks first). Errors are
// std::runtime_error or H5::Exception, without the file's name.
study_data read_file(const std::string& path) {
  study_data out;
  out.path = path;
  if (!H5::H5File::isHdf5(path)) throw std::runtime_error("not an HDF5 file");
  const H5::H5File file(path, H5F_ACC_RDONLY);
  if (!file.attrExists("format_version")) throw std::runtime_error("not a stepbench study (no format_version)");
  out.format_version = h5::long_attr(file, "format_version");
  if (out.format_version > study_format_version)
    throw std::runtime_error(fmt::format("written by a newer stepbench (format_version {}; this build reads {} to {})",
                                         out.format_version, study_format_read_min, study_format_version));
  if (out.format_version < study_format_read_min)
    throw std::runtime_error(fmt::format("format_version {} is older than this build reads ({}); run the study again",
                                         out.format_version, study_format_read_min));
  out.meta = h5::string_attrs(file);
  out.settings = h5::number_attrs(file, false);
  out.timed = h5::long_attr(file, "timing") != 0;
  if (h5::is_group(file, "stability")) {
    const H5::Group g = file.openGroup("stability");
    if (!h5::is_dataset(g, "limits")) throw std::runtime_error("missing dataset /stability/limits");
    const h5::table_data limits = h5::read_table(g.openDataSet("limits"));
    const auto &integrator = limits.strings("integrator"), &test = limits.strings("test");
    const auto theory = limits.doubles("theory"), measured = limits.doubles("measured");
    const auto &all = limits.ints("unstable_for_all_dt"), &uncond = limits.ints("unconditionally_stable");
    for (std::size_t i = 0; i < integrator.size(); ++i)
      out.stability.push_back({integrator[i], test[i], theory[i], measured[i], all[i] != 0, uncond[i] != 0});
  }
  if (!h5::is_group(file, "problems")) throw std::runtime_error("missing group 'problems'");
  const H5::Group problems = file.openGroup("problems");
  for (const auto& name : h5::children(problems)) out.problems.push_back(read_problem(problems.openGroup(name), name));
  return out;
}

// HDF5 1.10 trusts sizes stored in the file where no call of its API can check them
// first (a global heap object's length when it reads a variable-length string, an
// attribute message's size when it looks an attribute up): a damaged file can make it
// copy out of bounds and crash. So the file is read first in a child process, its output
// discarded; the child ends normally whether it read the file or refused it. Returns
// how it ended when it did not ("SIGSEGV"; "exit 1": a sanitizer's report), else "".
std::string crash_reading(const std::string& path) {
  std::fflush(nullptr);
  const pid_t child = ::fork();
  if (child < 0)
    throw std::runtime_error(fmt::format("cannot start the process that checks it: {}", std::strerror(errno)));
  if (child == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    try {
      read_file(path);
    } catch (...) {
    }
    std::_Exit(0);
  }
  int status = 0;
  while (::waitpid(child, &status, 0) < 0)
    if (errno != EINTR)
      throw std::runtime_error(fmt::format("cannot wait for the process that checks it: {}", std::strerror(errno)));
  if (WIFSIGNALED(status)) return fmt::format("SIG{}", sigabbrev_np(WTERMSIG(status)));
  if (WEXITSTATUS(status) != 0) return fmt::format("exit {}", WEXITSTATUS(status));
  return {};
}

}  // namespace

study_data read_study(const std::string& path) {
  const auto fail = [&](const std::string& what) {
    return std::runtime_error(fmt::format("cannot read study file '{}': {}", path, what));
  };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw fail("no such file");
  if (std::filesystem::is_directory(path, ec)) throw fail("it is a directory");
  H5::Exception::dontPrint();
  try {
    if (const std::string crash = crash_reading(path); !crash.empty())
      throw std::runtime_error(fmt::format("damaged: reading it crashes the HDF5 library ({})", crash));
    return read_file(path);
  } catch (const H5::Exception& e) {
    throw fail(fmt::format("HDF5: {} (truncated or corrupt?)", e.getDetailMsg()));
  } catch (const std::runtime_error& e) {
    throw fail(e.what());
  }
}

std::vector<wp_method> work_precision_input(const study_problem& p, const std::string& metric, bool timed) {
  std::vector<wp_method> out;
  for (const auto& m : p.methods) {
    wp_method w{m.name, m.origin, m.kind, {}};
    const auto& param = m.col("param");
    const auto& err = m.col(metric);
    const auto& evals = m.col("force_evals");
    const auto& diverged = m.col("diverged");
    const auto& failed = m.col("failed");
    const auto& skipped = m.col("skipped");
    const std::vector<double> none(param.size(), std::numeric_limits<double>::quiet_NaN()), zeros(param.size(), 0.0);
    const auto& time = timed ? m.col("time_ns") : none;
    const auto& cut = timed ? m.col("cut") : zeros;
    for (std::size_t i = 0; i < param.size(); ++i)
      w.rows.push_back({param[i], err[i], time[i], evals[i],
                        row_completed(diverged[i] != 0, failed[i] != 0, skipped[i] != 0), diverged[i] != 0,
                        cut[i] != 0});
    out.push_back(std::move(w));
  }
  return out;
}

}  // namespace stepbench
