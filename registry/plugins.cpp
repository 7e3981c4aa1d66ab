#include "registry/plugins.hpp"

#include <dlfcn.h>
#include <fmt/format.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <type_traits>

#include "registry/plugin_adapter.hpp"
#include "registry/registry.hpp"

namespace stepbench {

namespace {

// A dlopen handle, closed when it goes (a refused plugin is unloaded before the error
// is reported; a loaded one stays until the program ends).
struct plugin_library {
  void* handle = nullptr;
  explicit plugin_library(void* h) : handle(h) {}
  plugin_library(const plugin_library&) = delete;
  plugin_library& operator=(const plugin_library&) = delete;
  ~plugin_library() {
    if (handle != nullptr) ::dlclose(handle);
  }
};

struct plugin_registry {
  std::vector<std::unique_ptr<plugin_library>> libraries;
  std::vector<loaded_plugin> plugins;
  std::vector<plugin_method> methods;
};
plugin_registry& plugins_loaded() {
  static plugin_registry r;
  return r;
}

bool plugin_name_ok(const char* name) {
  if (name == nullptr) return false;
  const std::size_t n = ::strnlen(name, 41);
  if (n == 0 || n > 40 || !(name[0] >= 'a' && name[0] <= 'z')) return false;
  return std::all_of(name, name + n,
                     [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'; });
}

// A description as one printable line of at most 200 characters, or "" (none, or not one).
std::string plugin_description(const char* d) {
  if (d == nullptr) return "";
  const std::size_t n = ::strnlen(d, 201);
  if (n > 200 || !std::all_of(d, d + n, [](char c) { return c >= ' ' && c <= '~'; })) return "";
  return {d, n};
}

std::string plugin_method_error(const stepbench_method& m) {
  if (!plugin_name_ok(m.name)) return "its name is not 1 to 40 characters of [a-z0-9_] starting with a letter";
  if (m.kind != STEPBENCH_FIXED_STEP && m.kind != STEPBENCH_ADAPTIVE)
    return fmt::format("its kind is {}, neither STEPBENCH_FIXED_STEP (0) nor STEPBENCH_ADAPTIVE (1)", m.kind);
  if (m.order < 1 || m.order > 16) return fmt::format("its order is {}, not 1 to 16", m.order);
  if (m.force_evals_per_step < 1 || m.force_evals_per_step > 64)
    return fmt::format("its force evaluations a step are {}, not 1 to 64", m.force_evals_per_step);
  if (m.symplectic != 0 && m.symplectic != 1) return fmt::format("its symplectic flag is {}, not 0 or 1", m.symplectic);
  if (m.create == nullptr || m.destroy == nullptr) return "it has no create or no destroy function";
  if (m.kind == STEPBENCH_FIXED_STEP && (m.step == nullptr || m.try_step != nullptr))
    return "it is fixed-step: it needs step and no try_step";
  if (m.kind == STEPBENCH_ADAPTIVE && (m.try_step == nullptr || m.step != nullptr))
    return "it is adaptive: it needs try_step and no step";
  return "";
}

}  // namespace

std::string validate_plugin_table(const stepbench_plugin_table* table, std::span<const std::string> taken) {
  if (table == nullptr) return "stepbench_plugin() returned NULL";
  if (table->abi_version != STEPBENCH_PLUGIN_ABI_VERSION)
    return fmt::format("it declares plugin ABI version {}; this stepbench reads version {}", table->abi_version,
                       STEPBENCH_PLUGIN_ABI_VERSION);
  if (table->method_count < 1 || table->method_count > 64)
    return fmt::format("it declares {} methods, not 1 to 64", table->method_count);
  if (table->methods == nullptr) return "its table of methods is NULL";
  for (int i = 0; i < table->method_count; ++i) {
    const stepbench_method& m = table->methods[i];
    if (auto e = plugin_method_error(m); !e.empty())
      return fmt::format("method {}{}: {}", i + 1, plugin_name_ok(m.name) ? fmt::format(" ({})", m.name) : "", e);
    if (std::find(taken.begin(), taken.end(), m.name) != taken.end())
      return fmt::format("method {} ({}): the name is taken by a method already registered (stepbench list)", i + 1,
                         m.name);
    for (int j = 0; j < i; ++j)
      if (std::strcmp(table->methods[j].name, m.name) == 0)
        return fmt::format("method {} ({}): the name of method {} too", i + 1, m.name, j + 1);
  }
  return "";
}

std::string fnv1a_64_hex(std::string_view bytes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;  // the offset basis
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ULL;  // the 64-bit FNV prime
  }
  return fmt::format("{:016x}", h);
}

void load_plugin(const std::string& path) {
  const auto fail = [&](const std::string& why) {
    return std::invalid_argument(fmt::format("plugin {}: {}", path, why));
  };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw fail("no such file");
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (!in && !in.eof()) throw fail("cannot be read");
  // An absolute path: dlopen would search the library path for a name without a slash.
  const std::string absolute = std::filesystem::absolute(path, ec).string();
  ::dlerror();
  auto lib = std::make_unique<plugin_library>(::dlopen(absolute.c_str(), RTLD_NOW | RTLD_LOCAL));
  if (lib->handle == nullptr) {
    const char* e = ::dlerror();
    std::string why = e != nullptr ? e : "dlopen failed";
    std::replace(why.begin(), why.end(), '\n', ' ');
    throw fail("not a shared library it can load (" + why + ")");
  }
  void* entry = ::dlsym(lib->handle, STEPBENCH_PLUGIN_ENTRY);
  if (entry == nullptr) throw fail("not a stepbench plugin: it has no function " STEPBENCH_PLUGIN_ENTRY "()");
  const auto* table = reinterpret_cast<const stepbench_plugin_table* (*)()>(entry)();

  std::vector<std::string> taken;
  for (const auto& m : all_methods()) taken.push_back(m.name);
  if (auto e = validate_plugin_table(table, taken); !e.empty()) throw fail(e);

  plugin_registry& r = plugins_loaded();
  loaded_plugin record{path, fnv1a_64_hex(bytes), table->abi_version, {}};
  for (int i = 0; i < table->method_count; ++i) {
    const stepbench_method& m = table->methods[i];
    const bool adaptive = m.kind == STEPBENCH_ADAPTIVE;
    method_info info{.name = m.name,
                     .description = plugin_description(m.description),
                     .origin = method_origin::plugin,
                     .kind = adaptive ? method_kind::adaptive : method_kind::fixed_step,
                     .declared_order = static_cast<double>(m.order),
                     .evals_per_step = static_cast<double>(m.force_evals_per_step),
                     .traits = {.symplectic = m.symplectic == 1, .error_estimate = adaptive},
                     .library = "plugin " + std::filesystem::path(path).filename().string()};
    registry_detail::register_method(info);
    r.methods.push_back({std::move(info), &m});
    record.methods.emplace_back(m.name);
  }
  r.plugins.push_back(std::move(record));
  r.libraries.push_back(std::move(lib));
}

const std::vector<loaded_plugin>& loaded_plugins() { return plugins_loaded().plugins; }
const std::vector<plugin_method>& plugin_methods() { return plugins_loaded().methods; }

const plugin_method* find_plugin_method(std::string_view name) {
  for (const auto& m : plugins_loaded().methods)
    if (m.info.name == name) return &m;
  return nullptr;
}

// --- The reasons a plugin's run fails (registry/plugin_adapter.hpp). ---

void registry_detail::plugin_step_failed(const stepbench_method& m, int status, double t,
                                         const std::string& host_reason) {
  if (!host_reason.empty())
    throw std::runtime_error(fmt::format("plugin method {} stopped at t = {:.6g}: {}", m.name, t, host_reason));
  throw std::runtime_error(fmt::format("plugin method {} returned status {} at t = {:.6g}", m.name, status, t));
}

void registry_detail::plugin_bad_proposal(const stepbench_method& m, double dt_next, double t) {
  throw std::runtime_error(fmt::format("plugin method {} proposed a next step of {} at t = {:.6g} (not finite and > 0)",
                                       m.name, dt_next, t));
}

void registry_detail::plugin_no_workspace(const stepbench_method& m, int n) {
  throw std::runtime_error(fmt::format("plugin method {}: create({}) returned NULL", m.name, n));
}

// --- --isolate: a plugin's run in a child process. ---

namespace {

struct isolation {
  bool on = false;
  double timeout_s = 60.0;
};
isolation& isolation_settings() {
  static isolation i;
  return i;
}

// Every field of a run_result, in one order, for the writer and the reader alike.
template <class R, class F>
void each_field(R& r, F&& f) {
  f(r.steps), f(r.rejected_steps), f(r.work.force_evals), f(r.work.jacobian_evals), f(r.work.newton_iterations);
  f(r.work.linear_solves), f(r.non_finite), f(r.stop_reason), f(r.skipped), f(r.constraint_violation);
  f(r.sample_t), f(r.drawn_samples), f(r.drawn_final), f(r.contacts), f(r.tunnelled), f(r.max_penetration);
  f(r.contact_times), f(r.param), f(r.horizon), f(r.sample_y), f(r.final_y), f(r.contact_positions);
}

struct byte_writer {
  std::string out;
  template <class T>
  void operator()(const T& v) {
    if constexpr (std::is_arithmetic_v<T>) {
      out.append(reinterpret_cast<const char*>(&v), sizeof v);
    } else if constexpr (std::is_same_v<T, std::string>) {
      (*this)(v.size());
      out += v;
    } else {
      (*this)(v.size());
      for (const auto& e : v) (*this)(e);
    }
  }
};

struct byte_reader {
  std::string_view in;
  bool ok = true;
  template <class T>
  void operator()(T& v) {
    if constexpr (std::is_arithmetic_v<T>) {
      if (in.size() < sizeof v) return void(ok = false);
      std::memcpy(&v, in.data(), sizeof v);
      in.remove_prefix(sizeof v);
    } else {
      std::size_t n = 0;
      (*this)(n);
      if (!ok || n > in.size()) return void(ok = false);  // no element takes less than a byte
      if constexpr (std::is_same_v<T, std::string>) {
        v.assign(in.data(), n);
        in.remove_prefix(n);
      } else {
        v.resize(n);
        for (auto& e : v) (*this)(e);
      }
    }
  }
};

run_result failed_run(std::string why) {
  run_result r;
  r.stop_reason = std::move(why);
  return r;
}

}  // namespace

void set_plugin_isolation(bool on, double timeout_s) { isolation_settings() = {on, timeout_s}; }
bool plugin_isolation() { return isolation_settings().on; }

run_result run_isolated(const std::function<run_result()>& run) {
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error(fmt::format("--isolate: pipe: {}", std::strerror(errno)));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    throw std::runtime_error(fmt::format("--isolate: fork: {}", std::strerror(errno)));
  }
  if (pid == 0) {  // the child: the run, its bytes to the pipe, and out without unwinding
    ::close(fds[0]);
    int status = 0;
    try {
      run_result r = run();
      byte_writer w;
      each_field(r, w);
      for (std::size_t done = 0; done < w.out.size();) {
        const ssize_t n = ::write(fds[1], w.out.data() + done, w.out.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
          status = 4;
          break;
        }
        done += static_cast<std::size_t>(n);
      }
    } catch (...) {
      status = 3;
    }
    ::_exit(status);
  }
  ::close(fds[1]);
  std::string bytes;
  char buf[1 << 16];
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(isolation_settings().timeout_s);
  bool timed_out = false;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) continue;
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    bytes.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out)
    return failed_run(fmt::format("--isolate: killed after {:g} s without finishing", isolation_settings().timeout_s));
  if (WIFSIGNALED(status))
    return failed_run(
        fmt::format("--isolate: the run crashed: signal {} ({})", WTERMSIG(status), ::strsignal(WTERMSIG(status))));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return failed_run(fmt::format("--isolate: the run's process ended with exit status {}", WEXITSTATUS(status)));
  run_result r;
  byte_reader reader{bytes};
  each_field(r, reader);
  if (!reader.ok || !reader.in.empty()) return failed_run("--isolate: the run's process sent a damaged result");
  return r;
}

}  // namespace stepbench
