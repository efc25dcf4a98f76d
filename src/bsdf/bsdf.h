#pragma once
// The closed set of BSDFs, dispatched through std::variant (no virtual calls per scattering event).
//
// Contract shared by every BSDF (all vectors in the local shading frame, n = +z, unit length):
//   wo      direction towards the previous vertex (the camera side, in Radiance mode)
//   wi      direction towards the next vertex (the light side, in Radiance mode)
//   eval    f(wo, wi) * |cos theta_i|            [1/sr], zero for delta lobes
//   pdf     density of sample() choosing wi       [1/sr, solid angle], zero for delta lobes
//   eval_pdf  {eval, pdf}, bit for bit the same values, from one evaluation (next-event estimation)
//   sample  wi with weight = f * |cos theta_i| / pdf; for a delta lobe pdf is the discrete
//           probability of that lobe and f carries the Dirac's weight, so only f / pdf matters.
// TransportMode says which quantity flows along the path: Radiance (camera paths) or Importance
// (light paths, for bidirectional methods), for the non-symmetric scaling of refraction.
#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>
#include "bsdf/conductor.h"
#include "bsdf/dielectric.h"
#include "bsdf/diffuse.h"
#include "bsdf/plastic.h"
#include "bsdf/pplastic.h"
#include "bsdf/principled.h"
#include "bsdf/thindielectric.h"
#include "texture/texture.h"

namespace candela {

// Each alternative is a plain struct of parameters (the viewer edits them in place):
//   DiffuseBsdf     Lambertian                                   (Mitsuba `diffuse`)
//   ConductorBsdf   mirror (alpha 0) or rough metal               (`conductor`, `roughconductor`)
//   PlasticBsdf     dielectric coat over a diffuse base          (`plastic`, `roughplastic`)
//   DielectricBsdf  glass, smooth (alpha 0) or rough             (`dielectric`, `roughdielectric`)
//   ThinDielectricBsdf  a thin pane: reflection + straight through (`thindielectric`)
//   PrincipledBsdf  Burley's principled model as Mitsuba 3.9 has it (`principled`)
//   PPlasticBsdf    rough specular plus refracted Lambertian, added (`pplastic`, unpolarised)
// docs/materials.md describes each model and its tests.
using Bsdf = std::variant<DiffuseBsdf, ConductorBsdf, PlasticBsdf, DielectricBsdf, ThinDielectricBsdf, PrincipledBsdf,
                          PPlasticBsdf>;

// Dispatch that knows only the diffuse BSDF, as a diffuse-only renderer would have it; any other
// BSDF renders black. Used in two places: the whole dispatch of the yardstick build for issue 6
// (cmake -DCANDELA_DIFFUSE_ONLY=ON; not for real use), and the per-scene specialisation below.
namespace diffuse_only {
inline vec3 eval(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode) {
    const DiffuseBsdf* d = std::get_if<DiffuseBsdf>(&b);
    return d ? d->eval(wo, wi, mode) : vec3(0.f);
}
inline float pdf(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode) {
    const DiffuseBsdf* d = std::get_if<DiffuseBsdf>(&b);
    return d ? d->pdf(wo, wi, mode) : 0.f;
}
inline BsdfEval eval_pdf(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode) {
    const DiffuseBsdf* d = std::get_if<DiffuseBsdf>(&b);
    return d ? d->eval_pdf(wo, wi, mode) : BsdfEval{};
}
inline std::optional<BsdfSample> sample(const Bsdf& b, vec3 wo, float u1, vec2 u2, TransportMode mode) {
    const DiffuseBsdf* d = std::get_if<DiffuseBsdf>(&b);
    return d ? d->sample(wo, u1, u2, mode) : std::nullopt;
}
inline bool has_smooth_component(const Bsdf& b) { return std::holds_alternative<DiffuseBsdf>(b); }
}  // namespace diffuse_only

#if CANDELA_DIFFUSE_ONLY
inline vec3 eval(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    return diffuse_only::eval(b, wo, wi, mode);
}
inline float pdf(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    return diffuse_only::pdf(b, wo, wi, mode);
}
inline BsdfEval eval_pdf(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    return diffuse_only::eval_pdf(b, wo, wi, mode);
}
inline std::optional<BsdfSample> sample(const Bsdf& b, vec3 wo, float u1, vec2 u2,
                                        TransportMode mode = TransportMode::Radiance) {
    return diffuse_only::sample(b, wo, u1, u2, mode);
}
inline bool has_smooth_component(const Bsdf& b) { return diffuse_only::has_smooth_component(b); }
#else
inline vec3 eval(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    return std::visit([&](const auto& x) { return x.eval(wo, wi, mode); }, b);
}
inline float pdf(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    return std::visit([&](const auto& x) { return x.pdf(wo, wi, mode); }, b);
}
// {eval, pdf} bit for bit, in one call.
inline BsdfEval eval_pdf(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    return std::visit([&](const auto& x) { return x.eval_pdf(wo, wi, mode); }, b);
}
inline std::optional<BsdfSample> sample(const Bsdf& b, vec3 wo, float u1, vec2 u2,
                                        TransportMode mode = TransportMode::Radiance) {
    return std::visit([&](const auto& x) { return x.sample(wo, u1, u2, mode); }, b);
}
// True when the BSDF has a non-delta component, so that light sampling can contribute.
inline bool has_smooth_component(const Bsdf& b) {
    return std::visit([](const auto& x) { return x.has_smooth_component(); }, b);
}
#endif

// Dispatch chosen per scene (render/renderer.cpp): when every material of a scene is diffuse, the
// renderer instantiates the path tracer with DiffuseOnly = true, and these compile to the
// diffuse-only build's code: no variant dispatch, no code for the other lobes in the loop.
template <bool DiffuseOnly>
inline vec3 eval_in(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    if constexpr (DiffuseOnly) return diffuse_only::eval(b, wo, wi, mode);
    else return eval(b, wo, wi, mode);
}
template <bool DiffuseOnly>
inline float pdf_in(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    if constexpr (DiffuseOnly) return diffuse_only::pdf(b, wo, wi, mode);
    else return pdf(b, wo, wi, mode);
}
template <bool DiffuseOnly>
inline BsdfEval eval_pdf_in(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    if constexpr (DiffuseOnly) return diffuse_only::eval_pdf(b, wo, wi, mode);
    else return eval_pdf(b, wo, wi, mode);
}
template <bool DiffuseOnly>
inline std::optional<BsdfSample> sample_in(const Bsdf& b, vec3 wo, float u1, vec2 u2,
                                           TransportMode mode = TransportMode::Radiance) {
    if constexpr (DiffuseOnly) return diffuse_only::sample(b, wo, u1, u2, mode);
    else return sample(b, wo, u1, u2, mode);
}
template <bool DiffuseOnly>
inline bool has_smooth_component_in(const Bsdf& b) {
    if constexpr (DiffuseOnly) return diffuse_only::has_smooth_component(b);
    else return has_smooth_component(b);
}

// Derives what a BSDF precomputes from its parameters (the plastic coat's tables). Call it after
// creating or editing a BSDF; it is cheap when nothing changed.
inline void prepare(Bsdf& b) {
    std::visit([](auto& x) {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, PlasticBsdf>) x.prepare();
    }, b);
}

