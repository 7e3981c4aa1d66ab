#include "store/study_reader.hpp"

#include <H5Cpp.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <concepts>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "core/measure.hpp"
#include "store/h5.hpp"
#include "store/schema.hpp"
#include "store/study_file.hpp"

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
  // constraint_violation_max came within format_version 4 (with xpbd): a file written
  // before it reads the field as NaN (no constraint view measured), so an older study
  // still compares with a newer one.
  for (const auto& group : schema::find("runs").groups)
    for (const auto& f : group.fields) {
      const std::string field(f.name);
      if (group.timed_only || runs.has(field)) continue;
      if (field == "constraint_violation_max") {
        m.columns[field].assign(runs.rows(), std::numeric_limits<double>::quiet_NaN());
        continue;
      }
      throw std::runtime_error(fmt::format("missing field '{}' in {}/runs", f.name, g.getObjName()));
    }
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

// The reader's answer carried from the child process to the parent ("wire"): the
// study's fields in a flat binary form, each struct's fields listed once (fields()
// below) for both directions. Both ends are this build, so native sizes and byte order.
template <class A, class S>
void fields(A& a, S& m) requires std::same_as<std::remove_const_t<S>, study_method> {
  a(m.name, m.origin, m.kind, m.description, m.library, m.declared_order, m.fit_status, m.fit_slope,
    m.declared_order_holds, m.fit_levels, m.columns, m.notes);
}
template <class A, class S>
void fields(A& a, S& r) requires std::same_as<std::remove_const_t<S>, study_reference> {
  a(r.source, r.status, r.reason, r.compared_with, r.err_pos_rel, r.err_vel_rel, r.is_truth);
}
template <class A, class S>
void fields(A& a, S& p) requires std::same_as<std::remove_const_t<S>, study_problem> {
  a(p.name, p.unit, p.truth_source, p.truth_trusted, p.horizon, p.pos_scale, p.vel_scale, p.params, p.references,
    p.methods);
}
template <class A, class S>
void fields(A& a, S& l) requires std::same_as<std::remove_const_t<S>, study_stability_limit> {
  a(l.integrator, l.test, l.theory, l.measured, l.unstable_for_all_dt, l.unconditionally_stable);
}
template <class A, class S>
void fields(A& a, S& d) requires std::same_as<std::remove_const_t<S>, study_data> {
  a(d.path, d.format_version, d.meta, d.settings, d.timed, d.problems, d.stability);
}
template <class T>
concept wire_scalar = std::is_arithmetic_v<T> || std::is_enum_v<T>;

struct wire_writer {
  std::string out;
  template <class... T>
  void operator()(const T&... v) {
    (put(v), ...);
  }
  template <wire_scalar T>
  void put(const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put(const std::string& v) {
    put(v.size());
    out.append(v);
  }
  template <class T>
  void put(const std::vector<T>& v) {
    put(v.size());
    if constexpr (wire_scalar<T>) {
      if (!v.empty()) out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    } else {
      for (const auto& x : v) put(x);
    }
  }
  template <class K, class V>
  void put(const std::map<K, V>& m) {
    put(m.size());
    for (const auto& [k, v] : m) put(k), put(v);
  }
  template <class T>
  void put(const T& v) requires(!wire_scalar<T>) {
    fields(*this, v);
  }
};

struct wire_reader {
  const char* p;
  const char* end;
  void need(std::size_t n) const {
    if (static_cast<std::size_t>(end - p) < n) throw std::runtime_error("the checking process's answer is cut short");
  }
  template <class... T>
  void operator()(T&... v) {
    (get(v), ...);
  }
  template <wire_scalar T>
  void get(T& v) {
    need(sizeof v);
    std::memcpy(&v, p, sizeof v);
    p += sizeof v;
  }
  std::size_t size() {
    std::size_t n = 0;
    get(n);
    return n;
  }
  void get(std::string& v) {
    const std::size_t n = size();
    need(n);
    v.assign(p, n);
    p += n;
  }
  template <class T>
  void get(std::vector<T>& v) {
    const std::size_t n = size();
    if constexpr (wire_scalar<T>) {
      need(n * sizeof(T));
      v.resize(n);
      if (n > 0) std::memcpy(v.data(), p, n * sizeof(T));  // an empty vector's data() may be null
      p += n * sizeof(T);
    } else {
      v.resize(n);
      for (auto& x : v) get(x);
    }
  }
  template <class K, class V>
  void get(std::map<K, V>& m) {
    for (std::size_t n = size(); n > 0; --n) {
      K k;
      get(k);
      get(m[k]);
    }
  }
  template <class T>
  void get(T& v) requires(!wire_scalar<T>) {
    fields(*this, v);
  }
};

// HDF5 1.10 trusts sizes stored in the file where no call of its API can check them
// first (a global heap object's length when it reads a variable-length string, an
// attribute message's size when it looks an attribute up): a damaged file can make it
// copy out of bounds and crash. So the file is read in a child process, which sends the
// study back through a pipe (wire_writer) or why it could not read it; the parent never
// calls HDF5 on the file. The first byte of the answer: 'S' the study, 'H' an HDF5
// error's detail, 'R' another error's text. The children of several files run at once.
struct reading_child {
  std::string path;
  pid_t pid = -1;
  int fd = -1;
};

void write_all(int fd, const std::string& bytes) {
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the parent is gone: nothing to tell
    done += static_cast<std::size_t>(n);
  }
}

