#pragma once
#include <string>
#include <utility>
#include <vector>
#include "scene/scene.h"

namespace candela {

using Defines = std::vector<std::pair<std::string, std::string>>;

// Mitsuba 3 XML subset (docs/scene-format.md). Errors name file:line.
SceneDescription load_mitsuba_xml(const std::string& path, const Defines& defines);

// A plain OBJ + MTL file: Kd -> diffuse albedo, Ke -> area light; two-sided materials; a default
// camera that frames the mesh's bounds. Errors name file:line.
SceneDescription load_obj_scene(const std::string& path);

}  // namespace candela
