#pragma once
// Watertight ray-triangle intersection (Woop, Benthin, Wald 2013, "Watertight ray/triangle
// intersection"; the same as pbrt-v4's Triangle::Intersect). The ray is sheared so that it runs
// along +z; edge functions are then evaluated in 2D. A ray through a shared edge or vertex gives
// the same edge function values (up to sign) for both triangles, so it hits at least one of them
// and never slips between. Edge functions that round to exactly 0 are redone in double.
#include "core/ray.h"

namespace candela {

// Per-ray constants of the shear; computed once per ray and reused for every triangle tested.
struct RayShear {
    int kx, ky, kz;
    float sx, sy, sz;
    explicit RayShear(vec3 d) {
        kz = max_dimension(abs3(d));
        kx = kz + 1 == 3 ? 0 : kz + 1;
        ky = kx + 1 == 3 ? 0 : kx + 1;
        sx = -d[kx] / d[kz];
        sy = -d[ky] / d[kz];
        sz = 1.f / d[kz];
    }
};

struct TriangleHit {
    float t;
    float b1, b2;  // barycentrics of p1 and p2; p = (1-b1-b2) p0 + b1 p1 + b2 p2
};

// Whether the triangle has zero area as intersect_triangle() decides it (an exactly zero
// cross(p1 - p0, p2 - p0)): it never hits such a triangle, and the k-d tree leaves them out.
inline bool zero_area_triangle(vec3 p0, vec3 p1, vec3 p2) {
    const vec3 n = glm::cross(p1 - p0, p2 - p0);
    return n.x == 0.f && n.y == 0.f && n.z == 0.f;
}

// The bounds of the interval check made before the division (on t_scaled = t det), widened by
// 2^-20 of their size. That check is only an early-out: the exact one is on t after the division.
// Unwidened, the rounding of tmax det, 1 / det and t_scaled / det could make it reject a t that is
// below tmax by an ulp or two, and which of two hits an ulp apart (at a vertex several triangles
// share) is the closest would then depend on the order they are tested in. Widened, it rejects
// only what the exact check rejects too. Also used by the k-d tree's SIMD test.
inline float scaled_check_tmin(float tmin) { return tmin - std::abs(tmin) * 0x1p-20f; }
inline float scaled_check_tmax(float tmax) { return tmax + std::abs(tmax) * 0x1p-20f; }

// Returns true and fills `hit` when the ray meets the triangle with tmin < t < tmax.
inline bool intersect_triangle(const Ray& ray, const RayShear& sh, vec3 p0, vec3 p1, vec3 p2, TriangleHit& hit) {
    // Translate to the ray origin and permute so that the largest direction component is z.
    vec3 a = p0 - ray.o, b = p1 - ray.o, c = p2 - ray.o;
    float ax = a[sh.kx] + sh.sx * a[sh.kz], ay = a[sh.ky] + sh.sy * a[sh.kz];
    float bx = b[sh.kx] + sh.sx * b[sh.kz], by = b[sh.ky] + sh.sy * b[sh.kz];
    float cx = c[sh.kx] + sh.sx * c[sh.kz], cy = c[sh.ky] + sh.sy * c[sh.kz];

    float e0 = bx * cy - by * cx;
    float e1 = cx * ay - cy * ax;
    float e2 = ax * by - ay * bx;
    if (e0 == 0.f || e1 == 0.f || e2 == 0.f) {
        e0 = float(double(bx) * double(cy) - double(by) * double(cx));
        e1 = float(double(cx) * double(ay) - double(cy) * double(ax));
        e2 = float(double(ax) * double(by) - double(ay) * double(bx));
    }
    if ((e0 < 0.f || e1 < 0.f || e2 < 0.f) && (e0 > 0.f || e1 > 0.f || e2 > 0.f)) return false;
    // A zero-area triangle (collinear vertices) can pass the edge test: the shear rounds its edge
    // functions to tiny values of one sign. Reject it as pbrt-v4 does (checked here, after the
    // cheap edge test, so that it costs nothing for the many triangles that miss).
    if (zero_area_triangle(p0, p1, p2)) return false;
    float det = e0 + e1 + e2;
    if (det == 0.f) return false;

    float az = sh.sz * a[sh.kz], bz = sh.sz * b[sh.kz], cz = sh.sz * c[sh.kz];
    float t_scaled = e0 * az + e1 * bz + e2 * cz;
    // Compare t against [tmin, tmax] (widened) without dividing: the signs follow det's.
    const float lo = scaled_check_tmin(ray.tmin) * det, hi = scaled_check_tmax(ray.tmax) * det;
    if (det < 0.f && (t_scaled >= lo || t_scaled <= hi)) return false;
    if (det > 0.f && (t_scaled <= lo || t_scaled >= hi)) return false;

    float inv_det = 1.f / det;
    float t = t_scaled * inv_det;
    if (!(t > ray.tmin && t < ray.tmax)) return false;  // rounding, and NaN from degenerate input

    // t must exceed its own rounding error bound (pbrt-v4 Triangle::Intersect, section 6.8.7 of
    // "Physically Based Rendering", 4th ed.). A ray leaving a surface point whose coordinate along
    // the normal is exact (e.g. a wall at x = 0: zero error, so zero origin offset) would otherwise
    // re-hit its own triangle at t ~ 1e-8 from rounding in the other coordinates.
    float max_zt = max_component(abs3(vec3(az, bz, cz)));
    float max_xt = max_component(abs3(vec3(ax, bx, cx)));
    float max_yt = max_component(abs3(vec3(ay, by, cy)));
    float delta_z = gamma_bound(3) * max_zt;
    float delta_x = gamma_bound(5) * (max_xt + max_zt);
    float delta_y = gamma_bound(5) * (max_yt + max_zt);
    float delta_e = 2.f * (gamma_bound(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    float max_e = max_component(abs3(vec3(e0, e1, e2)));
    float delta_t = 3.f * (gamma_bound(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * std::abs(inv_det);
    if (t <= delta_t) return false;

    hit.t = t;
    hit.b1 = e1 * inv_det;
    hit.b2 = e2 * inv_det;
    return true;
}

}  // namespace candela
