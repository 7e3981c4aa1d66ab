#pragma once
// The subcommands of `stepbench`, one file each. Each adds its options to the app and
// returns the function that runs it; main() dispatches and turns exceptions into one
// line and an exit code (2 bad usage: std::invalid_argument; 1 anything else).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>

namespace stepbench {
struct scan_answer;   // study/scan.hpp
struct scan_options;  // study/scan.hpp
struct study;         // study/study.hpp
}  // namespace stepbench

namespace stepbench::cli {

struct command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

command add_list(CLI::App& app);
command add_run(CLI::App& app);
command add_sweep(CLI::App& app);
command add_advise(CLI::App& app);
command add_ratios(CLI::App& app);
command add_compare(CLI::App& app);
command add_stability(CLI::App& app);
command add_loop(CLI::App& app);
command add_energy(CLI::App& app);
command add_schema(CLI::App& app);
command add_scan(CLI::App& app);
command add_merge(CLI::App& app);
command add_summary(CLI::App& app);
command add_scene(CLI::App& app);

// A command's answer on stdout: the JSON document (indented by two) with --json, else the text.
inline void print_answer(bool as_json, const nlohmann::json& out, const std::string& text) {
  if (as_json)
    std::cout << out.dump(2) << "\n";
  else
    fmt::print("{}", text);
}

// The range answer of a scan as JSON (`scan --json`, `advise --scan --json`).
nlohmann::json scan_answer_json(const scan_answer& a);

// A scan's ranking cost (scan_options::ns_per_force_eval) from the study `s` read from
// `path`, when it has timed rows of the scan's problem; else the scan ranks by evaluations.
void take_costs(scan_options& o, const study& s, const std::string& path);

}  // namespace stepbench::cli
