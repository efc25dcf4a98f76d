#pragma once
#include <optional>
#include "bsdf/common.h"
#include "bsdf/fresnel.h"

namespace candela {

// A thin dielectric slab (window pane, soap bubble; Mitsuba 3 `thindielectric`): two parallel
// smooth interfaces so close together that the light leaves where it entered. Light bounces
// between the two faces; summing the geometric series of the inner reflections, with
// R = F(|cos theta_o|, eta) the single-interface Fresnel reflectance,
//   reflectance    R' = R + (1 - R)^2 R / (1 - R^2) = 2 R / (1 + R)
//   transmittance  T' = 1 - R'
// Two delta lobes, the same from both sides: the mirror direction with weight
// specular_reflectance, chosen with probability R', and the straight-through direction -wo with
// weight specular_transmittance, probability T' (so f = R_s R' or T_s T', pdf = R' or T', and
// f / pdf is the tint). The ray is not bent, so radiance is not scaled by eta^2 in either
// transport mode (BsdfSample::eta = 1); eval = pdf = 0.
struct ThinDielectricBsdf {
    float int_ior = 1.5046f;    // Mitsuba's default, BK7 glass
    float ext_ior = 1.000277f;  // air
    vec3 specular_reflectance{1.f};
    vec3 specular_transmittance{1.f};

    float eta() const { return int_ior / ext_ior; }
    // R' for a direction at |cos theta| = c.
    float reflectance(float c) const {
        const float r = fresnel_dielectric(std::abs(c), eta()).F;
        return r < 1.f ? 2.f * r / (1.f + r) : 1.f;
    }

    vec3 eval(vec3, vec3, TransportMode) const { return vec3(0.f); }
    float pdf(vec3, vec3, TransportMode) const { return 0.f; }
    BsdfEval eval_pdf(vec3, vec3, TransportMode) const { return {}; }
    std::optional<BsdfSample> sample(vec3 wo, float u1, vec2, TransportMode) const {
        if (wo.z == 0.f) return std::nullopt;
        const float r = reflectance(wo.z);
        BsdfSample s;
        s.delta = true;
        if (u1 < r) {
            s.wi = reflect_z(wo);
            s.pdf = r;
            s.f = specular_reflectance * r;
        } else {
            s.wi = -wo;
            s.pdf = 1.f - r;
            s.f = specular_transmittance * (1.f - r);
        }
        return s.pdf > 0.f ? std::optional<BsdfSample>(s) : std::nullopt;
    }
    bool has_smooth_component() const { return false; }
};

}  // namespace candela
