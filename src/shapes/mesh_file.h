#pragma once
// Readers for the mesh files Mitsuba 3 scenes reference: Stanford PLY and Mitsuba's `serialized`.
// Both return the file's data in object space, unchanged (the XML shape applies to_world and the
// normal flags). Every failure is a candela::Error of one line: "file:line: what" where the file
// has lines (the PLY header, ASCII PLY bodies), "file: byte N: what" in binary data.
#include <string>
#include <vector>
#include "core/math.h"

namespace candela {

struct MeshFile {
    std::string name;               // serialized v4: the mesh's name; else empty
    std::vector<vec3> positions;
    std::vector<vec3> normals;      // per vertex, or empty
    std::vector<vec2> uvs;          // per vertex, or empty
    std::vector<vec3> colors;       // per vertex, or empty; the file's values, not rescaled
    std::vector<uvec3> triangles;   // every index < positions.size()
    bool face_normals = false;      // serialized flag 0x0010: the file asks for flat shading
};

// PLY 1.0, ascii / binary_little_endian / binary_big_endian, any property order and scalar type
// (Mitsuba's type names and extensions: char..double, int8..float64, long, ulong, half).
// Vertex properties: x y z; nx ny nz; uv as u v, else texture_u texture_v, else s t (Mitsuba's
// order); colour as r g b, else red green blue. Faces: the list `vertex_index`, else
// `vertex_indices`; polygons are fan-triangulated (0,1,2), (0,2,3)... Other elements and
// properties are read past. `comment` and `obj_info` lines are skipped.
MeshFile read_ply(const std::string& path);
MeshFile parse_ply(const std::string& name, const std::string& bytes);

// Mitsuba's serialized format, versions 3 and 4 (src/shapes/serialized.cpp): a little-endian
// header 0x041C + version, then a zlib stream with flags, (v4) name, counts, positions, normals,
// uvs, colours (single or double precision) and uint32 triangles. shape_index > 0 is found
// through the end-of-file dictionary of offsets.
MeshFile read_serialized(const std::string& path, int shape_index);
MeshFile parse_serialized(const std::string& name, const std::string& bytes, int shape_index);

// The whole file as bytes; throws Error "path: cannot open file" / "path: read error".
std::string read_file_bytes(const std::string& path);

}  // namespace candela
