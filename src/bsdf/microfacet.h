#pragma once
// Microfacet normal distributions (Mitsuba 3's MicrofacetDistribution): Beckmann and GGX
// (Trowbridge-Reitz), anisotropic, in the local shading frame (n = +z, alpha_u along x = the
// tangent dp/du, alpha_v along y).
//
//   D(m)      density of microfacet normals per unit projected area, so that the integral of
//             D(m) m.z over the hemisphere of m (solid angle) is 1
//               Beckmann  exp(-(m.x^2/au^2 + m.y^2/av^2) / m.z^2) / (pi au av m.z^4)
//               GGX       1 / (pi au av (m.x^2/au^2 + m.y^2/av^2 + m.z^2)^2)
//   G1(v, m)  Smith masking, zero when v sees the back of m or of the surface. With a^2 the
//             inverse of the squared tangent of v scaled by the roughness along v's azimuth:
//               GGX       2 / (1 + sqrt(1 + 1/a^2))                       (exact)
//               Beckmann  Mitsuba's rational fit of 2 / (1 + Lambda), relative error < 0.35 %:
//                         (3.535 a + 2.181 a^2) / (1 + 2.276 a + 2.577 a^2), 1 for a >= 1.6
//             Renders agree with Mitsuba because this is Mitsuba's own definition; the price is
//             that for Beckmann the visible-normal density below integrates to 1 +- 0.35 %.
//   G         separable Smith G1(wo, m) G1(wi, m), as Mitsuba 3 uses
//   sample_visible(v, u): a normal m drawn from the normals visible from v (v.z > 0),
//             D_v(m) = G1(v, m) max(0, v.m) D(m) / v.z   [solid angle of m]; pdf_visible gives it.
//             Both distributions stretch v to the roughness-1 configuration, sample there and
//             unstretch. GGX: Heitz 2018 ("Sampling the GGX distribution of visible normals",
//             with the concentric disk map for stratification). Beckmann: the slope along v's
//             azimuth by a numerical inversion of its CDF in the erf domain (Jakob 2014, "An
//             improved visible normal sampling routine for the Beckmann distribution": three
//             Newton steps from the grazing-angle solution), the other slope Gaussian.
//
// alpha is the roughness (the RMS slope scale for Beckmann, the GGX width): 1e-4 is nearly a
// mirror, 1 is very rough. The caller handles alpha = 0 as a delta lobe; below 1e-4 the
// distribution is clamped (float precision), as Mitsuba clamps it.
#include <cmath>
#include <cstdint>
#include "core/math.h"
#include "sampling/warp.h"

namespace candela {

constexpr float kMinAlpha = 1e-4f;

// Mitsuba's default is Beckmann: a rough plugin without `distribution` is Beckmann.
enum class MicrofacetType : uint8_t { Beckmann = 0, GGX = 1 };

inline const char* microfacet_type_name(MicrofacetType t) { return t == MicrofacetType::GGX ? "ggx" : "beckmann"; }

// Inverse error function in float: Giles' single-precision polynomial ("Approximating the erfinv
// function", 2010), refined by one Newton step against std::erf in double. x in (-1, 1).
inline float erfinv(float x) {
    x = std::clamp(x, -1.f + 1e-7f, 1.f - 1e-7f);
    float w = -std::log((1.f - x) * (1.f + x)), p;
    if (w < 5.f) {
        w -= 2.5f;
        p = 2.81022636e-08f;
        p = 3.43273939e-07f + p * w;
        p = -3.5233877e-06f + p * w;
        p = -4.39150654e-06f + p * w;
        p = 0.00021858087f + p * w;
        p = -0.00125372503f + p * w;
        p = -0.00417768164f + p * w;
        p = 0.246640727f + p * w;
        p = 1.50140941f + p * w;
    } else {
        w = std::sqrt(w) - 3.f;
        p = -0.000200214257f;
        p = 0.000100950558f + p * w;
        p = 0.00134934322f + p * w;
        p = -0.00367342844f + p * w;
        p = 0.00573950773f + p * w;
        p = -0.0076224613f + p * w;
        p = 0.00943887047f + p * w;
        p = 1.00167406f + p * w;
        p = 2.83297682f + p * w;
    }
    const double y = double(p) * x;
    // d erf / dy = 2 / sqrt(pi) exp(-y^2)
    const double dy = (std::erf(y) - double(x)) / (1.1283791670955126 * std::exp(-y * y));
    return float(y - dy);
}

struct Microfacet {
    MicrofacetType type = MicrofacetType::Beckmann;
    float alpha_u = 0.1f, alpha_v = 0.1f;

    Microfacet(MicrofacetType t, float au, float av)
        : type(t), alpha_u(std::max(au, kMinAlpha)), alpha_v(std::max(av, kMinAlpha)) {}
    Microfacet(MicrofacetType t, float a) : Microfacet(t, a, a) {}

    float D(vec3 m) const {
        if (m.z <= 0.f) return 0.f;
        const float z2 = m.z * m.z;
        const float sx = m.x / alpha_u, sy = m.y / alpha_v;
        float d;
        if (type == MicrofacetType::Beckmann) {
            d = std::exp(-(sx * sx + sy * sy) / z2) / (kPi * alpha_u * alpha_v * z2 * z2);
        } else {
            const float t = sx * sx + sy * sy + z2;
            d = 1.f / (kPi * alpha_u * alpha_v * t * t);
        }
        // As Mitsuba: drop vanishing densities, which only produce overflow further on.
        return std::isfinite(d) && d * m.z > 1e-20f ? d : 0.f;
    }

