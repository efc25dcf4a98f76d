#pragma once
#include <optional>
#include "bsdf/common.h"
#include "bsdf/fresnel.h"
#include "bsdf/microfacet.h"

namespace candela {

// An interface between two dielectrics (glass, water, diamond): the outside medium (IOR ext_ior)
// lies on the +z side, the inside (int_ior) on the -z side; wo and wi may be on either side.
// eta = int_ior / ext_ior. Below, eta_r = n(wi side) / n(wo side): 1 for reflection, eta or 1/eta
// for refraction.
//
//   alpha == 0  smooth (Mitsuba 3 `dielectric`): two delta lobes. sample() reflects with
//               probability F (exact Fresnel, total internal reflection included) with
//               f = R_s F, and refracts otherwise with f = T_s (1 - F) * (1 / eta_r^2 in Radiance
//               mode): the weight f / pdf is R_s or T_s / eta_r^2. eval = pdf = 0.
//   alpha > 0   rough (Walter et al. 2007; Mitsuba 3 `roughdielectric`; Beckmann or GGX,
//               anisotropic alpha_u / alpha_v as in microfacet.h), with the
//               generalised half vector h = +-normalize(wo + eta_r wi), h.z > 0:
//                 reflection   f |cos theta_i| = R_s F D G / (4 |cos theta_o|)
//                 refraction   f |cos theta_i| = T_s (1 - F) D G eta_r^2 |wo.h| |wi.h|
//                                                / (|cos theta_o| (wo.h + eta_r wi.h)^2) * s
//               with s = 1 / eta_r^2 in Radiance mode and 1 in Importance mode, F = F(wo.h).
//               Sampling picks h from the normals visible from wo (Heitz 2018; from inside, from
//               those visible from -wo), then reflects with probability F and refracts otherwise:
//                 pdf = F D_wo(h) / (4 |wo.h|)   or   (1 - F) D_wo(h) eta_r^2 |wi.h| / (wo.h + eta_r wi.h)^2
//               with D_wo(h) = G1(wo, h) |wo.h| D(h) / |cos theta_o|. The sample weight is then
//               R_s G1(wi, h) (reflection) or T_s G1(wi, h) s (refraction): at most 1, or 1 / eta_r^2
//               for Radiance leaving the denser side, whatever the roughness and angle.
//
// Radiance mode follows the radiance from wi to wo, which is squeezed into a smaller solid angle
// on entering a denser medium: L grows by eta_r^2 (n_o / n_i)^2 going in. Importance flows the
// other way and is not scaled (Veach 1997, section 5.2); the two modes give f_R(wo, wi) =
// f_I(wi, wo). BsdfSample::eta carries eta_r so that Russian roulette can undo the scaling.
struct DielectricBsdf {
    float int_ior = 1.5046f;   // Mitsuba's default, BK7 glass
    float ext_ior = 1.000277f; // air
    vec3 specular_reflectance{1.f};
    vec3 specular_transmittance{1.f};
    MicrofacetType distribution = MicrofacetType::Beckmann;  // Mitsuba's default
    float alpha_u = 0.f, alpha_v = 0.f;  // roughness along x and y; both 0 = smooth

    float eta() const { return int_ior / ext_ior; }
    bool is_delta() const { return !(std::max(alpha_u, alpha_v) > 0.f); }
    Microfacet microfacet() const { return Microfacet(distribution, alpha_u, alpha_v); }

    vec3 eval(vec3 wo, vec3 wi, TransportMode mode) const {
        if (is_delta()) return vec3(0.f);
        return rough(wo, wi, mode).f;
    }
    float pdf(vec3 wo, vec3 wi, TransportMode mode) const {
        if (is_delta()) return 0.f;
        return rough(wo, wi, mode).pdf;
    }
    BsdfEval eval_pdf(vec3 wo, vec3 wi, TransportMode mode) const {
        if (is_delta()) return {};
        return rough(wo, wi, mode);
    }