// Whether a BSDF's lobes depend on the azimuth of the tangent frame (alpha_u != alpha_v, or a
// principled `anisotropic` above 0).
inline bool is_anisotropic(const Bsdf& b) {
    return std::visit([](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, ConductorBsdf> || std::is_same_v<T, DielectricBsdf> ||
                      std::is_same_v<T, PPlasticBsdf>)
            return x.alpha_u != x.alpha_v;
        else if constexpr (std::is_same_v<T, PrincipledBsdf>) return x.anisotropic > 0.f;
        else return false;
    }, b);
}

// A BSDF parameter driven by a texture. `apply` writes the texture's value at a surface point into
// the parameter it drives; the loader, which knows the BSDF's type and parameter, chooses it.
struct TextureSlot {
    std::shared_ptr<const Texture> texture;
    void (*apply)(Bsdf& bsdf, vec3 value) = nullptr;
    const char* parameter = "";  // Mitsuba's name, for the viewer
};

// One BSDF of a material and its textured parameters (a leaf of a blendbsdf tree).
struct MaterialLeaf {
    Bsdf bsdf;
    std::vector<TextureSlot> textures;
};

// Mitsuba's `blendbsdf` node: (1 - w) child[0] + w child[1], w = weight (or the texture's eval_1
// clamped to [0, 1]). A child >= 0 is another node of Material::blend, a child < 0 is leaf -1 - c
// (leaf 0 is Material::bsdf/textures, leaf k > 0 is Material::extra_leaves[k - 1]).
struct BlendNode {
    float weight = 0.5f;
    std::shared_ptr<const Texture> weight_texture;  // null: `weight` is the value
    int child[2] = {-1, -1};
};

// The shading-normal wrappers (Mitsuba 3.9's bumpmap and normalmap, both on src/bsdfs/perturbed_bsdf.h).
enum class Perturbation { None, Bump, Normal };