reading_child start_reading(const std::string& path) {
  int fds[2];
  if (::pipe(fds) != 0)
    throw std::runtime_error(fmt::format("cannot start the process that reads it: {}", std::strerror(errno)));
  std::fflush(nullptr);
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(fds[0]), ::close(fds[1]);
    throw std::runtime_error(fmt::format("cannot start the process that reads it: {}", std::strerror(errno)));
  }
  if (child == 0) {
    ::close(fds[0]);
    // Bounds on what a damaged file can make HDF5 do: a stored length it trusts makes it
    // allocate gigabytes, a damaged B-tree can make it loop. A whole study reads in well
    // under a second and a few hundred MB, so past these the file is damaged: the child
    // is stopped (SIGXCPU) or its allocation fails, and the parent says so. (Not the
    // address-space bound under AddressSanitizer, which reserves terabytes of it.)
    const rlimit cpu{20, 20};
    ::setrlimit(RLIMIT_CPU, &cpu);
#if !defined(__SANITIZE_ADDRESS__)
    const rlimit memory{std::size_t{2} << 30, std::size_t{2} << 30};
    ::setrlimit(RLIMIT_AS, &memory);
#endif
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    wire_writer w;
    try {
      const study_data study = read_file(path);
      w.out = "S";
      w.put(study);
    } catch (const H5::Exception& e) {
      w.out = "H" + e.getDetailMsg();
    } catch (const std::exception& e) {
      w.out = std::string("R") + e.what();
    }
    write_all(fds[1], w.out);
    std::_Exit(0);
  }
  ::close(fds[1]);
  return {path, child, fds[0]};
}

// The child's answer, once it has ended; throws the line read_study prints.
study_data finish_reading(reading_child& c) {
  const auto fail = [&](const std::string& what) {
    return std::runtime_error(fmt::format("cannot read study file '{}': {}", c.path, what));
  };
  std::string answer;
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(c.fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    answer.append(buf, static_cast<std::size_t>(n));
  }
  ::close(c.fd);
  c.fd = -1;
  int status = 0;
  while (::waitpid(c.pid, &status, 0) < 0)
    if (errno != EINTR) throw fail(fmt::format("cannot wait for the process that reads it: {}", std::strerror(errno)));
  c.pid = -1;
  // How the child ended when it did not end normally: a signal ("SIGSEGV"), or a
  // sanitizer's report ("exit 1").
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGXCPU)
    throw fail("damaged: reading it did not end within 20 s of CPU time (HDF5 looping on it)");
  if (WIFSIGNALED(status))
    throw fail(fmt::format("damaged: reading it crashes the HDF5 library (SIG{})", sigabbrev_np(WTERMSIG(status))));
  if (WEXITSTATUS(status) != 0)
    throw fail(fmt::format("damaged: reading it crashes the HDF5 library (exit {})", WEXITSTATUS(status)));
  if (answer.empty()) throw fail("the process that reads it gave no answer");
  const std::string rest = answer.substr(1);
  if (answer[0] == 'H') throw fail(fmt::format("HDF5: {} (truncated or corrupt?)", rest));
  if (answer[0] != 'S') throw fail(rest);
  study_data out;
  wire_reader r{answer.data() + 1, answer.data() + answer.size()};
  r.get(out);
  return out;
}

// Children still running when reading stops early (an error in an earlier file) are
// stopped and reaped.
struct reading_children {
  std::vector<reading_child> all;
  ~reading_children() {
    for (auto& c : all) {
      if (c.fd >= 0) ::close(c.fd);
      if (c.pid > 0) {
        ::kill(c.pid, SIGKILL);
        while (::waitpid(c.pid, nullptr, 0) < 0 && errno == EINTR) {
        }
      }
    }
  }
};

}  // namespace

std::vector<study_data> read_studies(const std::vector<std::string>& paths) {
  for (const auto& path : paths) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
      throw std::runtime_error(fmt::format("cannot read study file '{}': no such file", path));
    if (std::filesystem::is_directory(path, ec))
      throw std::runtime_error(fmt::format("cannot read study file '{}': it is a directory", path));
  }
  H5::Exception::dontPrint();
  reading_children children;
  for (const auto& path : paths) children.all.push_back(start_reading(path));
  std::vector<study_data> out;
  for (auto& c : children.all) out.push_back(finish_reading(c));
  return out;
}

study_data read_study(const std::string& path) { return std::move(read_studies({path}).front()); }

}  // namespace stepbench
