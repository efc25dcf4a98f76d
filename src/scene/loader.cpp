#include <filesystem>
#include "core/error.h"
#include "film/image_io.h"
#include "scene/loaders.h"

namespace candela {

SceneDescription load_scene(const std::string& path, const Defines& defines) {
    // A directory opens like a file and fails only when read, with a stream error that names
    // neither the file nor the problem.
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw Error(path, 0, "is a directory, not a scene file");
    std::string ext = file_extension(path);
    if (ext == ".xml") return load_mitsuba_xml(path, defines);
    if (ext == ".obj") return load_obj_scene(path);
    throw Error(path, 0, "unknown scene format '" + ext + "' (expected .xml or .obj)");
}

}  // namespace candela
