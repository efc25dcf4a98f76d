#pragma once
// The GGX (Trowbridge-Reitz) microfacet distribution, isotropic, in the local shading frame.
//
//   D(m)      density of microfacet normals per unit projected area: integral of D(m) m.z dm = 1
//   G1(v, m)  Smith masking for the GGX profile; zero when v sees the back of m or of the surface
//   G         separable Smith G1(wo) G1(wi), as Mitsuba 3 uses (so that renders agree with it)
//   sample_visible(v, u): a normal m from the distribution of normals visible from v (v.z > 0),
//             D_v(m) = G1(v, m) max(0, v.m) D(m) / v.z   (Heitz 2018, "Sampling the GGX
//             distribution of visible normals", with the concentric disk map for stratification)
//
// alpha is the roughness (the slope scale): 1e-4 is nearly a mirror, 1 is very rough. The caller
// handles alpha = 0 as a delta lobe; below 1e-4 the distribution is clamped (float precision).
#include "core/math.h"
#include "sampling/warp.h"

namespace candela {

constexpr float kMinAlpha = 1e-4f;

struct Ggx {
    float alpha;

    explicit Ggx(float a) : alpha(std::max(a, kMinAlpha)) {}

    float D(vec3 m) const {
        if (m.z <= 0.f) return 0.f;
        const float a2 = alpha * alpha;
        const float t = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
        const float d = 1.f / (kPi * a2 * t * t);
        return std::isfinite(d) ? d : 0.f;
    }
    // Smith's Lambda-based masking, 2 / (1 + sqrt(1 + alpha^2 tan^2 theta)).
    float G1(vec3 v, vec3 m) const {
        if (glm::dot(v, m) * v.z <= 0.f) return 0.f;
        const float xy2 = v.x * v.x + v.y * v.y;
        if (xy2 == 0.f) return 1.f;
        const float tan2_alpha2 = alpha * alpha * xy2 / (v.z * v.z);
        return 2.f / (1.f + std::sqrt(1.f + tan2_alpha2));
    }
    float G(vec3 wo, vec3 wi, vec3 m) const { return G1(wo, m) * G1(wi, m); }

    // Density of sample_visible(v, .) over microfacet normals (solid angle of m), v.z > 0.
    float pdf_visible(vec3 v, vec3 m) const {
        if (v.z <= 0.f) return 0.f;
        return G1(v, m) * std::max(0.f, glm::dot(v, m)) * D(m) / v.z;
    }

    vec3 sample_visible(vec3 v, vec2 u) const {
        // Stretch to the configuration where the roughness is 1: the visible normals of a
        // hemisphere, i.e. a disk seen from vh plus the half-disk hidden behind it.
        const vec3 vh = glm::normalize(vec3(alpha * v.x, alpha * v.y, v.z));
        const float len2 = vh.x * vh.x + vh.y * vh.y;
        const vec3 t1 = len2 > 0.f ? vec3(-vh.y, vh.x, 0.f) / std::sqrt(len2) : vec3(1.f, 0.f, 0.f);
        const vec3 t2 = glm::cross(vh, t1);
        vec2 p = square_to_uniform_disk_concentric(u);
        // Squash the lower half of the disk onto the visible projected area.
        const float s = 0.5f * (1.f + vh.z);
        p.y = (1.f - s) * safe_sqrt(1.f - p.x * p.x) + s * p.y;
        const vec3 nh = p.x * t1 + p.y * t2 + safe_sqrt(1.f - p.x * p.x - p.y * p.y) * vh;
        // Unstretch; the normal transforms with the inverse transpose.
        return glm::normalize(vec3(alpha * nh.x, alpha * nh.y, std::max(1e-7f, nh.z)));
    }
};

}  // namespace candela
