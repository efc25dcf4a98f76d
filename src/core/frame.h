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
    vec3 to_local(vec3 v) const { return vec3(glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)); }
    vec3 to_world(vec3 v) const { return s * v.x + t * v.y + n * v.z; }

    static float cos_theta(vec3 v) { return v.z; }
    static float abs_cos_theta(vec3 v) { return std::abs(v.z); }
};

}  // namespace candela
