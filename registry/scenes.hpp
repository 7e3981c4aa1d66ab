#pragma once
// Scenes: a user's scene files (docs/scenes.md), loaded at the start of a command
// (--scene FILE) and joined to the problem registry under the name each file declares,
// beside the built-in problems: every command that takes a problem takes a scene.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/problem_instance.hpp"
#include "problems/scene.hpp"

namespace stepbench {

// One loaded scene as the study file records it (root attribute `scenes`).
struct loaded_scene {
  std::string name;
  std::string path;      // as given on the command line
  std::string fnv1a_64;  // of the file's bytes (registry/plugins.hpp's fnv1a_64_hex): which version of it ran
  std::shared_ptr<const scene_data> data;
};

// Reads and checks the scene file at `path` (problems/scene_file.hpp) and registers it
// under its name; returns that name. Throws std::invalid_argument in one line for a bad
// file, or a name that a built-in problem or a scene loaded before already has.
std::string load_scene(const std::string& path);

const std::vector<loaded_scene>& loaded_scenes();
// The loaded scene of that name, or nullptr.
const loaded_scene* find_scene(std::string_view name);

// The problem_instance of a scene: problem_model<scene> over the methods that run on it
// (registry/scene_unit.cpp), or problem_model<contact_scene> for a scene with walls
// (registry/contact_scene_unit.cpp).
std::unique_ptr<problem_instance> make_scene_problem(std::shared_ptr<const scene_data> data);

namespace registry_detail {
std::unique_ptr<problem_instance> make_smooth_scene_problem(std::shared_ptr<const scene_data> data);
std::unique_ptr<problem_instance> make_contact_scene_problem(std::shared_ptr<const scene_data> data);
}  // namespace registry_detail

}  // namespace stepbench
