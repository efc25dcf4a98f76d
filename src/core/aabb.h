#pragma once
#include "core/math.h"
#include "core/ray.h"

namespace candela {

// Axis-aligned box. An empty box has min = +inf, max = -inf, so that expand() just works.
struct AABB {
    vec3 min{kInfinity};
    vec3 max{-kInfinity};

    AABB() = default;
    AABB(vec3 a, vec3 b) : min(a), max(b) {}
    bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    void expand(vec3 p) { min = glm::min(min, p); max = glm::max(max, p); }
    void expand(const AABB& b) { min = glm::min(min, b.min); max = glm::max(max, b.max); }
    vec3 extent() const { return max - min; }
    vec3 center() const { return 0.5f * (min + max); }
    float surface_area() const {
        if (empty()) return 0.f;
        vec3 e = extent();
        return 2.f * (e.x * e.y + e.y * e.z + e.z * e.x);
    }
    bool contains(vec3 p) const {
        return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y && p.z >= min.z && p.z <= max.z;
    }

    // Slab test against [ray.tmin, ray.tmax]. inv_d is 1/d per component (may be +-inf for axis-
    // parallel rays). The far distance is scaled up by 1 + 2 gamma(3) so that a ray grazing the box
    // is never culled by rounding (pbrt-v4, Bounds3::IntersectP). NaNs (0 * inf) fall through the
    // comparisons so that they never shrink the interval. On a hit, t0/t1 are the entry/exit.
    bool intersect(const Ray& ray, vec3 inv_d, float& t0, float& t1) const {
        float lo = ray.tmin, hi = ray.tmax;
        for (int i = 0; i < 3; ++i) {
            float tn = (min[i] - ray.o[i]) * inv_d[i];
            float tf = (max[i] - ray.o[i]) * inv_d[i];
            if (tn > tf) std::swap(tn, tf);
            tf *= 1.f + 2.f * gamma_bound(3);
            lo = tn > lo ? tn : lo;
            hi = tf < hi ? tf : hi;
            if (lo > hi) return false;
        }
        t0 = lo;
        t1 = hi;
        return true;
    }
};

}  // namespace candela
