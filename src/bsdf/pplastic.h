#pragma once
#include <optional>
#include "bsdf/common.h"
#include "bsdf/fresnel.h"
#include "bsdf/microfacet.h"
#include "sampling/warp.h"

namespace candela {

// Mitsuba 3's `pplastic` ("polarized plastic", after Baek et al. 2018) as its RGB variants render
// it: no polarisation state, so its Mueller matrices reduce to their intensity terms. Unlike
// `roughplastic` there is no coat model: a rough specular reflection and a Lambertian term seen
// through two smooth refractions are simply added. With m = normalize(wo + wi), F the dielectric
// Fresnel reflectance for eta = int_ior / ext_ior, rho = diffuse_reflectance, R_s = specular_reflectance:
//   f cos theta_i = R_s F(wo.m) D(m) G(wo, wi, m) / (4 cos theta_o)                 (glossy)
//                 + (1 - F(cos theta_o)) (1 - F(cos theta_i)) rho cos theta_i / pi   (diffuse)
// Neither term depends on the transport mode (both are symmetric in wo and wi). The glossy lobe is
// sampled from the normals visible from wo with probability s / (s + d) (s, d: the mean specular
// and diffuse reflectances, Mitsuba's specular_sampling_weight), the cosine lobe otherwise; the
// pdf is the mixture. Anisotropic (alpha_u along the tangent x, alpha_v along y); alpha is clamped
// to 1e-4 as in Mitsuba, which has no smooth variant of this plugin. One-sided.
struct PPlasticBsdf {
    vec3 diffuse_reflectance{0.5f};
    vec3 specular_reflectance{1.f};
    float int_ior = 1.49f;      // polypropylene
    float ext_ior = 1.000277f;  // air
    MicrofacetType distribution = MicrofacetType::Beckmann;  // Mitsuba's default
    float alpha_u = 0.1f, alpha_v = 0.1f;

    float eta() const { return int_ior / ext_ior; }
    Microfacet microfacet() const { return Microfacet(distribution, alpha_u, alpha_v); }

    float specular_probability() const {
        const float s = (specular_reflectance.x + specular_reflectance.y + specular_reflectance.z) / 3.f;
        const float d = (diffuse_reflectance.x + diffuse_reflectance.y + diffuse_reflectance.z) / 3.f;
        return s + d > 0.f ? s / (s + d) : 0.5f;
    }

    vec3 eval(vec3 wo, vec3 wi, TransportMode) const {
        if (wo.z <= 0.f || wi.z <= 0.f) return vec3(0.f);
        return both(wo, wi).f;
    }

    float pdf(vec3 wo, vec3 wi, TransportMode) const {
        if (wo.z <= 0.f || wi.z <= 0.f) return 0.f;
        return both(wo, wi).pdf;
    }
    BsdfEval eval_pdf(vec3 wo, vec3 wi, TransportMode) const {
        if (wo.z <= 0.f || wi.z <= 0.f) return {};
        return both(wo, wi);
    }

    std::optional<BsdfSample> sample(vec3 wo, float u1, vec2 u2, TransportMode) const {
        if (wo.z <= 0.f) return std::nullopt;
        BsdfSample s;
        s.wi = u1 < specular_probability() ? reflect(wo, microfacet().sample_visible(wo, u2))
                                           : square_to_cosine_hemisphere(u2);
        if (s.wi.z <= 0.f) return std::nullopt;  // reflected below the surface
        const BsdfEval e = both(wo, s.wi);
        if (!(e.pdf > 0.f)) return std::nullopt;
        s.f = e.f;
        s.pdf = e.pdf;
        return s;
    }
    bool has_smooth_component() const { return true; }

private:
    // f cos theta_i and the mixture pdf from one half vector and one D(m) (wo.z, wi.z > 0).
    BsdfEval both(vec3 wo, vec3 wi) const {
        const float e = eta();
        const vec3 m = glm::normalize(wo + wi);
        const Microfacet mf = microfacet();
        const float D = mf.D(m), g1o = mf.G1(wo, m);
        const float glossy = D * g1o * mf.G1(wi, m) / (4.f * wo.z);
        const vec3 f = specular_reflectance * (fresnel_dielectric(glm::dot(wo, m), e).F * glossy);
        const float t = (1.f - fresnel_dielectric(wo.z, e).F) * (1.f - fresnel_dielectric(wi.z, e).F);
        // Visible normals: D_wo(m) / (4 wo.m) = D(m) G1(wo, m) / (4 cos theta_o).
        const float p_glossy = glm::dot(wo, m) > 0.f && glm::dot(wi, m) > 0.f ? D * g1o / (4.f * wo.z) : 0.f;
        const float ps = specular_probability();
        return {f + diffuse_reflectance * (t * wi.z * kInvPi),
                ps * p_glossy + (1.f - ps) * square_to_cosine_hemisphere_pdf(wi)};
    }
};

}  // namespace candela
