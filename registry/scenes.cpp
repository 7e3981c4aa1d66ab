#include "registry/scenes.hpp"

#include <fmt/format.h>

#include <fstream>
#include <iterator>
#include <stdexcept>

#include "problems/scene_file.hpp"
#include "registry/plugins.hpp"
#include "registry/registry.hpp"

namespace stepbench {

namespace {
std::vector<loaded_scene>& scenes() {
  static std::vector<loaded_scene> all;
  return all;
}
}  // namespace

std::string load_scene(const std::string& path) {
  auto data = std::make_shared<scene_data>(read_scene_file(path));
  for (const auto& n : builtin_problem_names())
    if (n == data->name)
      throw std::invalid_argument(
          fmt::format("{}:{}:{}: the scene's name '{}' is a built-in problem's; give it another", path, data->name_line,
                      data->name_column, data->name));
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const std::string hash = fnv1a_64_hex(bytes);
  for (auto& s : scenes())
    if (s.name == data->name) {
      if (s.path != path)
        throw std::invalid_argument(fmt::format("{}:{}:{}: the scene's name '{}' is taken by the scene file {}", path,
                                                data->name_line, data->name_column, data->name, s.path));
      // The same file again: as it reads now (problems made from the earlier reading keep it).
      if (s.fnv1a_64 != hash) s = {data->name, path, hash, std::move(data)};
      return s.name;
    }
  scenes().push_back({data->name, path, hash, std::move(data)});
  return scenes().back().name;
}

const std::vector<loaded_scene>& loaded_scenes() { return scenes(); }

std::unique_ptr<problem_instance> make_scene_problem(std::shared_ptr<const scene_data> data) {
  return data->planes.empty() ? registry_detail::make_smooth_scene_problem(std::move(data))
                              : registry_detail::make_contact_scene_problem(std::move(data));
}

const loaded_scene* find_scene(std::string_view name) {
  for (const auto& s : scenes())
    if (s.name == name) return &s;
  return nullptr;
}

}  // namespace stepbench
