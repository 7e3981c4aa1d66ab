// stepbench: the command line. Every error is one line on stderr and a non-zero exit
// (2 bad usage, 1 a file or solver failure; a command may add its own, see its help),
// and a results file is written whole or not at all.
#include <fmt/format.h>

#include <cstdio>
#include <exception>
#include <vector>

#include "cli/commands.hpp"
#include "study/registry.hpp"

namespace stepbench::cli {

std::string resolve_named_value(std::string assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq + 1 == assignment.size()) return assignment;
  const std::string target = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  const auto dot = target.find('.');
  const std::string param = dot == std::string::npos ? target : target.substr(dot + 1);
  std::vector<std::string> problems;
  if (dot != std::string::npos) {
    problems.push_back(target.substr(0, dot));
  } else {
    problems = problem_names();
  }
  for (const auto& name : problems) {
    try {
      for (const auto& v : make_problem(name)->named_values(param))
        if (v.name == text) return target + "=" + fmt::format("{}", v.value);
    } catch (const std::invalid_argument&) {
      // an unknown problem: left for the command to report
    }
  }
  return assignment;
}

}  // namespace stepbench::cli

int main(int argc, char** argv) {
  using namespace stepbench::cli;
  CLI::App app{"stepbench: accuracy, stability and speed of time integrators on game-physics problems"};
  app.require_subcommand(1);
  const std::vector<command> commands{add_list(app),      add_run(app),    add_sweep(app),
                                      add_advise(app),    add_ratios(app), add_compare(app),
                                      add_stability(app), add_loop(app),   add_energy(app)};
  // --set takes a name where the parameter understands one (sliding_block's material).
  for (const auto& c : commands)
    if (auto* set = c.app->get_option_no_throw("--set")) set->transform(resolve_named_value);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "stepbench: error: %s\n", e.what());
    return 2;
  }
  try {
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