// A material as scenes name it: a BSDF plus whether both sides of the surface scatter.
// Mitsuba's BSDFs are one-sided (black from the back) unless wrapped in `twosided`; plain OBJ+MTL
// scenes are two-sided, as users of those files expect. Textured parameters are in `textures`:
// `bsdf` holds the rest (and, for those, values that bsdf_at overwrites at each point).
//
// Wrappers (docs/materials.md, "Wrappers"). A plain material (no wrapper: plain() is true) is one
// BSDF and the integrators treat it exactly as before the wrappers existed. Otherwise it is a small
// tree kept flat: `blend` nodes over leaves (blendbsdf), at most one shading-normal perturbation
// (bumpmap or normalmap) and an opacity (mask; null is opacity 0) applied to the whole tree. Only
// materials with a wrapper go through the mixture code (integrator/shading.h).
struct Material {
    std::string name;
    Bsdf bsdf;
    bool two_sided = false;
    std::vector<TextureSlot> textures;

    std::vector<MaterialLeaf> extra_leaves;  // leaves 1.. of the blend tree
    std::vector<BlendNode> blend;            // blend[0] is the root when not empty
    Perturbation perturbation = Perturbation::None;
    std::shared_ptr<const Texture> perturbation_texture;  // bump height (eval_1) or tangent-space normal
    float bump_scale = 1.f;                  // bumpmap `scale`
    bool shadow_terminator = true;           // Mitsuba's use_shadowing_function (Estevez et al. 2019)
    bool flip_invalid_normals = true;        // Mitsuba's flip_invalid_normals
    // Some BSDF of the material is anisotropic: its shading frame follows dp/du (Frame::from_tangent,
    // as Mitsuba's), not only the normal. Derived by prepare(Material&); isotropic materials skip it.
    bool tangent_frame = false;
    bool masked = false;                     // mask or null: the surface lets part of the light through
    float opacity = 1.f;                     // mask `opacity` in [0, 1] (null: 0)
    std::shared_ptr<const Texture> opacity_texture;  // null: `opacity` is the value

    bool textured() const { return !textures.empty(); }
    bool plain() const { return blend.empty() && perturbation == Perturbation::None && !masked; }
    bool uses_vertex_colors() const {
        auto reads = [](const std::shared_ptr<const Texture>& t) { return t && t->uses_vertex_colors(); };
        for (const TextureSlot& t : textures)
            if (reads(t.texture)) return true;
        for (const MaterialLeaf& l : extra_leaves)
            for (const TextureSlot& t : l.textures)
                if (reads(t.texture)) return true;
        for (const BlendNode& b : blend)
            if (reads(b.weight_texture)) return true;
        return reads(perturbation_texture) || reads(opacity_texture);
    }
    // The opacity at a point (1 for an unmasked material): Mitsuba's mask, eval_1 clamped to [0, 1].
    float opacity_at(const TextureQuery& q) const {
        if (!masked) return 1.f;
        if (!opacity_texture) return opacity;
        return std::clamp(opacity_texture->eval_1(q), 0.f, 1.f);
    }
};

// Derives what a material precomputes: its BSDFs' tables (prepare(Bsdf&)) and tangent_frame.
inline void prepare(Material& m) {
    prepare(m.bsdf);
    for (MaterialLeaf& l : m.extra_leaves) prepare(l.bsdf);
    // A textured alpha_u or alpha_v may differ from its partner at some point.
    auto anisotropic = [](const Bsdf& b, const std::vector<TextureSlot>& tex) {
        if (is_anisotropic(b)) return true;
        for (const TextureSlot& t : tex)
            if (std::string(t.parameter) == "alpha_u" || std::string(t.parameter) == "alpha_v" ||
                std::string(t.parameter) == "anisotropic")
                return true;
        return false;
    };
    m.tangent_frame = anisotropic(m.bsdf, m.textures);
    for (const MaterialLeaf& l : m.extra_leaves) m.tangent_frame = m.tangent_frame || anisotropic(l.bsdf, l.textures);
}

// A leaf's BSDF at a surface point: its own when nothing is textured (no copy, the case of every
// untextured scene), else a copy in `scratch` with its textured parameters evaluated at `q`.
inline const Bsdf& bsdf_at(const Bsdf& b, const std::vector<TextureSlot>& textures, const TextureQuery& q,
                           Bsdf& scratch) {
    if (textures.empty()) return b;
    scratch = b;
    for (const TextureSlot& t : textures) t.apply(scratch, t.texture->eval(q));
    return scratch;
}
// The material's first (for a plain material: only) BSDF at a surface point.
inline const Bsdf& bsdf_at(const Material& m, const TextureQuery& q, Bsdf& scratch) {
    return bsdf_at(m.bsdf, m.textures, q, scratch);
}

}  // namespace candela
