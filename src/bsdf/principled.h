#pragma once
#include <cmath>
#include <optional>
#include "bsdf/common.h"
#include "bsdf/fresnel.h"
#include "bsdf/microfacet.h"
#include "sampling/warp.h"

namespace candela {

// Mitsuba 3.9's `principled` (Burley 2012 / 2015, src/bsdfs/principled.cpp and principledhelpers.h),
// term for term so that values match Mitsuba's, quirks included. Local frame, n = +z; wo is
// Mitsuba's si.wi (the camera side), wi its wo. Weights: brdf = (1 - metallic)(1 - spec_trans),
// bsdf = (1 - metallic) spec_trans. GGX with alpha_u = max(1e-3, r^2 / a), alpha_v = max(1e-3, r^2 a),
// r = roughness, a = sqrt(1 - 0.9 anisotropic). With h the (generalised) half vector, flipped to
// h.z > 0, F = fresnel_dielectric(wo.h, eta), every lobe a term of f |cos theta_i|:
//   main specular  Fp D G / (4 |cos theta_o|), Fp the principled Fresnel: on the front side
//                  (1 - metallic)(1 - spec_tint) F + metallic Schlick(base_color)
//                  + (1 - metallic) spec_tint Schlick(tint R0(eta)); on the back side bsdf F
//   transmission   sqrt(base_color) bsdf |s (1 - F) D G eta_p^2 (wo.h)(wi.h) / (cos theta_o (wo.h + eta_p wi.h)^2)|
//                  with eta_p = n(wi side) / n(wo side) and s = 1 / eta_p^2 in Radiance mode, 1 in Importance
//   clearcoat      0.25 clearcoat Schlick(0.04) D_GTR1(h) G1(wo) G1(wi) |cos theta_i| (GGX G1 of alpha
//                  0.25, GTR1 alpha lerp(0.1, 0.001, clearcoat_gloss)); front side only. Mitsuba has
//                  no 1 / (4 cos cos) on this lobe; kept, because matching Mitsuba is the point
//   diffuse        brdf |cos theta_i| base_color / pi ((1 - Fi/2)(1 - Fo/2) + retro), lerped towards
//                  Hanrahan-Krueger's fake subsurface by `flatness` (Mitsuba 3.9 has it); front side
//   sheen          sheen (1 - metallic) Schlick weight(h.wi) tint |cos theta_i|, only where the diffuse
//                  lobe is active (brdf > 0), front side
// Sampling: a GGX visible normal m from wo (mirrored to the upper side when inside) decides with
// F(wo.m) between reflection and refraction; the lobe probabilities, front side, proportional to
//   spec reflection  srate (1 - bsdf (1 - F)),  transmission  srate bsdf (1 - F),
//   clearcoat        0.25 clearcoat cc_rate,    diffuse       brdf diffuse_rate (cosine hemisphere);
// back side F and 1 - F only (and nothing at all when bsdf = 0). pdf is the matching mixture in
// solid angle, with the Jacobians 1 / (4 |wi.h|) and eta_p^2 |wi.h| / (wo.h + eta_p wi.h)^2; the
// sample's weight is eval / pdf for the sampled wi, as Mitsuba computes it. Nothing is a delta lobe.
struct PrincipledBsdf {
    vec3 base_color{0.5f};
    float roughness = 0.5f, anisotropic = 0.f, metallic = 0.f, spec_tint = 0.f;
    float sheen = 0.f, sheen_tint = 0.f, clearcoat = 0.f, clearcoat_gloss = 0.f;
    float spec_trans = 0.f, flatness = 0.f;
    float eta = 1.5f;  // interior / exterior IOR; specular s gives eta = 2 / (1 - sqrt(0.08 s)) - 1
    float main_specular_sampling_rate = 1.f, clearcoat_sampling_rate = 1.f, diffuse_reflectance_sampling_rate = 1.f;
    // Mitsuba's m_has_spec_trans: spec_trans given (a texture, or a float other than 0). Without
    // it the back side samples nothing and its pdf has no transmission part.
    bool has_spec_trans = false;

    // Mitsuba's Specular -> eta rule, and its inverse (for the viewer).
    static float eta_from_specular(float s) { return 2.f / (1.f - std::sqrt(0.08f * s)) - 1.f; }
    static float specular_from_eta(float e) { return sqr((e - 1.f) / (e + 1.f)) / 0.08f; }