    float G1(vec3 v, vec3 m) const {
        if (glm::dot(v, m) * v.z <= 0.f) return 0.f;
        const float xy2 = sqr(alpha_u * v.x) + sqr(alpha_v * v.y);
        if (xy2 == 0.f) return 1.f;
        const float tan2_alpha2 = xy2 / (v.z * v.z);
        if (type == MicrofacetType::Beckmann) {
            const float a = 1.f / std::sqrt(tan2_alpha2);
            if (a >= 1.6f) return 1.f;
            return (3.535f * a + 2.181f * a * a) / (1.f + 2.276f * a + 2.577f * a * a);
        }
        return 2.f / (1.f + std::sqrt(1.f + tan2_alpha2));
    }
    float G(vec3 wo, vec3 wi, vec3 m) const { return G1(wo, m) * G1(wi, m); }

    // Density of sample_visible(v, .) over microfacet normals (solid angle of m), v.z > 0.
    float pdf_visible(vec3 v, vec3 m) const {
        if (v.z <= 0.f) return 0.f;
        return G1(v, m) * std::max(0.f, glm::dot(v, m)) * D(m) / v.z;
    }

    vec3 sample_visible(vec3 v, vec2 u) const {
        // Stretch v to the configuration where the roughness is 1 in both directions.
        const vec3 vh = glm::normalize(vec3(alpha_u * v.x, alpha_v * v.y, v.z));
        vec3 nh;
        if (type == MicrofacetType::GGX) {
            // The visible normals of a hemisphere: a disk seen from vh plus the half-disk hidden
            // behind it.
            const float len2 = vh.x * vh.x + vh.y * vh.y;
            const vec3 t1 = len2 > 0.f ? vec3(-vh.y, vh.x, 0.f) / std::sqrt(len2) : vec3(1.f, 0.f, 0.f);
            const vec3 t2 = glm::cross(vh, t1);
            vec2 p = square_to_uniform_disk_concentric(u);
            // Squash the lower half of the disk onto the visible projected area.
            const float s = 0.5f * (1.f + vh.z);
            p.y = (1.f - s) * safe_sqrt(1.f - p.x * p.x) + s * p.y;
            nh = p.x * t1 + p.y * t2 + safe_sqrt(1.f - p.x * p.x - p.y * p.y) * vh;
        } else {
            // Slopes of the visible normals in the frame where vh lies in the xz plane.
            const vec2 slope = beckmann_visible_slopes_11(vh.z, u);
            const float r = std::sqrt(vh.x * vh.x + vh.y * vh.y);
            const float c = r > 0.f ? vh.x / r : 1.f, s = r > 0.f ? vh.y / r : 0.f;
            const vec2 rs(c * slope.x - s * slope.y, s * slope.x + c * slope.y);
            nh = vec3(-rs.x, -rs.y, 1.f);  // (unnormalised) normal of those slopes
        }
        // Unstretch; the normal transforms with the inverse transpose.
        return glm::normalize(vec3(alpha_u * nh.x, alpha_v * nh.y, std::max(1e-7f, nh.z)));
    }

private:
    static float sqr(float x) { return x * x; }

    // Beckmann, roughness 1, v at cos theta_i in the xz plane: the slope x has (in the erf domain
    // x' = erf(slope)) the CDF proportional to 1 + x' + tan theta_i / sqrt(pi) exp(-slope^2) over
    // [-1, erf(cot theta_i)]; the slope y is independent and Gaussian.
    static vec2 beckmann_visible_slopes_11(float cos_i, vec2 u) {
        constexpr float kInvSqrtPi = 0.56418958354775628f;
        const float tan_i = safe_sqrt(1.f - cos_i * cos_i) / cos_i;
        const float cot_i = 1.f / tan_i;  // +inf at normal incidence: erf(inf) = 1
        const float maxval = std::erf(cot_i);
        u = glm::clamp(u, vec2(1e-6f), vec2(1.f - 1e-6f));
        // Exact solution at grazing incidence as the first guess.
        float x = maxval - (maxval + 1.f) * std::erf(std::sqrt(-std::log(u.x)));
        const float target = u.x * (1.f + maxval + kInvSqrtPi * tan_i * std::exp(-cot_i * cot_i));
        for (int i = 0; i < 3; ++i) {
            const float slope = erfinv(x);
            const float value = 1.f + x + kInvSqrtPi * tan_i * std::exp(-slope * slope) - target;
            const float derivative = 1.f - slope * tan_i;  // >= 0: the CDF is increasing
            if (!(derivative > 0.f)) break;
            x -= value / derivative;
            x = std::clamp(x, -1.f + 1e-7f, maxval);
        }
        return vec2(erfinv(x), erfinv(2.f * u.y - 1.f));
    }
};

// The isotropic or anisotropic GGX distribution (what the principled BSDF builds on).
struct Ggx : Microfacet {
    explicit Ggx(float a) : Microfacet(MicrofacetType::GGX, a, a) {}
    Ggx(float au, float av) : Microfacet(MicrofacetType::GGX, au, av) {}
};

}  // namespace candela
