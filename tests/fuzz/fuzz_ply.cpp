// libFuzzer target: the PLY reader (src/shapes/ply.cpp) on arbitrary bytes, then what the XML shape
// does with its result (vertex normals from the triangles). Any input must parse or throw
// candela::Error; a crash, a sanitizer report, another exception, a leak or a hang is a finding.
#include <cstdint>
#include <string>
#include "core/error.h"
#include "scene/obj.h"
#include "shapes/mesh_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        candela::MeshFile m = candela::parse_ply("fuzz.ply", std::string(reinterpret_cast<const char*>(data), size));
        candela::compute_vertex_normals(m.positions, m.triangles);
    } catch (const candela::Error&) {
    }
    return 0;
}
