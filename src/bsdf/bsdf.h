#pragma once
// The closed set of BSDFs, dispatched through std::variant (no virtual calls per scattering event).
//
// Contract shared by every BSDF (all vectors in the local shading frame, n = +z, unit length):
//   wo      direction towards the previous vertex (the camera side, in Radiance mode)
//   wi      direction towards the next vertex (the light side, in Radiance mode)
//   eval    f(wo, wi) * |cos theta_i|            [1/sr], zero for delta lobes
//   pdf     density of sample() choosing wi       [1/sr, solid angle], zero for delta lobes
//   sample  wi with weight = f * |cos theta_i| / pdf; for a delta lobe pdf is the discrete
//           probability of that lobe and f carries the Dirac's weight, so only f / pdf matters.
// TransportMode says which quantity flows along the path: Radiance (camera paths) or Importance
// (light paths, for bidirectional methods), for the non-symmetric scaling of refraction.
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>
#include "bsdf/conductor.h"
#include "bsdf/dielectric.h"
#include "bsdf/diffuse.h"
#include "bsdf/plastic.h"
#include "bsdf/thindielectric.h"
#include "texture/texture.h"

namespace candela {

// Each alternative is a plain struct of parameters (the viewer edits them in place):
//   DiffuseBsdf     Lambertian                                   (Mitsuba `diffuse`)
//   ConductorBsdf   mirror (alpha 0) or rough metal               (`conductor`, `roughconductor`)
//   PlasticBsdf     dielectric coat over a diffuse base          (`plastic`, `roughplastic`)
//   DielectricBsdf  glass, smooth (alpha 0) or rough             (`dielectric`, `roughdielectric`)
//   ThinDielectricBsdf  a thin pane: reflection + straight through (`thindielectric`)
// docs/materials.md describes each model and its tests.
using Bsdf = std::variant<DiffuseBsdf, ConductorBsdf, PlasticBsdf, DielectricBsdf, ThinDielectricBsdf>;

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

// A BSDF parameter driven by a texture. `apply` writes the texture's value at a surface point into
// the parameter it drives; the loader, which knows the BSDF's type and parameter, chooses it.
struct TextureSlot {
    std::shared_ptr<const Texture> texture;
    void (*apply)(Bsdf& bsdf, vec3 value) = nullptr;
    const char* parameter = "";  // Mitsuba's name, for the viewer
};

// A material as scenes name it: a BSDF plus whether both sides of the surface scatter.
// Mitsuba's BSDFs are one-sided (black from the back) unless wrapped in `twosided`; plain OBJ+MTL
// scenes are two-sided, as users of those files expect. Textured parameters are in `textures`:
// `bsdf` holds the rest (and, for those, values that bsdf_at overwrites at each point).
struct Material {
    std::string name;
    Bsdf bsdf;
    bool two_sided = false;
    std::vector<TextureSlot> textures;

    bool textured() const { return !textures.empty(); }
    bool uses_vertex_colors() const {
        for (const TextureSlot& t : textures)
            if (t.texture->uses_vertex_colors()) return true;
        return false;
    }
};

// The material's BSDF at a surface point: the material's own when nothing is textured (no copy, the
// case of every untextured scene), else a copy in `scratch` with its textured parameters evaluated
// at `q`.
inline const Bsdf& bsdf_at(const Material& m, const TextureQuery& q, Bsdf& scratch) {
    if (!m.textured()) return m.bsdf;
    scratch = m.bsdf;
    for (const TextureSlot& t : m.textures) t.apply(scratch, t.texture->eval(q));
    return scratch;
}

}  // namespace candela
