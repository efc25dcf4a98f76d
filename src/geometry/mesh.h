#pragma once
#include <string>
#include <vector>
#include "core/aabb.h"
#include "core/math.h"

namespace candela {

// The unit geometric normal of a triangle, from its winding; +z for a degenerate one.
inline vec3 face_normal(vec3 p0, vec3 p1, vec3 p2) {
    vec3 ng = glm::cross(p1 - p0, p2 - p0);
    float len = glm::length(ng);
    return len > 0.f ? ng / len : vec3(0.f, 0.f, 1.f);
}

// All the scene's triangles in world space, in one indexed array: accelerators see one list of
// primitives (the triangle index is the primitive id) and never chase pointers to per-shape meshes.
// A Shape is a contiguous run of triangles that share a material and an emitter.
struct Mesh {
    std::vector<vec3> positions;
    std::vector<vec3> normals;       // per vertex; empty, or the same size as positions
    // Per-vertex texture coordinates and colours of only the shapes that have them, each shape's
    // as one run (Shape::uv_offset, Shape::color_offset): a scene or shape without them pays
    // nothing. Colours are as the file gives them (Mitsuba 3.9 does not rescale integer PLY
    // colours: a uchar 255 stays 255).
    std::vector<vec2> uvs;
    std::vector<vec3> colors;
    std::vector<uvec3> triangles;    // vertex indices
    std::vector<uint32_t> tri_shape; // shape index of each triangle
    // face_normal() of each triangle, filled once the mesh is final (build_scene): a hit then reads
    // it instead of a cross product, a square root and a division. Empty before.
    std::vector<vec3> face_normals;

    void compute_face_normals() {
        face_normals.resize(triangles.size());
        for (size_t i = 0; i < triangles.size(); ++i) {
            vec3 a, b, c;
            vertices(uint32_t(i), a, b, c);
            face_normals[i] = face_normal(a, b, c);
        }
    }

    size_t triangle_count() const { return triangles.size(); }
    // Bytes held by the arrays (capacity), for Scene::memory.
    size_t memory_bytes() const {
        return positions.capacity() * sizeof(vec3) + normals.capacity() * sizeof(vec3) +
               triangles.capacity() * sizeof(uvec3) + tri_shape.capacity() * sizeof(uint32_t) +
               face_normals.capacity() * sizeof(vec3) + uvs.capacity() * sizeof(vec2) + colors.capacity() * sizeof(vec3);
    }
    void vertices(uint32_t tri, vec3& p0, vec3& p1, vec3& p2) const {
        const uvec3& t = triangles[tri];
        p0 = positions[t.x];
        p1 = positions[t.y];
        p2 = positions[t.z];
    }
    AABB triangle_bounds(uint32_t tri) const {
        vec3 a, b, c;
        vertices(tri, a, b, c);
        AABB box(a, a);
        box.expand(b);
        box.expand(c);
        return box;
    }
    float triangle_area(uint32_t tri) const {
        vec3 a, b, c;
        vertices(tri, a, b, c);
        return 0.5f * glm::length(glm::cross(b - a, c - a));
    }
    AABB bounds() const {
        AABB box;
        for (const vec3& p : positions) box.expand(p);
        return box;
    }
};

struct Shape {
    std::string name;          // for messages and the viewer's pick readout
    uint32_t material = 0;     // index into Scene::materials
    int32_t emitter = -1;      // index into Scene::emitters, or -1
    bool smooth = false;       // interpolate vertex normals (else the face normal shades)
    static constexpr uint32_t kNone = ~0u;
    uint32_t first_vertex = 0;        // the shape's vertices are a contiguous run of Mesh::positions
    uint32_t uv_offset = kNone;       // vertex v's uv is Mesh::uvs[v - first_vertex + uv_offset]
    uint32_t color_offset = kNone;    // likewise in Mesh::colors
    bool has_uv() const { return uv_offset != kNone; }
    bool has_color() const { return color_offset != kNone; }
    uint32_t first_triangle = 0;
    uint32_t triangle_count = 0;
    int32_t analytic = -1;     // index into Geometry::analytic for a sphere, disk or cylinder, or the first
                               // segment of a linearcurve (no triangles)
    // Index into Geometry::groups for a shape of a shapegroup: first_triangle and analytic then
    // index the group's mesh and shapes, and the shape is only seen through instances.
    int32_t group = -1;
    // Participating media on either side (medium/medium.h): indices into Geometry::media, -1 for
    // none. A ray that crosses a shape naming either takes the one on the side it leaves towards
    // (exterior: the side the geometric normal points to); other shapes leave its medium as is.
    int32_t interior = -1, exterior = -1;
    bool medium_transition() const { return interior >= 0 || exterior >= 0; }
};

}  // namespace candela
