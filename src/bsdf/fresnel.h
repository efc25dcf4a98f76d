#pragma once
// Fresnel equations and the mirror / refraction directions they go with, in the local shading
// frame (n = +z). Unpolarised light throughout: reflectances are the mean of the s and p ones.
#include <optional>
#include <string>
#include "core/math.h"

namespace candela {

// Mirror direction of w about the normal +z, and about a microfacet normal m (unit).
inline vec3 reflect_z(vec3 w) { return vec3(-w.x, -w.y, w.z); }
inline vec3 reflect(vec3 w, vec3 m) { return 2.f * glm::dot(w, m) * m - w; }

// A smooth dielectric interface between an outside (+z side) and an inside (-z side) medium.
struct FresnelDielectric {
    float F = 1.f;       // reflectance, in [0, 1]; 1 under total internal reflection
    float cos_t = 0.f;   // cosine of the transmitted direction, signed: on the other side than cos_i
    float eta_it = 1.f;  // n_transmitted / n_incident: the relative IOR a refraction crosses
    float eta_ti = 1.f;  // its inverse
};

// cos_i: cosine between the incident direction (pointing away from the surface) and the normal,
// signed: positive when it lies outside. eta = n_inside / n_outside.
inline FresnelDielectric fresnel_dielectric(float cos_i, float eta) {
    FresnelDielectric r;
    const bool outside = cos_i >= 0.f;
    r.eta_it = outside ? eta : 1.f / eta;
    r.eta_ti = outside ? 1.f / eta : eta;
    const float ci = std::abs(cos_i);
    // Snell: sin_t = sin_i * eta_ti.
    const float cos_t2 = 1.f - (1.f - ci * ci) * r.eta_ti * r.eta_ti;
    if (eta == 1.f) {  // index-matched: everything passes straight through
        r.F = 0.f;
        r.cos_t = -cos_i;
        return r;
    }
    if (cos_t2 <= 0.f || ci == 0.f) {  // total internal reflection, or exactly grazing
        r.F = 1.f;
        r.cos_t = 0.f;
        return r;
    }
    const float ct = std::sqrt(cos_t2);
    // Amplitude ratios for the s (perpendicular) and p (parallel) polarisations.
    const float rs = (ci - r.eta_it * ct) / (ci + r.eta_it * ct);
    const float rp = (r.eta_it * ci - ct) / (r.eta_it * ci + ct);
    r.F = 0.5f * (rs * rs + rp * rp);
    r.cos_t = outside ? -ct : ct;
    return r;
}

// Refraction of w (pointing away from the surface) through the microfacet normal m, with cos_t and
// eta_ti from fresnel_dielectric(dot(w, m), eta). The result points away on the other side.
inline vec3 refract(vec3 w, vec3 m, float cos_t, float eta_ti) {
    return m * (glm::dot(w, m) * eta_ti + cos_t) - w * eta_ti;
}

// Reflectance of a conductor with complex IOR eta + i k (relative to the outside medium) for an
// incident cosine cos_i in [0, 1], per colour channel. With (eta, k) = (0, 1), i.e. a purely
// imaginary IOR, both polarisations reflect totally: F = 1 at every angle (Mitsuba's "none").
//
// Complex Snell's law and the two polarisations written out in real arithmetic (the form of
// Moeller's "Optics", which Mitsuba 3 and pbrt-v3 also use): with n^2 - sin^2 = a^2 - b^2 + 2iab,
// a^2 + b^2 = |eta^2 - k^2 - sin^2 + 2i eta k|, then R_s and R_p / R_s as ratios of real terms.
// Real arithmetic because std::complex<float> goes through libgcc's __divsc3 and csqrtf (the cost
// is in bench/RESULTS.md). tests/test_bsdf_models.cpp checks it against complex arithmetic in
// double.
inline float fresnel_conductor(float cos_i, float eta, float k) {
    if (eta * eta + k * k == 0.f) return 1.f;
    cos_i = std::clamp(cos_i, 0.f, 1.f);
    const float cos2 = cos_i * cos_i, sin2 = 1.f - cos2;
    const float re = eta * eta - k * k - sin2;                    // Re(n^2 - sin^2)
    const float a2b2 = std::sqrt(re * re + 4.f * eta * eta * k * k);  // |n^2 - sin^2| = a^2 + b^2
    // a^2 = (a^2 + b^2 + re) / 2, or, where re < 0 would cancel it (total internal reflection of
    // a nearly real eta < 1), the same as 2 eta^2 k^2 / (a^2 + b^2 - re).
    const float a2 = re >= 0.f ? 0.5f * (a2b2 + re) : 2.f * eta * eta * k * k / (a2b2 - re);
    const float a = std::sqrt(a2);  // Re(sqrt(n^2 - sin^2))
    const float t1 = a2b2 + cos2, t2 = 2.f * cos_i * a;
    if (!(t1 + t2 > 0.f)) return 1.f;  // n^2 = 1 at grazing incidence: the limit, total reflection
    const float r_s = (t1 - t2) / (t1 + t2);
    const float t3 = a2b2 * cos2 + sin2 * sin2, t4 = t2 * sin2;
    const float r_p = r_s * (t3 - t4) / (t3 + t4);
    return 0.5f * (r_s + r_p);
}
inline vec3 fresnel_conductor(float cos_i, vec3 eta, vec3 k) {
    return vec3(fresnel_conductor(cos_i, eta.x, k.x), fresnel_conductor(cos_i, eta.y, k.y),
                fresnel_conductor(cos_i, eta.z, k.z));
}

// Hemispherical average of the dielectric reflectance, 2 * integral of F(mu) mu dmu over [0, 1],
// for light arriving from the side where eta = n_other / n_this (numerical quadrature; exact to
// about 1e-6). Used by the plastic coat for the light bouncing back under the interface.
float fresnel_diffuse_reflectance(float eta);

// Index of refraction by name, as Mitsuba's int_ior / ext_ior accept them ("bk7", "air", ...).
std::optional<float> ior_from_name(const std::string& name);

}  // namespace candela