    Microfacet distribution() const {
        const float r2 = roughness * roughness, aspect = std::sqrt(1.f - 0.9f * anisotropic);
        return Microfacet(MicrofacetType::GGX, std::max(1e-3f, r2 / aspect), std::max(1e-3f, r2 * aspect));
    }

    vec3 eval(vec3 wo, vec3 wi, TransportMode mode) const {
        const float co = wo.z, ci = wi.z;
        if (co == 0.f) return vec3(0.f);
        const float brdf = (1.f - metallic) * (1.f - spec_trans), bsdf = (1.f - metallic) * spec_trans;
        const bool reflect = co * ci > 0.f, refract = co * ci < 0.f, front = co > 0.f;
        const float eta_path = front ? eta : 1.f / eta;
        const vec3 h = half_vector(wo, wi, reflect ? 1.f : eta_path);
        const float oh = glm::dot(wo, h), ih = glm::dot(wi, h);
        const float F = fresnel_dielectric(oh, eta).F;
        const float side = front ? 1.f : -1.f;  // Mitsuba's mulsign(h, cos theta_o)
        const bool refl_ok = oh * side > 0.f && ih * side > 0.f;
        const bool refr_ok = oh * side > 0.f && ih * side < 0.f;
        const bool spec_reflect = reflect && refl_ok && F > 0.f;
        const bool spec_trans_on = has_spec_trans && bsdf > 0.f && refract && refr_ok && F < 1.f;
        vec3 value(0.f);
        if (spec_reflect || spec_trans_on) {
            const Microfacet ggx = distribution();
            const float D = ggx.D(h), G = ggx.G(wo, wi, h);
            if (spec_reflect) {
                vec3 Fp;
                if (front) {
                    Fp = vec3((1.f - metallic) * (1.f - spec_tint) * F);
                    if (metallic != 0.f) Fp += metallic * schlick(base_color, oh);
                    if (spec_tint != 0.f) {
                        const float lum = luminance_mitsuba(base_color);
                        const vec3 tint = lum > 0.f ? base_color / lum : vec3(1.f);
                        const float eta_it = oh >= 0.f ? eta : 1.f / eta;
                        Fp += (1.f - metallic) * spec_tint * schlick(tint * sqr((eta_it - 1.f) / (eta_it + 1.f)), oh);
                    }
                } else {
                    Fp = vec3(bsdf * F);
                }
                value += Fp * (D * G / (4.f * std::abs(co)));
            }
            if (spec_trans_on) {
                const float scale = mode == TransportMode::Radiance ? 1.f / (eta_path * eta_path) : 1.f;
                const float t = std::abs(scale * (1.f - F) * D * G * eta_path * eta_path * oh * ih /
                                         (co * sqr(oh + eta_path * ih)));
                value += glm::sqrt(base_color) * (bsdf * t);
            }
        }
        if (clearcoat > 0.f && reflect && refl_ok && front) {
            const float Fcc = schlick(0.04f, oh), Dcc = gtr1_D(h), Gcc = smith_ggx1(wo, h, 0.25f) * smith_ggx1(wi, h, 0.25f);
            value += vec3(clearcoat * 0.25f * Fcc * Dcc * Gcc * std::abs(ci));
        }
        if (brdf > 0.f && reflect && front) {
            const float Fo = schlick_weight(std::abs(ci)), Fi = schlick_weight(std::abs(co));
            const float f_diff = (1.f - 0.5f * Fi) * (1.f - 0.5f * Fo);
            const float cos_d = ih;
            const float Rr = 2.f * roughness * cos_d * cos_d;
            float f = f_diff + Rr * (Fo + Fi + Fo * Fi * (Rr - 1.f));
            if (flatness != 0.f) {
                const float Fss90 = 0.5f * Rr;
                const float Fss = lerp(1.f, Fss90, Fo) * lerp(1.f, Fss90, Fi);
                const float f_ss = 1.25f * (Fss * (1.f / (std::abs(ci) + std::abs(co)) - 0.5f) + 0.5f);
                f = lerp(f, f_ss, flatness);
            }
            value += base_color * (brdf * std::abs(ci) * kInvPi * f);
            if (sheen > 0.f && 1.f - metallic > 0.f) {
                const float Fd = schlick_weight(std::abs(cos_d));
                vec3 c_sheen(1.f);
                if (sheen_tint != 0.f) {
                    const float lum = luminance_mitsuba(base_color);
                    const vec3 tint = lum > 0.f ? base_color / lum : vec3(1.f);
                    c_sheen = vec3(1.f) + (tint - vec3(1.f)) * sheen_tint;
                }
                value += c_sheen * (sheen * (1.f - metallic) * Fd * std::abs(ci));
            }
        }
        return all_finite(value) ? value : vec3(0.f);
    }

