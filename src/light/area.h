#pragma once
#include <climits>
#include <memory>
#include <vector>
#include "geometry/analytic.h"
#include "geometry/interaction.h"
#include "geometry/mesh.h"
#include "light/emitter.h"
#include "texture/texture.h"
#include "sampling/distribution.h"

namespace candela {

// An area emitter attached to a shape: radiance emitted on the side the shading normal points to
// (one-sided, as Mitsuba 3's `area`). A textured radiance (Mitsuba's nested texture) is evaluated
// at the uv of each point, on triangle meshes; `radiance` is then not used.
struct AreaEmitter {
    vec3 radiance{0.f};
    std::shared_ptr<const Texture> texture;
};

// Every light of the scene: the emissive triangles and analytic shapes, and the emitters that are
// not on a shape (light/emitter.h).
//
// Selection (u1): the choices are "the area lights" (one choice, when there are any) and each
// other light, picked uniformly (as pbrt-v4's UniformLightSampler, and as Mitsuba, which picks its
// emitters uniformly): pmf 1 / n_choices. Within the area lights a triangle or shape is picked with
// probability proportional to area x luminance(radiance). A scene with area lights only has one
// choice, pmf 1, and samples exactly as before the other emitters existed. Unbiased whatever the
// mix: every light with a nonzero contribution has a nonzero pmf.
//
// On a triangle the point is uniform by area and the density converted to solid angle at the
// reference point: pdf_sa = pmf(tri) / area(tri) * dist^2 / |cos theta_light|. On an analytic shape
// it is sample_analytic's (a sphere seen from outside: uniform in the cone it subtends), times the
// pmf. The other lights: light/emitter.h, times their pmf.
class LightSet {
public:
    // `lights` and `bounds` (the scene's geometry, for the infinite lights' bounding sphere) may be
    // left out by a scene of area lights.
    void build(const Mesh& mesh, const std::vector<Shape>& shapes, const std::vector<AreaEmitter>& emitters,
               const std::vector<AnalyticShape>* analytic = nullptr, const std::vector<Light>* lights = nullptr,
               const AABB& bounds = AABB());

    bool empty() const { return tris_.empty() && alights_.empty() && lights_.empty(); }
    size_t triangle_count() const { return tris_.size(); }
    size_t light_count() const { return lights_.size(); }  // the lights not on shapes
    const Light& light(size_t i) const { return lights_[i]; }
    const SceneSphere& scene_sphere() const { return sphere_; }

    // u1 picks the light (and the triangle), u2 the point on it. Returns false where nothing can be
    // emitted towards ref_p (back side of a one-sided light, outside a spot's cone, zero radiance,
    // or a degenerate geometry).
    bool sample_li(vec3 ref_p, float u1, vec2 u2, LightSample& out) const;

    // Solid-angle density with which sample_li would pick the point `on_light` from ref_p.
    float pdf_li(vec3 ref_p, const SurfaceInteraction& on_light) const;

    // The infinite lights that a ray can see (constant, environment; not directional, a delta):
    // f(Le, pdf) for each, Le the radiance arriving along -w (w the escaping ray's direction) and
    // pdf the solid-angle density with which sample_li picks w through that light (with its pmf).
    bool has_infinite() const { return !infinite_.empty(); }
    // The tables of sample_li for a vector copy of it (wavefront branch), when the lights are
    // emissive triangles only, untextured, on a mesh without shading normals, each of non-zero
    // pmf (sample_li is then sample_area_li's triangle case alone). Per entry of the distribution,
    // `tri` holds 14 floats: p0, p1, p2, ng, pmf_area, pdf_area (EmissiveTriangle), and
    // `radiance` 3.
    struct AreaTriangleTables {
        const float* cdf = nullptr;  // entries + 1 values
        const float* pmf = nullptr;
        size_t entries = 0;
        const float* tri = nullptr;
        const float* radiance = nullptr;
    };
    bool area_triangle_tables(AreaTriangleTables& out) const {
        if (tris_.empty() || !alights_.empty() || !lights_.empty() || !mesh_->normals.empty() || has_textured_emitter())
            return false;
        if (dist_.size() > size_t(INT32_MAX) / 14) return false;  // the lanes gather with 32-bit indices
        for (size_t i = 0; i < dist_.size(); ++i)
            if (!(dist_.pmf(i) > 0.f)) return false;
        static_assert(sizeof(EmissiveTriangle) == 14 * sizeof(float), "EmissiveTriangle: 14 floats, no padding");
        out = {dist_.cdf_data(), dist_.pmf_data(), dist_.size(), &etris_[0].p0.x, &radiance_[0].x};
        return dist_.size() == tris_.size();
    }
    // Whether some emitter's radiance is a texture (emitted() then reads the hit's uv).
    bool has_textured_emitter() const {
        for (const Texture* t : emitter_texture_)
            if (t) return true;
        return false;
    }
    template <class F>
    void for_each_infinite(vec3 w, F&& f) const {
        for (uint32_t i : infinite_)
            f(candela::eval_infinite(lights_[i].model, w), choice_pmf_ * candela::pdf_li(lights_[i].model, w));
    }

