#pragma once
// Plugins: methods compiled outside stepbench against include/stepbench/plugin.h, loaded
// with dlopen at the start of a command (--plugin PATH) and joined to the registry under
// their names, with origin "plugin" (docs/plugins.md). A plugin is untrusted input: every
// field it declares is checked before any of its methods is registered, and a file that
// fails is refused in one line naming it and what is wrong.
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/method.hpp"
#include "include/stepbench/plugin.h"

namespace stepbench {

// One loaded plugin as the study file records it (root attribute `plugins`).
struct loaded_plugin {
  std::string path;      // as given on the command line
  std::string fnv1a_64;  // FNV-1a, 64 bits, of the file's bytes, 16 hex digits: which build of it ran
  int abi_version = 0;   // what it declared (only STEPBENCH_PLUGIN_ABI_VERSION loads)
  std::vector<std::string> methods;
};

// A plugin's method: what the registry says of it and the plugin's own table.
struct plugin_method {
  method_info info;
  const stepbench_method* method = nullptr;
};

// Loads the plugin at `path` and registers its methods (after every method loaded
// before). Call before anything runs a method: the registry's lists grow. Throws
// std::invalid_argument("plugin PATH: ...") for a file that is not a loadable stepbench
// plugin of this ABI, or whose declarations fail validate_plugin_table.
void load_plugin(const std::string& path);

const std::vector<loaded_plugin>& loaded_plugins();
const std::vector<plugin_method>& plugin_methods();
// The loaded plugin method of that name, or nullptr.
const plugin_method* find_plugin_method(std::string_view name);

// --isolate: each run of a plugin method in a child process (fork), so that a crash, or a
// step that never returns (killed after `timeout_s`), becomes that run's failure with its
// reason instead of the end of the program.
void set_plugin_isolation(bool on, double timeout_s = 60.0);
bool plugin_isolation();
// `run` in a child process; its result copied back through a pipe, or a failed run whose
// stop_reason says how the child ended (a signal, the timeout, an exit status).
run_result run_isolated(const std::function<run_result()>& run);

// What is wrong with a plugin's table, in a few words, or "" when it can be registered:
// its ABI version, its count of methods, and each method's declarations (name, kind,
// order, evaluations a step, functions), its name unique in the table and none of
// `taken` (the built-in methods' and the plugins' loaded before).
std::string validate_plugin_table(const stepbench_plugin_table* table, std::span<const std::string> taken);

// FNV-1a, 64 bits (Fowler, Noll, Vo; the parameters of draft-eastlake-fnv), of bytes, as
// 16 hex digits. A fingerprint of which file ran, not a guard against a forged one.
std::string fnv1a_64_hex(std::string_view bytes);

}  // namespace stepbench
