// stepbench: the command line. Every error is one line on stderr and a non-zero exit
// (2 bad usage, 1 a file or solver failure; a command may add its own, see its help),
// and a results file is written whole or not at all.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "build_info.hpp"
#include "cli/commands.hpp"
#include "registry/plugins.hpp"
#include "registry/scenes.hpp"

namespace {

// The commands that take --problem, and `list`: each takes --scene FILE too.
constexpr std::string_view scene_commands[] = {"list", "run", "sweep", "scan", "advise", "loop", "energy"};

// --scene FILE (or --scene=FILE): the scene file is read, checked and registered
// (registry/scenes.hpp) before the command line is parsed, and stands for --problem
// NAME, NAME the scene's (for `list`, it only joins the list). So every command that
// takes a problem takes a scene, with the same options, --set and all. Throws
// std::invalid_argument in one line for a bad file.
std::vector<std::string> load_scenes(int argc, char** argv) {
  std::vector<std::string> out(argv, argv + argc);
  std::string_view command;
  for (int i = 1; i < argc && command.empty(); ++i)
    if (argv[i][0] != '-') command = argv[i];
  if (std::find(std::begin(scene_commands), std::end(scene_commands), command) == std::end(scene_commands)) return out;
  std::vector<std::string> rewritten;
  for (std::size_t i = 0; i < out.size(); ++i) {
    std::string path;
    if (out[i] == "--scene") {
      if (i + 1 == out.size()) throw std::invalid_argument("--scene needs a scene file (docs/scenes.md)");
      path = out[++i];
    } else if (out[i].rfind("--scene=", 0) == 0) {
      path = out[i].substr(8);
    } else {
      rewritten.push_back(out[i]);
      continue;
    }
    if (path.empty()) throw std::invalid_argument("--scene needs a scene file (docs/scenes.md)");
    const std::string name = stepbench::load_scene(path);
    if (command != "list") rewritten.insert(rewritten.end(), {"--problem", name});
  }
  return rewritten;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace stepbench::cli;
  std::vector<std::string> args;
  try {
    args = load_scenes(argc, argv);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "stepbench: error: %s\n", e.what());
    return 2;
  }
  CLI::App app{"stepbench: accuracy, stability and speed of time integrators on game-physics problems"};
  app.require_subcommand(1);
  // The build facts every study file records (store/build_info.cmake).
  namespace info = stepbench::build_info;
  app.set_version_flag("--version",
                       fmt::format("stepbench {} (commit {}, {} build)\ncompiler: {}; flags: {}\ndependencies: {}",
                                   info::version, info::git_commit, info::build_type, info::compiler,
                                   *info::build_flags ? info::build_flags : "(none)", info::dependencies),
                       "print the version, commit, build type and flags, and exit");
  const std::vector<command> commands{add_list(app),    add_run(app),     add_sweep(app),     add_advise(app),
                                      add_ratios(app),  add_compare(app), add_stability(app), add_loop(app),
                                      add_energy(app),  add_schema(app),  add_scan(app),      add_merge(app),
                                      add_summary(app), add_scene(app)};
  // --plugin PATH (repeatable) on the commands that run methods: each plugin is loaded,
  // checked and registered before the command starts (registry/plugins.hpp, docs/plugins.md).
  std::vector<std::string> plugins;
  bool isolate = false;
  for (const auto& c : commands)
    for (const char* name : {"list", "run", "sweep", "scan", "advise", "energy", "loop"})
      if (c.app->get_name() == name) {
        c.app
            ->add_option("--plugin", plugins,
                         "load the methods of a plugin built against include/stepbench/plugin.h (repeatable)")
            ->allow_extra_args(false);
        // The game loop runs in this process: a loop is not one run a child could return.
        if (c.app->get_name() != std::string_view("loop"))
          c.app->add_flag("--isolate", isolate,
                          "run each run of a plugin's method in a child process (a crash fails the run)");
      }
  // Shown in each command's help; parsed above (load_scenes).
  std::vector<std::string> scene_files;
  for (const auto& c : commands)
    if (std::find(std::begin(scene_commands), std::end(scene_commands), c.app->get_name()) != std::end(scene_commands))
      c.app->add_option(
          "--scene", scene_files,
          c.app->get_name() == "list"
              ? "a scene file (docs/scenes.md): list it with the problems, its parameters too"
              : "a scene file (docs/scenes.md): the scene it declares, as --problem NAME would a built-in");
  try {
    std::vector<char*> rewritten;
    for (auto& a : args) rewritten.push_back(a.data());
    app.parse(static_cast<int>(rewritten.size()), rewritten.data());
  } catch (const CLI::Success& e) {  // --help, --help-all, --version: printed by exit()
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "stepbench: error: %s\n", e.what());
    return 2;
  }
  try {
    for (const auto& path : plugins) stepbench::load_plugin(path);
    stepbench::set_plugin_isolation(isolate);
    for (const auto& c : commands)
      if (c.app->parsed()) return c.run();
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "stepbench: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stepbench: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