    // Emission sampling over all lights (light/emitter.h, "sample_le"): u_sel picks the light as
    // sample_li does, and pdf_pos includes that pmf. Area lights: a point uniform by area on the
    // chosen triangle or shape, a cosine-distributed direction on its emitting side. Returns
    // nothing when the scene has no light or the chosen one emits nothing there.
    // `on_light` (area lights) receives the point's interaction, `light` the index into light(i)
    // (-1: an area light), when given.
    std::optional<EmissionSample> sample_le(float u_sel, vec2 u_pos, vec2 u_dir, SurfaceInteraction* on_light = nullptr,
                                            int32_t* light = nullptr) const;
    // A point on a light for a connection to the camera (the light tracer's emitters seen
    // directly): u_sel picks the light as sample_le does. Area lights: a point uniform by area on
    // the chosen triangle or shape, `pdf` its area density times the pmf, `Le` the radiance it
    // emits on its front side (the side of si.ns). Infinite lights (constant, envmap): light >= 0
    // names it and pdf is the pmf alone (the caller samples a direction). Delta lights: false.
    struct PositionSample {
        SurfaceInteraction si;
        vec3 Le{0.f};
        float pdf = 0.f;
        int32_t light = -1;  // index into light(i) for the lights not on shapes
    };
    bool sample_position(float u_sel, vec2 u_pos, PositionSample& out) const;
    float choice_pmf() const { return choice_pmf_; }
    // The densities sample_le gives to a ray leaving `on_light` (an area light's point) in w.
    void pdf_le(const SurfaceInteraction& on_light, vec3 w, float& pdf_pos, float& pdf_dir) const;
    // The densities sample_le gives to a ray of direction d from light i of light(i).
    void pdf_le(size_t i, vec3 d, float& pdf_pos, float& pdf_dir) const;

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
               tri_emitter_.capacity() * sizeof(int32_t) +
               etris_.capacity() * sizeof(EmissiveTriangle) + emitter_radiance_.capacity() * sizeof(vec3) +
               alights_.capacity() * sizeof(uint32_t) + analytic_light_.capacity() * sizeof(int32_t) +
               analytic_emitter_.capacity() * sizeof(int32_t) + dist_.memory_bytes() +
               lights_.capacity() * sizeof(Light) + infinite_.capacity() * sizeof(uint32_t) +
               emitter_texture_.capacity() * sizeof(const Texture*) + envmap_bytes();
    }

private:
    const Mesh* mesh_ = nullptr;
    std::vector<uint32_t> tris_;          // emissive triangle ids
    std::vector<float> area_;             // their areas
    std::vector<vec3> radiance_;          // their radiance
    std::vector<int32_t> prim_light_;     // triangle id -> index into tris_, or -1
    std::vector<int32_t> tri_emitter_;    // triangle id -> emitter index, or -1
    // Per entry of tris_, what a light sample needs without going through the mesh: computed once
    // in build(), with the same expressions the samplers used per call, so the values (and images)
    // are the same bit for bit.
    struct EmissiveTriangle {
        vec3 p0, p1, p2;
        vec3 ng;          // unit geometric normal: cross(p1 - p0, p2 - p0) / its length
        float pmf_area;   // pmf / area: density by area before the choice pmf (sample_area_li)
        float pdf_area;   // area_pmf_ * pmf / area: the same with it (pdf_li, pdf_le)
    };
    std::vector<EmissiveTriangle> etris_;
    std::vector<vec3> emitter_radiance_;
    std::vector<const Texture*> emitter_texture_;  // per emitter, null unless textured
    const std::vector<Shape>* shapes_ = nullptr;
    // The radiance leaving emissive triangle `tri` (of emitter e) at barycentrics (b1, b2) of its
    // vertices 1 and 2: the constant, or the texture at the mesh's uv there (Scene::interaction's).
    vec3 triangle_radiance(uint32_t tri, int32_t e, float b1, float b2) const;
    // Analytic emitters: entry tris_.size() + k of dist_ is analytic shape alights_[k].
    const std::vector<AnalyticShape>* analytic_ = nullptr;
    std::vector<uint32_t> alights_;           // emissive analytic shape indices
    std::vector<int32_t> analytic_light_;     // analytic index -> dist_ entry, or -1
    std::vector<int32_t> analytic_emitter_;   // analytic index -> emitter index, or -1
    DiscreteDistribution dist_;
    // The other lights and the selection among "the area lights" and them.
    std::vector<Light> lights_;
    std::vector<uint32_t> infinite_;  // indices into lights_ that a ray can see
    SceneSphere sphere_;
    uint32_t choices_ = 0;      // (area lights ? 1 : 0) + lights_.size()
    float choice_pmf_ = 1.f;    // 1 / choices_
    float area_pmf_ = 1.f;      // choice_pmf_ when there are area lights

    bool has_area() const { return !tris_.empty() || !alights_.empty(); }
    size_t envmap_bytes() const {
        size_t n = 0;
        for (const Light& l : lights_)
            if (const EnvmapLight* e = std::get_if<EnvmapLight>(&l.model)) n += e->map ? e->map->memory_bytes() : 0;
        return n;
    }
    bool sample_area_li(vec3 ref_p, float u1, vec2 u2, LightSample& out) const;
};

}  // namespace candela
