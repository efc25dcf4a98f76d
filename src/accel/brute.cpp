#include "accel/brute.h"
#include "geometry/triangle.h"

namespace candela {

bool BruteForceAccel::intersect(Ray& ray, Hit& hit) const {
    RayShear sh(ray.d);
    bool found = false;
    const uint32_t n = uint32_t(mesh_->triangles.size());
    for (uint32_t i = 0; i < n; ++i) {
        vec3 p0, p1, p2;
        mesh_->vertices(i, p0, p1, p2);
        TriangleHit th;
        if (intersect_triangle(ray, sh, p0, p1, p2, th)) {
            ray.tmax = th.t;
            hit.t = th.t;
            hit.b1 = th.b1;
            hit.b2 = th.b2;
            hit.prim = i;
            found = true;
        }
    }
    return found;
}

bool BruteForceAccel::occluded(const Ray& ray) const {
    RayShear sh(ray.d);
    const uint32_t n = uint32_t(mesh_->triangles.size());
    for (uint32_t i = 0; i < n; ++i) {
        vec3 p0, p1, p2;
        mesh_->vertices(i, p0, p1, p2);
        TriangleHit th;
        if (intersect_triangle(ray, sh, p0, p1, p2, th)) return true;
    }
    return false;
}

}  // namespace candela
