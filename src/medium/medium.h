#pragma once
// Participating media (Mitsuba 3's `homogeneous` medium with its `isotropic` and `hg` phase
// functions), in RGB. docs/media.md has the semantics and what is not supported.
//
// Contract. A medium fills the inside (or outside) of the shapes that name it (Shape::interior,
// Shape::exterior) and the space around the camera (Geometry::camera_medium); a ray carries the
// index of the medium it travels in and changes it where it crosses a shape that names media, to
// the side of the shape's geometric normal it leaves towards (Mitsuba's target_medium).
//   sigma_t   extinction per unit of world length (Mitsuba's sigma_t times its scale)
//   albedo    sigma_s / sigma_t (unitless, [0, 1])
//   g         Henyey-Greenstein asymmetry in (-1, 1): > 0 scatters forwards; isotropic is g = 0
// The phase function p(w_in, w_out) is a density in solid angle over w_out (integrates to 1), of
// the cosine between the travel directions before and after scattering: sample_phase returns a
// direction with pdf == eval, so the weight of a phase sample is exactly 1.
#include <cmath>
#include <string>
#include "core/frame.h"
#include "core/math.h"

namespace candela {

struct Medium {
    std::string name;      // its id in the scene file, for messages
    vec3 sigma_t{1.f};     // per unit length, scale applied
    vec3 albedo{0.75f};    // Mitsuba's default
    float g = 0.f;         // 0: isotropic
    bool spectral() const { return !(sigma_t.x == sigma_t.y && sigma_t.y == sigma_t.z); }
    vec3 sigma_s() const { return sigma_t * albedo; }
};

// Henyey-Greenstein density of the cosine `mu` between the travel directions (1: straight on).
inline float hg_phase(float g, float mu) {
    const float denom = 1.f + g * g - 2.f * g * mu;
    return (1.f - g * g) / (4.f * kPi * denom * std::sqrt(std::max(denom, 1e-12f)));
}

// A direction after scattering, for a ray that travelled along unit `d`; the density is
// hg_phase(g, dot(d, result)). The cosine by inverting the CDF of mu; uniform in azimuth.
inline vec3 sample_phase(float g, vec3 d, vec2 u) {
    float mu;
    if (std::abs(g) < 1e-3f) {
        mu = 1.f - 2.f * u.x;
    } else {
        const float s = (1.f - g * g) / (1.f - g + 2.f * g * u.x);
        mu = (1.f + g * g - s * s) / (2.f * g);
    }
    mu = std::clamp(mu, -1.f, 1.f);
    const float sin_t = std::sqrt(std::max(0.f, 1.f - mu * mu));
    const float phi = 2.f * kPi * u.y;
    return Frame(d).to_world(vec3(sin_t * std::cos(phi), sin_t * std::sin(phi), mu));
}

// Transmittance exp(-sigma_t t) over a length t (infinity: zero where sigma_t > 0).
inline vec3 transmittance(const Medium& m, float t) {
    return vec3(std::exp(-m.sigma_t.x * t), std::exp(-m.sigma_t.y * t), std::exp(-m.sigma_t.z * t));
}

// Free-flight distance sampled in one colour channel (Mitsuba 3's volpath picks the channel
// uniformly once per path): density sigma_c exp(-sigma_c t). Infinity when sigma_c is 0.
inline float sample_distance(const Medium& m, int channel, float u) {
    const float s = m.sigma_t[channel];
    return s > 0.f ? -std::log1p(-u) / s : kInfinity;
}

// Why a medium's values are refused (nullptr when valid): the loader's one rule.
inline const char* medium_error(const Medium& m) {
    for (int c = 0; c < 3; ++c) {
        if (!(m.sigma_t[c] >= 0.f) || !std::isfinite(m.sigma_t[c])) return "sigma_t (times scale) must be finite and >= 0";
        if (!(m.albedo[c] >= 0.f && m.albedo[c] <= 1.f)) return "albedo must lie in [0, 1]";
    }
    if (!(m.g > -1.f && m.g < 1.f)) return "the hg phase function's g must lie in (-1, 1)";
    return nullptr;
}

}  // namespace candela
