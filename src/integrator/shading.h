#pragma once
// The step every integrator takes at a hit: the material's BSDF there and its shading frame.
//
// Contract: Shading::frame is the local shading frame of the integrator (n = +z is the shading
// normal, turned to the side of wo for a two-sided material; si.ng is turned with it); wo is the
// direction towards the previous vertex in that frame. eval/pdf/sample follow bsdf.h in that frame
// (eval = f |cos theta_i|, pdf in solid angle, sample weight = f |cos| / pdf) whatever the material:
// a plain material calls its one BSDF (`bsdf`), a wrapped one (blendbsdf, bumpmap, normalmap) goes
// through `wrapped` (bsdf/wrappers.h). The DiffuseOnly instantiation (every material plain and
// diffuse) compiles to the plain call only.
//
// Masks (mask, null) are not part of the BSDF: whether a path passes a masked surface is decided
// before shading (path_impl.h), and shadow rays cross masked surfaces with transmittance
// 1 - opacity (shadow_transmittance below).
#include "bsdf/wrappers.h"
#include "scene/scene.h"

namespace candela {

// What a hit resolves to. Holds the textured copies of the BSDFs, so it lives as long as they are
// used (one per bounce; construct once per path and reuse). The diffuse-only instantiation holds
// room for one copy only: a plain diffuse scene builds nothing it does not use.
template <bool DiffuseOnly>
struct ShadingT {
    Frame frame;
    vec3 wo{0.f};
    const Bsdf* bsdf = nullptr;     // the plain material's BSDF (textured copy in scratch[0])
    bool is_wrapped = false;
    struct None {};
    std::conditional_t<DiffuseOnly, None, WrappedBsdf> wrapped;  // not even constructed in diffuse-only
    std::array<Bsdf, DiffuseOnly ? 1 : kMaxBlendLeaves> scratch;