    // The two share little (eval's lobes are not the sampling mixture's), so they stay apart.
    BsdfEval eval_pdf(vec3 wo, vec3 wi, TransportMode mode) const { return {eval(wo, wi, mode), pdf(wo, wi, mode)}; }

    float pdf(vec3 wo, vec3 wi, TransportMode) const {
        const float co = wo.z, ci = wi.z;
        if (co == 0.f) return 0.f;
        const bool reflect = co * ci > 0.f, refract = co * ci < 0.f, front = co > 0.f;
        const float eta_path = front ? eta : 1.f / eta;
        const vec3 h = half_vector(wo, wi, reflect ? 1.f : eta_path);
        const float oh = glm::dot(wo, h), ih = glm::dot(wi, h);
        const float F = fresnel_dielectric(oh, eta).F;
        const Probabilities p = probabilities(F, front, (1.f - metallic) * spec_trans);
        if (!p.valid) return 0.f;
        const float side = front ? 1.f : -1.f;
        const bool refl_ok = reflect && oh * side > 0.f && ih * side > 0.f;
        const bool refr_ok = has_spec_trans && refract && oh * side > 0.f && ih * side < 0.f;
        // dh/dwi: reflection 1 / (4 |wi.h|); refraction eta_p^2 |wi.h| / (wo.h + eta_p wi.h)^2.
        const float jacobian = reflect ? std::abs(1.f / (4.f * ih)) : std::abs(eta_path * eta_path * ih / sqr(oh + eta_path * ih));
        float result = 0.f;
        if (refl_ok || refr_ok) {
            const float dv = distribution().pdf_visible(wo * side, h);
            result += (refl_ok ? p.spec_reflect : p.spec_trans) * dv * jacobian;
        }
        if (reflect) result += p.diffuse * square_to_cosine_hemisphere_pdf(wi);
        if (refl_ok && p.clearcoat > 0.f) result += p.clearcoat * (h.z < 0.f ? 0.f : h.z * gtr1_D(h)) * jacobian;
        return std::isfinite(result) ? result : 0.f;
    }

    std::optional<BsdfSample> sample(vec3 wo, float u1, vec2 u2, TransportMode mode) const {
        const float co = wo.z;
        if (co == 0.f) return std::nullopt;
        const bool front = co > 0.f;
        const float bsdf = has_spec_trans ? (1.f - metallic) * spec_trans : 0.f;
        if (!front && !(bsdf > 0.f)) return std::nullopt;  // no transmission lobe: nothing inside
        const float side = front ? 1.f : -1.f;
        const vec3 m = distribution().sample_visible(wo * side, u2);
        const FresnelDielectric fr = fresnel_dielectric(glm::dot(wo, m), eta);
        const Probabilities p = probabilities(fr.F, front, bsdf);
        if (!p.valid) return std::nullopt;
        BsdfSample s;
        float om, im;
        if (u1 < p.diffuse) {
            s.wi = square_to_cosine_hemisphere(u2);
            if (!(s.wi.z * co > 0.f)) return std::nullopt;
        } else if (u1 < p.diffuse + p.clearcoat) {
            const vec3 mc = gtr1_sample(u2);
            s.wi = candela::reflect(wo, mc);
            om = glm::dot(wo, mc) * side, im = glm::dot(s.wi, mc) * side;
            if (!(s.wi.z * co > 0.f) || !(om > 0.f) || !(im > 0.f)) return std::nullopt;
        } else if (u1 < p.diffuse + p.clearcoat + p.spec_trans) {
            s.wi = glm::normalize(refract(wo, m, fr.cos_t, fr.eta_ti));
            om = glm::dot(wo, m) * side, im = glm::dot(s.wi, m) * side;
            if (!(s.wi.z * co < 0.f) || !(om > 0.f) || !(im < 0.f)) return std::nullopt;
            s.eta = fr.eta_it;
        } else {
            s.wi = candela::reflect(wo, m);
            om = glm::dot(wo, m) * side, im = glm::dot(s.wi, m) * side;
            if (!(s.wi.z * co > 0.f) || !(om > 0.f) || !(im > 0.f)) return std::nullopt;
        }
        s.pdf = pdf(wo, s.wi, mode);
        if (!(s.pdf > 0.f)) return std::nullopt;
        s.f = eval(wo, s.wi, mode);
        return s;
    }
    bool has_smooth_component() const { return true; }

private:
    struct Probabilities {
        float spec_reflect = 0.f, spec_trans = 0.f, clearcoat = 0.f, diffuse = 0.f;
        bool valid = false;
    };
    // Mitsuba's lobe probabilities, normalised; F = F(wo.m) for the microfacet normal in question.
    Probabilities probabilities(float F, bool front, float bsdf) const {
        Probabilities p;
        const float brdf = (1.f - metallic) * (1.f - spec_trans);
        const float srate = main_specular_sampling_rate;
        p.spec_reflect = front ? srate * (1.f - bsdf * (1.f - F)) : F;
        p.spec_trans = has_spec_trans ? (front ? srate * bsdf * (1.f - F) : 1.f - F) : 0.f;
        p.clearcoat = front ? 0.25f * clearcoat * clearcoat_sampling_rate : 0.f;
        p.diffuse = front ? brdf * diffuse_reflectance_sampling_rate : 0.f;
        const float total = p.spec_reflect + p.spec_trans + p.clearcoat + p.diffuse;
        if (!(total > 0.f) || !std::isfinite(total)) return p;
        p.spec_reflect /= total, p.spec_trans /= total, p.clearcoat /= total, p.diffuse /= total;
        p.valid = true;
        return p;
    }

