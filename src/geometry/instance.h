#pragma once
// Instancing as Mitsuba 3 defines it (src/shapes/shapegroup.cpp, instance.cpp): a `shapegroup`
// holds shapes stored once, in its own space, and is invisible by itself; each `instance` shows
// the whole group through an affine to_world. Groups may hold triangle meshes and analytic shapes,
// but no emitters, instances or other groups (Mitsuba refuses those too).
#include <string>
#include <vector>
#include "core/aabb.h"
#include "geometry/analytic.h"
#include "geometry/mesh.h"

namespace candela {

struct ShapeGroup {
    std::string id;
    Mesh mesh;                             // group space; tri_shape indexes Scene::shapes
    std::vector<AnalyticShape> analytic;   // group space; AnalyticShape::shape indexes Scene::shapes
    AABB bounds() const {
        AABB b = mesh.bounds();
        for (const AnalyticShape& a : analytic) b.expand(a.bounds());
        return b;
    }
};

struct Instance {
    uint32_t group = 0;     // index into Geometry::groups
    mat4 to_world{1.f};     // group space to world (affine, invertible)
    mat4 to_object{1.f};    // its inverse
    AABB bounds;            // world bounds of the transformed group box
};

// The world box of `box` under the affine m: the eight corners' bounds, widened by their rounding
// (a few ulps of the largest coordinate) so that it contains every transformed point.
inline AABB transform_box(const mat4& m, const AABB& box) {
    AABB out;
    if (box.empty()) return out;
    for (int c = 0; c < 8; ++c) {
        vec3 p((c & 1) ? box.max.x : box.min.x, (c & 2) ? box.max.y : box.min.y, (c & 4) ? box.max.z : box.min.z);
        out.expand(vec3(m * glm::vec4(p, 1.f)));
    }
    vec3 pad = gamma_bound(8) * glm::max(abs3(out.min), abs3(out.max));
    return AABB(out.min - pad, out.max + pad);
}

}  // namespace candela
