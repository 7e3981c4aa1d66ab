#pragma once
// Scene files (docs/scenes.md): TOML read with toml++, every key checked, the masses'
// names resolved, into the element arrays of problems/scene.hpp. A scene file is
// untrusted input: whatever is wrong with it is refused in one line, "FILE:LINE:COLUMN:
// what is wrong" (std::invalid_argument), before anything runs.
#include <string>
#include <string_view>

#include "problems/scene.hpp"

namespace stepbench {

// Reads and checks the scene file at `path`. Throws std::invalid_argument with the one line.
scene_data read_scene_file(const std::string& path);
// The same for a file's text (`path` names it in the messages).
scene_data parse_scene(std::string_view text, const std::string& path);

// The most bytes a scene file may have: a 16 MiB file is already a scene of about 10^5
// masses, far beyond what a study of it could run.
inline constexpr long max_scene_file_bytes = 16L << 20;

}  // namespace stepbench
