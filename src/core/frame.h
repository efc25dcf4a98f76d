#pragma once
#include "core/math.h"

namespace candela {

// Orthonormal shading basis (s, t, n). "Local" coordinates have n = +z, so cos(theta) = v.z.
// The basis is built without branches on n (Duff et al. 2017, "Building an orthonormal basis,
// revisited"), which is continuous everywhere but at n.z = -1 where the sign flips.
struct Frame {
    vec3 s{1, 0, 0}, t{0, 1, 0}, n{0, 0, 1};

    Frame() = default;
    explicit Frame(vec3 normal) : n(normal) {
        float sign = std::copysign(1.f, n.z);
        float a = -1.f / (sign + n.z);
        float b = n.x * n.y * a;
        s = vec3(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
        t = vec3(b, sign + n.y * n.y * a, -n.y);
    }
    // The frame of Mitsuba's SurfaceInteraction::initialize_sh_frame: s is the tangent made
    // orthogonal to n (Gram-Schmidt), t = n x s. For anisotropic BSDFs, whose x axis must follow
    // the surface's dp/du. A tangent parallel to n (or not finite) falls back to Frame(n).
    static Frame from_tangent(vec3 normal, vec3 tangent) {
        vec3 s = tangent - normal * glm::dot(normal, tangent);
        const float l2 = glm::dot(s, s);
        if (!(l2 > 1e-20f * glm::dot(tangent, tangent)) || !std::isfinite(l2)) return Frame(normal);
        Frame f;
        f.n = normal;
        f.s = s / std::sqrt(l2);
        f.t = glm::cross(normal, f.s);
        return f;
    }
    // Forced inline: the full build's path loop called both out of line (as IndependentSampler's
    // next_2d, sampler.h); three dot products are cheaper than the call.
    __attribute__((always_inline)) vec3 to_local(vec3 v) const { return vec3(glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)); }
    __attribute__((always_inline)) vec3 to_world(vec3 v) const { return s * v.x + t * v.y + n * v.z; }

    static float cos_theta(vec3 v) { return v.z; }
    static float abs_cos_theta(vec3 v) { return std::abs(v.z); }
};

}  // namespace candela
