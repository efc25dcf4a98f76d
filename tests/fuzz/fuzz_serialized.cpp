// libFuzzer target: the serialized reader (src/shapes/serialized.cpp). The first byte picks the
// shape_index (0..3, so the end-of-file dictionary is reached too), the rest is the file. Any input
// must parse or throw candela::Error; anything else is a finding.
#include <cstdint>
#include <string>
#include "core/error.h"
#include "scene/obj.h"
#include "shapes/mesh_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    try {
        candela::MeshFile m = candela::parse_serialized(
            "fuzz.serialized", std::string(reinterpret_cast<const char*>(data) + 1, size - 1), data[0] % 4);
        candela::compute_vertex_normals(m.positions, m.triangles);
    } catch (const candela::Error&) {
    }
    return 0;
}
