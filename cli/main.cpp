// stepbench: the command line. Every error is one line on stderr and a non-zero exit
// (2 bad usage, 1 a file or solver failure; a command may add its own, see its help),
// and a results file is written whole or not at all.
#include <fmt/format.h>

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "build_info.hpp"
#include "cli/commands.hpp"
#include "registry/plugins.hpp"

int main(int argc, char** argv) {
  using namespace stepbench::cli;
  CLI::App app{"stepbench: accuracy, stability and speed of time integrators on game-physics problems"};
  app.require_subcommand(1);
  // The build facts every study file records (store/build_info.cmake).
  namespace info = stepbench::build_info;
  app.set_version_flag("--version",
                       fmt::format("stepbench {} (commit {}, {} build)\ncompiler: {}; flags: {}\ndependencies: {}",
                                   info::version, info::git_commit, info::build_type, info::compiler,
                                   *info::build_flags ? info::build_flags : "(none)", info::dependencies),
                       "print the version, commit, build type and flags, and exit");
  const std::vector<command> commands{add_list(app),   add_run(app),     add_sweep(app),     add_advise(app),
                                      add_ratios(app), add_compare(app), add_stability(app), add_loop(app),
                                      add_energy(app), add_schema(app),  add_scan(app),      add_merge(app),
                                      add_summary(app)};
  // --plugin PATH (repeatable) on the commands that run methods: each plugin is loaded,
  // checked and registered before the command starts (registry/plugins.hpp, docs/plugins.md).
  std::vector<std::string> plugins;
  bool isolate = false;
  for (const auto& c : commands)
    for (const char* name : {"list", "run", "sweep", "scan", "advise", "energy"})
      if (c.app->get_name() == name) {
        c.app
            ->add_option("--plugin", plugins,
                         "load the methods of a plugin built against include/stepbench/plugin.h (repeatable)")
            ->allow_extra_args(false);
        c.app->add_flag("--isolate", isolate,
                        "run each run of a plugin's method in a child process (a crash fails the run)");
      }
  try {
    app.parse(argc, argv);
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
