// libFuzzer target: the OBJ path, both ways it is reached: a plain OBJ+MTL scene (materials,
// emitters, default camera, build_scene) and the geometry-only read that the XML `obj` shape uses.
// Any input must load or throw candela::Error; anything else is a finding.
#include <cstdint>
#include "core/error.h"
#include "fuzz_common.h"
#include "scene/loaders.h"
#include "scene/obj.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string path = candela::fuzz::write_input("scene.obj", data, size);
    try {
        candela::build_scene(candela::load_obj_scene(path));
    } catch (const candela::Error&) {
    }
    try {
        candela::ObjData obj = candela::read_obj(path, false);
        for (const candela::ObjGroup& g : obj.groups) candela::compute_vertex_normals(obj.positions, g.triangles);
    } catch (const candela::Error&) {
    }
    return 0;
}
