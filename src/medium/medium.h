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
// A heterogeneous medium (Mitsuba's `heterogeneous` with a `gridvolume` sigma_t) has the extinction
// scale * density(p) inside its grid's box and none outside; its albedo is a constant or a grid.
// Distances in it are sampled by delta tracking against the majorant scale * max(density), shadow
// rays take ratio tracking's estimate of the transmittance (Woodcock; Novak et al. 2014).
// The phase function p(w_in, w_out) is a density in solid angle over w_out (integrates to 1), of
// the cosine between the travel directions before and after scattering: sample_phase returns a
// direction with pdf == eval, so the weight of a phase sample is exactly 1.
#include <cmath>
#include <memory>
#include <string>
#include "core/frame.h"
#include "core/math.h"
#include "core/ray.h"
#include "medium/grid.h"

namespace candela {

struct Medium {
    std::string name;      // its id in the scene file, for messages
    vec3 sigma_t{1.f};     // per unit length, scale applied (derived: refresh_medium)
    vec3 sigma_t_base{1.f};  // homogeneous: sigma_t as the file gives it, before scale (what the viewer edits)
    vec3 albedo{0.75f};    // Mitsuba's default
    float g = 0.f;         // 0: isotropic
    // Heterogeneous media only (density non-null): a one-channel density grid, the world-to-grid
    // (unit cube) transform of each grid, and the majorant.
    std::shared_ptr<const VolumeGrid> density, albedo_grid;
    glm::mat4 density_to_local{1.f}, albedo_to_local{1.f};
    float scale = 1.f;
    float majorant = 0.f;  // scale * max(density): >= the extinction everywhere
    bool heterogeneous() const { return density != nullptr; }
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

// ---- heterogeneous media --------------------------------------------------------------------------

inline vec3 to_grid(const glm::mat4& m, vec3 p) { return vec3(m * glm::vec4(p, 1.f)); }

// The part [t0, t1] of [0, tmax] along `ray` inside the density grid's box; false when empty.
inline bool clip_to_grid(const Medium& m, const Ray& ray, float tmax, float& t0, float& t1) {
    const vec3 o = to_grid(m.density_to_local, ray.o);
    const vec3 d = vec3(m.density_to_local * glm::vec4(ray.d, 0.f));
    t0 = 0.f;
    t1 = tmax;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.f) {
            if (o[a] < 0.f || o[a] > 1.f) return false;
            continue;
        }
        float ta = (0.f - o[a]) / d[a], tb = (1.f - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 < t1;
}

inline float extinction_at(const Medium& m, vec3 p) {
    return m.scale * m.density->eval_1(to_grid(m.density_to_local, p));
}
inline vec3 albedo_at(const Medium& m, vec3 p) {
    return m.albedo_grid ? glm::clamp(m.albedo_grid->eval(to_grid(m.albedo_to_local, p)), 0.f, 1.f) : m.albedo;
}

// Delta tracking along `ray` (unit direction) up to tmax: true with the distance of the first real
// collision (probability 1 - transmittance of that stretch, at the density of collisions there);
// the sampled event's weight is then the albedo there (estimator of a grey extinction).
template <class S>
inline bool delta_track(const Medium& m, const Ray& ray, float tmax, S& sampler, float& t_hit) {
    float t0, t1;
    if (!(m.majorant > 0.f) || !clip_to_grid(m, ray, tmax, t0, t1)) return false;
    float t = t0;
    for (int i = 0; i < (1 << 20); ++i) {
        t -= std::log1p(-sampler.next_1d()) / m.majorant;
        if (!(t < t1)) return false;
        if (sampler.next_1d() * m.majorant < extinction_at(m, ray.o + t * ray.d)) {
            t_hit = t;
            return true;
        }
    }
    return false;
}

// Ratio tracking: an unbiased estimate of exp(-integral of the extinction) over [0, len] of `ray`
// (unit direction): the product of 1 - sigma_t / majorant over tentative collisions.
template <class S>
inline float ratio_track(const Medium& m, const Ray& ray, float len, S& sampler) {
    float t0, t1;
    if (!(m.majorant > 0.f) || !clip_to_grid(m, ray, len, t0, t1)) return 1.f;
    float T = 1.f, t = t0;
    for (int i = 0; i < (1 << 20); ++i) {
        t -= std::log1p(-sampler.next_1d()) / m.majorant;
        if (!(t < t1)) return T;
        T *= std::max(0.f, 1.f - extinction_at(m, ray.o + t * ray.d) / m.majorant);
        if (!(T > 0.f)) return 0.f;
    }
    return 0.f;
}

// Derives sigma_t and the majorant from what a file or the viewer sets: sigma_t_base (homogeneous)
// or the density grid (heterogeneous), times scale.
inline void refresh_medium(Medium& m) {
    if (m.heterogeneous()) {
        m.majorant = m.scale * m.density->max_value;
        m.sigma_t = vec3(m.majorant);
    } else {
        m.sigma_t = m.sigma_t_base * m.scale;
    }
}

// Why a medium's values are refused (nullptr when valid): the loader's and the viewer's one rule.
inline const char* medium_error(const Medium& m) {
    if (!(m.scale >= 0.f) || !std::isfinite(m.scale)) return "scale must be finite and >= 0";
    for (int c = 0; c < 3; ++c) {
        if (!(m.sigma_t[c] >= 0.f) || !std::isfinite(m.sigma_t[c])) return "sigma_t (times scale) must be finite and >= 0";
        if (!(m.albedo[c] >= 0.f && m.albedo[c] <= 1.f)) return "albedo must lie in [0, 1]";
    }
    if (!(m.g > -1.f && m.g < 1.f)) return "the hg phase function's g must lie in (-1, 1)";
    return nullptr;
}

}  // namespace candela