    std::optional<BsdfSample> sample(vec3 wo, float u1, vec2 u2, TransportMode mode) const {
        if (wo.z == 0.f) return std::nullopt;
        const float e = eta();
        BsdfSample s;
        if (is_delta()) {
            const FresnelDielectric fr = fresnel_dielectric(wo.z, e);
            s.delta = true;
            if (u1 < fr.F) {
                s.wi = reflect_z(wo);
                s.pdf = fr.F;
                s.f = specular_reflectance * fr.F;
            } else {
                s.wi = vec3(-fr.eta_ti * wo.x, -fr.eta_ti * wo.y, fr.cos_t);
                s.pdf = 1.f - fr.F;
                const float scale = mode == TransportMode::Radiance ? fr.eta_ti * fr.eta_ti : 1.f;
                s.f = specular_transmittance * ((1.f - fr.F) * scale);
                s.eta = fr.eta_it;
            }
            return s.pdf > 0.f ? std::optional<BsdfSample>(s) : std::nullopt;
        }
        // m from the normals visible from wo; from inside (wo.z < 0) from those visible from the
        // mirrored wo, as Mitsuba 3 does, so that m is on the upper side like rough()'s h.
        const Microfacet ggx = microfacet();
        const float side = wo.z > 0.f ? 1.f : -1.f;
        const vec3 m = ggx.sample_visible(wo * side, u2);
        const float om = glm::dot(wo, m);
        const FresnelDielectric fr = fresnel_dielectric(om, e);
        const float dm = ggx.pdf_visible(wo * side, m);  // D_wo(m)
        // f and pdf come from m itself, not from the half vector rough() rebuilds out of wo and wi:
        // near grazing reflection wo + wi nearly cancels, and the rebuilt h (so D, G1 and the
        // Jacobian) can be far off m, giving weights of 1e4 and more at alpha 1e-4. From m the
        // weight is exactly R G1(wi, m), or T G1(wi, m) / eta_r^2 in Radiance mode.
        float g1i;
        if (u1 < fr.F) {
            s.wi = reflect(wo, m);
            g1i = ggx.G1(s.wi, m);  // zero unless wi is on wo's side and sees m
            s.pdf = fr.F * dm / (4.f * std::abs(om));
            s.f = specular_reflectance * (g1i * s.pdf);
        } else {
            s.wi = glm::normalize(refract(wo, m, fr.cos_t, fr.eta_ti));
            g1i = ggx.G1(s.wi, m);  // zero unless wi is on the other side and sees m
            const float eta_r = fr.eta_it, im = glm::dot(s.wi, m), denom = om + eta_r * im;
            s.pdf = (1.f - fr.F) * dm * eta_r * eta_r * std::abs(im) / (denom * denom);
            const float scale = mode == TransportMode::Radiance ? 1.f / (eta_r * eta_r) : 1.f;
            s.f = specular_transmittance * (g1i * scale * s.pdf);
            s.eta = eta_r;
        }
        if (!(g1i > 0.f) || !(s.pdf > 0.f) || !std::isfinite(s.pdf) || !all_finite(s.f)) return std::nullopt;
        return s;
    }
    bool has_smooth_component() const { return !is_delta(); }

private:
    // f |cos theta_i| and the pdf of sample(), from one generalised half vector.
    BsdfEval rough(vec3 wo, vec3 wi, TransportMode mode) const {
        BsdfEval r;
        const float co = wo.z, ci = wi.z;
        if (co == 0.f || ci == 0.f) return r;
        const bool reflection = co * ci > 0.f;
        const float e = eta();
        const float eta_r = reflection ? 1.f : (co > 0.f ? e : 1.f / e);
        vec3 h = wo + wi * eta_r;
        const float len2 = glm::dot(h, h);
        if (!(len2 > 0.f)) return r;
        h /= std::sqrt(len2);
        if (h.z < 0.f) h = -h;
        const float oh = glm::dot(wo, h), ih = glm::dot(wi, h);
        // Each direction must see the microfacet from its own side of the macro-surface.
        if (oh * co <= 0.f || ih * ci <= 0.f) return r;
        const Microfacet ggx = microfacet();
        const float D = ggx.D(h);
        const float G = ggx.G1(wo, h) * ggx.G1(wi, h);
        const float F = fresnel_dielectric(oh, e).F;
        // Density of h: visible normals from wo flipped to the upper side.
        const float dv = ggx.G1(wo * (co > 0.f ? 1.f : -1.f), h) * std::abs(oh) * D / std::abs(co);
        if (reflection) {
            // The Jacobian 1 / (4 |wi.h|) written with |wo.h| (equal for a true half vector), so
            // that f / pdf is R G1(wi, h) even where rounding makes h inexact (grazing angles).
            r.f = specular_reflectance * (F * D * G / (4.f * std::abs(co)));
            r.pdf = F * dv / (4.f * std::abs(oh));
        } else {
            const float denom = oh + eta_r * ih;
            const float denom2 = denom * denom;
            const float scale = mode == TransportMode::Radiance ? 1.f / (eta_r * eta_r) : 1.f;
            const float v = (1.f - F) * D * G * eta_r * eta_r * std::abs(oh) * std::abs(ih) / (std::abs(co) * denom2);
            r.f = specular_transmittance * (v * scale);
            r.pdf = (1.f - F) * dv * eta_r * eta_r * std::abs(ih) / denom2;
        }
        if (!std::isfinite(r.pdf) || !all_finite(r.f)) return BsdfEval{};
        return r;
    }
};

}  // namespace candela
