#pragma once
// Reading Wavefront OBJ files, shared by the plain OBJ scene loader and the XML `obj` shape.
#include <string>
#include <vector>
#include "core/math.h"

namespace candela {

struct ObjMaterial {
    std::string name;
    vec3 kd{0.5f};  // diffuse albedo
    vec3 ke{0.f};   // emitted radiance
};

// Triangles of one OBJ group/object that share a material (-1: none given).
struct ObjGroup {
    std::string name;
    int material = -1;
    std::vector<uvec3> triangles;  // indices into ObjData::positions
};

struct ObjData {
    // One vertex per distinct (position, texcoord, normal) index triple that a face uses, as
    // Mitsuba does: vertices merge only where the file shares them.
    std::vector<vec3> positions;
    std::vector<vec3> normals;           // unit, same size as positions; zero where the file gave none
    std::vector<unsigned char> has_normal;
    std::vector<vec2> uvs;               // the file's vt (u, v as written), same size; zero where none
    std::vector<unsigned char> has_uv;
    std::vector<ObjGroup> groups;        // in file order
    std::vector<ObjMaterial> materials;  // from the MTL files (empty unless requested)
    std::vector<std::string> warnings;   // non-fatal, "file: what"

    bool all_have_normals() const;
    bool all_have_uvs() const;
};

// Reads and validates an OBJ file. Polygons are fan-triangulated ((0,1,2), (0,2,3), ...), as
// Mitsuba's OBJ reader does. Throws Error "file:line: what" for a missing, empty or malformed file,
// out-of-range indices and non-finite numbers. MTL files (mtllib, relative to the OBJ) are read
// only when `materials` is true.
ObjData read_obj(const std::string& path, bool materials);

// Angle-weighted vertex normals (Thuermer and Wuethrich), Mitsuba's choice when a mesh has none.
// Vertices without any non-degenerate face get a zero normal (shading then uses the face normal).
std::vector<vec3> compute_vertex_normals(const std::vector<vec3>& positions, const std::vector<uvec3>& triangles);

}  // namespace candela

namespace candela {
struct SceneDescription;
// The camera of a scene file that has none: it looks along +z at the centre of the mesh's bounds,
// from far enough that a 45 degree fov (on the smaller image axis) frames the bounding sphere.
void set_default_camera(SceneDescription& scene);
}  // namespace candela
