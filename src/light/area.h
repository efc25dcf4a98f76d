#pragma once
#include <vector>
#include "geometry/analytic.h"
#include "geometry/interaction.h"
#include "geometry/mesh.h"
#include "sampling/distribution.h"

namespace candela {

// An area emitter attached to a shape: constant radiance, emitted on the side the shading normal
// points to (one-sided, as Mitsuba 3's `area`).
struct AreaEmitter {
    vec3 radiance{0.f};
};

// A point chosen on a light for next-event estimation, seen from a reference point.
struct LightSample {
    vec3 p{0.f}, p_error{0.f};  // point on the light and its error bound
    vec3 n{0.f};                // geometric normal at p
    vec3 wi{0.f};               // unit direction from the reference point to p
    float dist = 0.f;           // distance from the reference point to p
    vec3 Le{0.f};               // radiance leaving p towards the reference point
    float pdf = 0.f;            // solid-angle density at the reference point (includes the pmf)
};

// All emissive triangles and analytic shapes of the scene. A triangle or shape is picked with
// probability proportional to area x luminance(radiance). On a triangle the point is uniform by area
// and the density converted to solid angle at the reference point: pdf_sa = pmf(tri) / area(tri)
// * dist^2 / |cos theta_light|. On an analytic shape it is sample_analytic's (a sphere seen from
// outside: uniform in the cone it subtends), times the pmf.
class LightSet {
public:
    void build(const Mesh& mesh, const std::vector<Shape>& shapes, const std::vector<AreaEmitter>& emitters,
               const std::vector<AnalyticShape>* analytic = nullptr);

    bool empty() const { return tris_.empty() && alights_.empty(); }
    size_t triangle_count() const { return tris_.size(); }

    // u1 picks the triangle, u2 the point on it. Returns false where nothing can be emitted
    // towards ref_p (back side of a one-sided light, zero radiance, or a degenerate geometry).
    bool sample_li(vec3 ref_p, float u1, vec2 u2, LightSample& out) const;

    // Solid-angle density with which sample_li would pick the point `on_light` from ref_p.
    float pdf_li(vec3 ref_p, const SurfaceInteraction& on_light) const;

    // Radiance leaving a point of an emissive shape in direction w (world space, unit).
    vec3 emitted(const SurfaceInteraction& on_light, vec3 w) const;

    // The emitter of the shape a triangle belongs to, or -1.
    int32_t emitter_of(uint32_t prim) const { return prim_light_.empty() ? -1 : tri_emitter_[prim]; }
    // The emitter of the primitive a ray hit (a triangle or an analytic shape), or -1.
    int32_t emitter_of(const Hit& hit) const {
        // Instanced shapes never emit (Mitsuba refuses emitters in a shapegroup); one test for both
        // rare cases, as in Scene::interaction.
        if (__builtin_expect((uint32_t(hit.kind) | (hit.instance + 1u)) != 0u, 0))
            return hit.instance != ~0u || analytic_emitter_.empty() ? -1 : analytic_emitter_[hit.prim];
        return emitter_of(hit.prim);
    }

    // Bytes held by the light tables (the per-triangle maps exist only when the scene has lights).
    size_t memory_bytes() const {
        return tris_.capacity() * sizeof(uint32_t) + area_.capacity() * sizeof(float) +
               radiance_.capacity() * sizeof(vec3) + prim_light_.capacity() * sizeof(int32_t) +
               tri_emitter_.capacity() * sizeof(int32_t) + emitter_radiance_.capacity() * sizeof(vec3) +
               alights_.capacity() * sizeof(uint32_t) + analytic_light_.capacity() * sizeof(int32_t) +
               analytic_emitter_.capacity() * sizeof(int32_t) + dist_.memory_bytes();
    }

private:
    const Mesh* mesh_ = nullptr;
    std::vector<uint32_t> tris_;          // emissive triangle ids
    std::vector<float> area_;             // their areas
    std::vector<vec3> radiance_;          // their radiance
    std::vector<int32_t> prim_light_;     // triangle id -> index into tris_, or -1
    std::vector<int32_t> tri_emitter_;    // triangle id -> emitter index, or -1
    std::vector<vec3> emitter_radiance_;
    // Analytic emitters: entry tris_.size() + k of dist_ is analytic shape alights_[k].
    const std::vector<AnalyticShape>* analytic_ = nullptr;
    std::vector<uint32_t> alights_;           // emissive analytic shape indices
    std::vector<int32_t> analytic_light_;     // analytic index -> dist_ entry, or -1
    std::vector<int32_t> analytic_emitter_;   // analytic index -> emitter index, or -1
    DiscreteDistribution dist_;
};

}  // namespace candela