    vec3 eval(vec3 wi, TransportMode mode = TransportMode::Radiance) const {
        if constexpr (!DiffuseOnly)
            if (is_wrapped) return wrapped.eval_w(wo, wi, mode);
        return eval_in<DiffuseOnly>(*bsdf, wo, wi, mode);
    }
    float pdf(vec3 wi, TransportMode mode = TransportMode::Radiance) const {
        if constexpr (!DiffuseOnly)
            if (is_wrapped) return wrapped.pdf_w(wo, wi, mode);
        return pdf_in<DiffuseOnly>(*bsdf, wo, wi, mode);
    }
    // {eval(wi), pdf(wi)} bit for bit, from one evaluation of the BSDF.
    BsdfEval eval_pdf(vec3 wi, TransportMode mode = TransportMode::Radiance) const {
        if constexpr (!DiffuseOnly)
            if (is_wrapped) return wrapped.eval_pdf_w(wo, wi, mode);
        return eval_pdf_in<DiffuseOnly>(*bsdf, wo, wi, mode);
    }
    // The density with another wo (BDPT's reverse pdfs: the path walked the other way).
    float pdf_from(vec3 wo_other, vec3 wi, TransportMode mode) const {
        if constexpr (!DiffuseOnly)
            if (is_wrapped) return wrapped.pdf_w(wo_other, wi, mode);
        return pdf_in<DiffuseOnly>(*bsdf, wo_other, wi, mode);
    }
    std::optional<BsdfSample> sample(float u1, vec2 u2, TransportMode mode = TransportMode::Radiance) const {
        if constexpr (!DiffuseOnly)
            if (is_wrapped) return wrapped.sample_w(wo, u1, u2, mode);
        return sample_in<DiffuseOnly>(*bsdf, wo, u1, u2, mode);
    }
    bool has_smooth_component() const {
        if constexpr (!DiffuseOnly)
            if (is_wrapped) return wrapped.has_smooth_w();
        return has_smooth_component_in<DiffuseOnly>(*bsdf);
    }
};

namespace detail {

// Adds the leaves under blend child `c` with mixture weight `w` (depth-first, leaf order).
inline void add_blend_leaves(const Material& m, const TextureQuery& q, int c, float w, ShadingT<false>& sh) {
    WrappedBsdf& wb = sh.wrapped;
    if (c >= 0) {
        const BlendNode& b = m.blend[size_t(c)];
        const float t = b.weight_texture ? std::clamp(b.weight_texture->eval_1(q), 0.f, 1.f) : b.weight;
        add_blend_leaves(m, q, b.child[0], w * (1.f - t), sh);
        add_blend_leaves(m, q, b.child[1], w * t, sh);
        return;
    }
    if (!(w > 0.f) || wb.n >= kMaxBlendLeaves) return;  // the loader keeps trees within the limit
    const int leaf = -1 - c;
    const Bsdf& b = leaf == 0 ? m.bsdf : m.extra_leaves[size_t(leaf - 1)].bsdf;
    const std::vector<TextureSlot>& tex = leaf == 0 ? m.textures : m.extra_leaves[size_t(leaf - 1)].textures;
    wb.leaf[size_t(wb.n)] = &bsdf_at(b, tex, q, sh.scratch[size_t(wb.n)]);
    wb.w[size_t(wb.n)] = w;
    ++wb.n;
}

}  // namespace detail

// The wrapped part of shade() (frame and wo already set).
inline void shade_wrapped(const Scene& sc, const Hit& hit, const SurfaceInteraction& si, const Material& mat, bool flipped,
                          ShadingT<false>& sh) {
    // A wrapped material: the blend tree's leaves, then the perturbed frame.
    const TextureQuery q = sc.texture_query(si, hit);
    WrappedBsdf& wb = sh.wrapped;
    wb.n = 0;
    wb.perturbed = false;
    detail::add_blend_leaves(mat, q, mat.blend.empty() ? -1 : 0, 1.f, sh);
    if (wb.n == 0) {  // all weights zero: cannot happen with weights summing to 1, but stay defined
        wb.leaf[0] = &mat.bsdf;
        wb.w[0] = 1.f;
        wb.n = 1;
    }
    if (mat.perturbation != Perturbation::None) {
        const vec3 ns = si.ns;  // the front side's normal: the map is defined there
        vec3 np = mat.perturbation == Perturbation::Bump
                      ? bump_normal(ns, flipped ? -si.ng : si.ng, si.dpdu, si.dpdv,
                                    mat.bump_scale * mat.perturbation_texture->eval_1_grad(q))
                      : normalmap_normal(ns, si.dpdu, mat.perturbation_texture->eval(q));
        // Seen from the back of a two-sided material: the map mirrored through the tangent plane,
        // as Mitsuba's twosided mirrors the directions (local z -> -z) for its nested BSDF.
        if (flipped) np -= 2.f * glm::dot(np, ns) * ns;
        wb.frame = perturbed_frame(sh.frame.to_local(np), sh.wo, mat.flip_invalid_normals);
        wb.perturbed = true;
        wb.terminator = mat.shadow_terminator;
    }
    sh.is_wrapped = true;
}

// Resolves the material at a hit. `si.ng` is turned with the frame for two-sided materials (the
// ray offsets use it). `wo_world` points towards the previous vertex.
template <bool DiffuseOnly>
inline void shade(const Scene& sc, const Hit& hit, SurfaceInteraction& si, vec3 wo_world, ShadingT<DiffuseOnly>& sh) {
    const Material& mat = sc.materials[sc.shapes[si.shape].material];
    vec3 n = si.ns;
    const bool flipped = mat.two_sided && glm::dot(wo_world, n) < 0.f;
    if (flipped) {  // a two-sided material is seen from whichever side the ray arrives
        n = -n;
        si.ng = -si.ng;
    }
    // Seen from the back, from_tangent keeps s and negates t: an anisotropic lobe (even in x and y)
    // is the same as under Mitsuba's twosided, which negates z instead.
    sh.frame = !DiffuseOnly && mat.tangent_frame ? Frame::from_tangent(n, si.dpdu) : Frame(n);
    sh.wo = sh.frame.to_local(wo_world);
    if (DiffuseOnly || mat.plain()) {
        sh.is_wrapped = false;
        sh.bsdf = mat.textured() ? &bsdf_at(mat, sc.texture_query(si, hit), sh.scratch[0]) : &mat.bsdf;
        return;
    }
    if constexpr (!DiffuseOnly) shade_wrapped(sc, hit, si, mat, flipped, sh);
}


// Whether any material of the scene is masked: the integrators then test opacity at hits and let
// shadow rays through masked surfaces; otherwise they never look.
inline bool scene_has_masks(const Scene& sc) {
    for (const Material& m : sc.materials)
        if (m.masked) return true;
    return false;
}

// The loop over masked surfaces, out of line: scenes without masks never run it.
inline __attribute__((noinline)) float shadow_transmittance_masked(const Scene& sc, Ray shadow, uint64_t& rays) {
    // To a point (spawn_ray_to: tmax = 1 - eps stops just short of o + d), or towards an infinite
    // light (spawn_ray: unbounded).
    const bool to_point = std::isfinite(shadow.tmax);
    const vec3 target = shadow.o + shadow.d;
    float T = 1.f;
    for (int i = 0; i < 256; ++i) {
        Hit h;
        if (!sc.accel->intersect(shadow, h)) return T;
        const SurfaceInteraction s = sc.interaction(h);
        const Material& m = sc.materials[sc.shapes[s.shape].material];
        if (!m.masked) return 0.f;
        T *= 1.f - m.opacity_at(sc.texture_query(s, h));
        if (!(T > 0.f)) return 0.f;
        shadow.o = offset_ray_origin(s.p, s.p_error, s.ng, shadow.d);
        if (to_point) {
            shadow.d = target - shadow.o;
            shadow.tmax = 1.f - kShadowEpsilon;
        }
        ++rays;
    }
    return 0.f;  // a pile of masks deeper than any scene needs: treat as opaque
}

// The fraction of light that travels along a shadow ray (from spawn_ray_to): 0 when an unmasked
// surface is in the way, else the product of (1 - opacity) over the masked surfaces crossed.
// Without masks in the scene this is the plain any-hit test.
inline float shadow_transmittance(const Scene& sc, const Ray& shadow, bool masks, uint64_t& rays) {
    if (!masks) return sc.accel->occluded(shadow) ? 0.f : 1.f;
    return shadow_transmittance_masked(sc, shadow, rays);
}

}  // namespace candela
