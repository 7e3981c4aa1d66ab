// The study's parts, in the order the study runs, judges and writes them (parts/part.hpp).
// Adding an analysis: its file in parts/ and one line here.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <stdexcept>

#include "core/contains.hpp"
#include "parts/part.hpp"
#include "run/scan.hpp"
#include "run/sweep.hpp"

namespace stepbench {

extern const study_part sweep_part, stability_part, substeps_part, frame_rates_part, loop_part, energy_part, scans_part,
    challenge_part, work_per_step_part, verdict_part;

std::string list_or_all(const std::vector<std::string>& names) {
  return names.empty() ? std::string("all") : fmt::format("{}", fmt::join(names, ","));
}

const std::vector<study_part>& study_parts() {
  static const std::vector<study_part> parts{
      sweep_part,          // /problems: every method on every problem over its ladder
      stability_part,      // /stability: our steps' stability limits and regions
      substeps_part,       // /substeps: an implicit step against explicit substeps, a frame
      frame_rates_part,    // /frame_rates: our fixed-step methods at whole frames of 30 .. 240 Hz
      challenge_part,      // /challenge: the pendulum challenge and Small Steps
      energy_part,         // /energy: energy over 10^4 periods
      loop_part,           // /loop: the game loop around the integrator, as the player sees it
      scans_part,          // /scan: a scene's whole parameter range
      work_per_step_part,  // /work_per_step: counted force evaluations a step against the declared
      verdict_part,        // /verdict: the answer, judged from all the above
  };
  return parts;
}

std::vector<merged_group> merged_groups() {
  std::vector<merged_group> out;
  for (const auto& p : study_parts()) out.push_back({p.group_name(), p.merge, p.judge_again, p.tables});
  return out;
}

std::vector<const schema::table*> parts_tables() {
  std::vector<const schema::table*> out;
  for (const auto& p : study_parts())
    for (const auto& t : p.tables) out.push_back(&t);
  return out;
}

const study_part& find_part(std::string_view name) {
  for (const auto& p : study_parts())
    if (p.name == name) return p;
  std::vector<std::string_view> known;
  for (const auto& p : study_parts()) known.push_back(p.name);
  throw std::invalid_argument(fmt::format("unknown part '{}' (known: {})", name, fmt::join(known, ", ")));
}

std::vector<const study_part*> selected_parts(const sweep_options& opts) {
  for (const auto& name : opts.parts) find_part(name);  // throws for an unknown name
  std::vector<const study_part*> out;
  for (const auto& p : study_parts())
    if (opts.parts.empty() || contains(opts.parts, std::string(p.name))) out.push_back(&p);
  return out;
}

const std::vector<study_preset>& study_presets() {
  static const std::vector<study_preset> presets{
      {"full", "every part at its defaults: the default study", [](sweep_options&) {}},
      {"quick", "the CI study: 8 levels, every other tolerance, the stiff spring's quick scan, no challenge",
       [](sweep_options& o) {
         o.levels = o.max_levels = 8;
         o.tolerances = tolerance_ladder(true);
         o.scans = default_scans(true);
         // The challenge's timings and 1000 s energy run belong to the full study.
         o.parts.clear();
         for (const auto& p : study_parts())
           if (p.name != "challenge") o.parts.emplace_back(p.name);
       }},
  };
  return presets;
}

const study_preset& find_preset(std::string_view name) {
  for (const auto& p : study_presets())
    if (p.name == name) return p;
  throw std::invalid_argument(fmt::format("unknown preset '{}' (known: full, quick)", name));
}

}  // namespace stepbench
