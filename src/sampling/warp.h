#pragma once
// Warps from the unit square [0,1)^2 to other domains, each with the density it produces.
// Densities are with respect to the natural measure of the target: area for disks and triangles,
// solid angle for directions. Every warp is chi-square tested against its pdf (tests/test_warp.cpp).
#include "core/math.h"

namespace candela {

// sin a and cos a for |a| <= pi/4, the only range the concentric map needs, as short polynomials
// (minimax, the coefficients of Cephes' sinf/cosf; error within 2 ulp of the exact values, tested
// in test_warp.cpp). No range reduction and no libm call, which the full-range sincosf needs
// (the cost is in bench/RESULTS.md).
inline void sincos_quarter(float a, float& s, float& c) {
    const float a2 = a * a;
    s = a + a * a2 * (-1.6666654611e-1f + a2 * (8.3321608736e-3f + a2 * -1.9515295891e-4f));
    c = 1.f - 0.5f * a2 + a2 * a2 * (4.166664568298827e-2f + a2 * (-1.388731625493765e-3f + a2 * 2.443315711809948e-5f));
}

// Shirley-Chiu concentric map: low distortion, continuous, area-preserving up to a constant.
inline vec2 square_to_uniform_disk_concentric(vec2 u) {
    vec2 o = 2.f * u - vec2(1.f);
    if (o.x == 0.f && o.y == 0.f) return vec2(0.f);
    // The wedge (|x| > |y|: angle a = pi/4 y/x; else pi/2 - a with a = pi/4 x/y) is a coin toss
    // per sample: chosen without a branch, with one division. cos(pi/2 - a) = sin a.
    const bool xm = std::abs(o.x) > std::abs(o.y);
    const float r = choose(xm, o.x, o.y);
    const float a = (kPi / 4.f) * (choose(xm, o.y, o.x) / r);
    float s, c;
    sincos_quarter(a, s, c);
    return r * vec2(choose(xm, c, s), choose(xm, s, c));
}
inline float square_to_uniform_disk_pdf(vec2 p) { return glm::dot(p, p) <= 1.f ? kInvPi : 0.f; }

// Cosine-weighted hemisphere about +z (Malley's method); pdf = cos(theta) / pi per steradian.
inline vec3 square_to_cosine_hemisphere(vec2 u) {
    vec2 d = square_to_uniform_disk_concentric(u);
    float z = safe_sqrt(1.f - d.x * d.x - d.y * d.y);
    return vec3(d.x, d.y, z);
}
inline float square_to_cosine_hemisphere_pdf(vec3 v) { return v.z > 0.f ? v.z * kInvPi : 0.f; }

inline vec3 square_to_uniform_sphere(vec2 u) {
    float z = 1.f - 2.f * u.x;
    float r = safe_sqrt(1.f - z * z);
    float phi = 2.f * kPi * u.y;
    return vec3(r * std::cos(phi), r * std::sin(phi), z);
}
inline float square_to_uniform_sphere_pdf(vec3) { return kInv4Pi; }
// The inverse of square_to_uniform_sphere (cylindrical, equal-area: u = ((1 - z) / 2, phi / 2pi)),
// clamped into [0,1)^2 so that a cell lookup never falls off the square.
inline vec2 uniform_sphere_to_square(vec3 d) {
    float phi = std::atan2(d.y, d.x);
    if (phi < 0.f) phi += 2.f * kPi;
    const float one_below = 0x1.fffffep-1f;
    return vec2(std::clamp(0.5f * (1.f - d.z), 0.f, one_below), std::clamp(phi * kInv2Pi, 0.f, one_below));
}

// Uniform direction in the cone of half-angle acos(cos_max) about +z; pdf = 1 / (2 pi (1 - cos_max))
// per steradian inside the cone, 0 outside.
inline vec3 square_to_uniform_cone(vec2 u, float cos_max) {
    float z = 1.f - u.x * (1.f - cos_max);
    float r = safe_sqrt(1.f - z * z);
    float phi = 2.f * kPi * u.y;
    return vec3(r * std::cos(phi), r * std::sin(phi), z);
}
inline float square_to_uniform_cone_pdf(vec3 v, float cos_max) {
    return v.z >= cos_max && cos_max < 1.f ? kInv2Pi / (1.f - cos_max) : 0.f;
}

inline vec3 square_to_uniform_hemisphere(vec2 u) {
    float z = u.x;
    float r = safe_sqrt(1.f - z * z);
    float phi = 2.f * kPi * u.y;
    return vec3(r * std::cos(phi), r * std::sin(phi), z);
}
inline float square_to_uniform_hemisphere_pdf(vec3 v) { return v.z >= 0.f ? kInv2Pi : 0.f; }

// Uniform point on a triangle as barycentrics (b0, b1, b2 = 1 - b0 - b1). This is the low-
// distortion map of Heitz 2019 ("A low-distortion map between triangle and square"): it keeps
// stratification better than the square-root map. Density 1 / area on the triangle.
inline vec2 square_to_uniform_triangle(vec2 u) {
    // Which half is a coin toss per sample: both computed, chosen without a branch.
    const float hx = u.x / 2.f, hy = u.y / 2.f;
    const bool lower = u.x < u.y;
    return vec2(choose(lower, hx, u.x - hy), choose(lower, u.y - hx, hy));
}

}  // namespace candela
