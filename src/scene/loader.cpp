#include "core/error.h"
#include "film/image_io.h"
#include "scene/loaders.h"

namespace candela {

Scene load_scene(const std::string& path, const Defines& defines) {
    std::string ext = file_extension(path);
    if (ext == ".xml") return load_mitsuba_xml(path, defines);
    if (ext == ".obj") return load_obj_scene(path);
    throw Error(path, 0, "unknown scene format '" + ext + "' (expected .xml or .obj)");
}

}  // namespace candela