    static float sqr(float x) { return x * x; }
    static float lerp(float a, float b, float t) { return a + (b - a) * t; }
    static float luminance_mitsuba(vec3 c) { return 0.212671f * c.x + 0.715160f * c.y + 0.072169f * c.z; }

    // normalize(wo + e wi) turned to the upper side (Mitsuba's mulsign(h, h.z)).
    static vec3 half_vector(vec3 wo, vec3 wi, float e) {
        vec3 h = glm::normalize(wo + wi * e);
        return std::signbit(h.z) ? -h : h;
    }

    static float schlick_weight(float c) {
        const float m = std::clamp(1.f - c, 0.f, 1.f);
        return m * m * m * m * m;
    }
    // Mitsuba's calc_schlick: R0 + (1 - R0) w, w from |cos| when entering the denser side, else
    // from the cosine of the refracted direction (0 under total internal reflection: then w = 1).
    template <class T>
    T schlick(T R0, float cos_i) const {
        const bool outside = cos_i >= 0.f;
        const float eta_it = outside ? eta : 1.f / eta, eta_ti = outside ? 1.f / eta : eta;
        const float cos_t = safe_sqrt(1.f - (1.f - cos_i * cos_i) * eta_ti * eta_ti);
        const float w = schlick_weight(eta_it > 1.f ? std::abs(cos_i) : cos_t);
        return R0 + (T(1.f) - R0) * w;
    }

    // Clearcoat: GTR1 (Berry) with alpha from the gloss, D normalised so that D(m) m.z integrates to 1.
    float clearcoat_alpha() const { return 0.1f + (0.001f - 0.1f) * clearcoat_gloss; }
    float gtr1_D(vec3 m) const {
        const float a2 = sqr(clearcoat_alpha()), c2 = m.z * m.z;
        const float d = (a2 - 1.f) / (kPi * std::log(a2) * (1.f + (a2 - 1.f) * c2));
        return d * m.z > 1e-20f ? d : 0.f;
    }
    vec3 gtr1_sample(vec2 u) const {
        const float a2 = sqr(clearcoat_alpha());
        const float phi = 2.f * kPi * u.x;
        const float c2 = (1.f - std::pow(a2, 1.f - u.y)) / (1.f - a2);
        const float st = safe_sqrt(1.f - c2), ct = safe_sqrt(c2);
        return vec3(std::cos(phi) * st, std::sin(phi) * st, ct);
    }
    // The clearcoat's isotropic GGX G1 of Mitsuba's principledhelpers.h (smith_ggx1).
    static float smith_ggx1(vec3 v, vec3 h, float alpha) {
        if (glm::dot(v, h) * v.z <= 0.f) return 0.f;
        if (v.z == 1.f) return 1.f;
        const float c2 = v.z * v.z, t2 = (1.f - c2) / c2;
        return 2.f / (1.f + std::sqrt(1.f + alpha * alpha * t2));
    }
};

}  // namespace candela
