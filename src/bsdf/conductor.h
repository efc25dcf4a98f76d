#pragma once
#include <optional>
#include "bsdf/common.h"
#include "bsdf/fresnel.h"
#include "bsdf/microfacet.h"

namespace candela {

// A metal: specular reflection weighted by the conductor Fresnel term, smooth or rough.
//   alpha == 0   ideal mirror, a delta lobe (Mitsuba 3 `conductor`): sample() returns the mirror
//                direction with pdf 1 and f = specular_reflectance * F(cos theta_o); eval = pdf = 0.
//   alpha > 0    microfacet reflection (Walter et al. 2007; Mitsuba 3 `roughconductor`), with
//                the Beckmann or GGX distribution D of microfacet.h, anisotropic (alpha_u along
//                the tangent x, alpha_v along y):
//                f(wo, wi) cos theta_i = R F(wo.h) D(h) G1(wo, h) G1(wi, h) / (4 cos theta_o),
//                h = normalize(wo + wi); sampled from the normals visible from wo, so
//                pdf = D_wo(h) / (4 wo.h) and the weight is R F G1(wi, h).
// One-sided: zero unless wo and wi are both above the surface (use the material's two_sided flag).
// Reflection only, so eval is symmetric and the transport mode does not matter.
// With the default (eta, k) = (0, 1), F = 1: a perfect mirror, tinted by specular_reflectance.
struct ConductorBsdf {
    vec3 eta{0.f};                   // complex IOR of the metal relative to the outside medium
    vec3 k{1.f};
    vec3 specular_reflectance{1.f};  // tint R (not physical, but handy)
    MicrofacetType distribution = MicrofacetType::Beckmann;  // Mitsuba's default
    float alpha_u = 0.f, alpha_v = 0.f;  // roughness along x and y; both 0 = ideal mirror

    bool is_delta() const { return !(std::max(alpha_u, alpha_v) > 0.f); }
    Microfacet microfacet() const { return Microfacet(distribution, alpha_u, alpha_v); }

    vec3 eval(vec3 wo, vec3 wi, TransportMode) const {
        if (is_delta() || wo.z <= 0.f || wi.z <= 0.f) return vec3(0.f);
        return rough(wo, wi).f;
    }
    float pdf(vec3 wo, vec3 wi, TransportMode) const {
        if (is_delta() || wo.z <= 0.f || wi.z <= 0.f) return 0.f;
        return rough(wo, wi).pdf;
    }
    BsdfEval eval_pdf(vec3 wo, vec3 wi, TransportMode) const {
        if (is_delta() || wo.z <= 0.f || wi.z <= 0.f) return {};
        return rough(wo, wi);
    }
    std::optional<BsdfSample> sample(vec3 wo, float, vec2 u, TransportMode) const {
        if (wo.z <= 0.f) return std::nullopt;
        BsdfSample s;
        if (is_delta()) {
            s.wi = reflect_z(wo);
            s.pdf = 1.f;
            s.delta = true;
            s.f = specular_reflectance * fresnel_conductor(wo.z, eta, k);
            return s;
        }
        const vec3 m = microfacet().sample_visible(wo, u);
        s.wi = reflect(wo, m);
        if (s.wi.z <= 0.f) return std::nullopt;  // reflected below the surface: no sample
        const BsdfEval e = rough(wo, s.wi);
        if (!(e.pdf > 0.f)) return std::nullopt;
        s.f = e.f;
        s.pdf = e.pdf;
        return s;
    }
    bool has_smooth_component() const { return !is_delta(); }

private:
    // Both from the same half vector, so that f / pdf is exactly R F G1(wi, h).
    BsdfEval rough(vec3 wo, vec3 wi) const {
        const vec3 h = glm::normalize(wo + wi);
        const Microfacet ggx = microfacet();
        const float D = ggx.D(h);
        const float g1o = ggx.G1(wo, h), g1i = ggx.G1(wi, h);
        if (D == 0.f || g1o == 0.f || g1i == 0.f) return {};
        const float c = D * g1o / (4.f * wo.z);
        const vec3 F = fresnel_conductor(glm::dot(wo, h), eta, k);
        return {specular_reflectance * F * (c * g1i), c};
    }
};

}  // namespace candela
