#pragma once
#include "core/frame.h"
#include "core/ray.h"

namespace candela {

// The kinds of primitive an accelerator reports (geometry/analytic.h for the analytic ones).
enum class PrimKind : uint32_t { Triangle = 0, Sphere, Disk, Cylinder, Curve };

// What an accelerator reports: the closest primitive and where on it. A triangle's surface point
// is rebuilt from the barycentrics (not o + t d), which keeps its error small and bounded; an
// analytic shape's is `local`, already refined onto the surface by its intersector.
struct Hit {
    float t = kInfinity;
    float b1 = 0.f, b2 = 0.f;
    uint32_t prim = ~0u;                // triangle index, or index into Geometry::analytic
    PrimKind kind = PrimKind::Triangle;
    vec3 local{0.f};                    // analytic shapes only (see intersect_analytic)
    // Index into Geometry::instances when the primitive belongs to an instanced shapegroup: prim,
    // kind and local are then in the group's own space. ~0u for the scene's own primitives.
    uint32_t instance = ~0u;
};

// A point on a surface with what shading needs. p_error bounds |p - exact point| per axis.
struct SurfaceInteraction {
    vec3 p{0.f};
    vec3 p_error{0.f};
    vec3 ng{0.f, 0.f, 1.f};  // geometric normal, normalised, from the triangle's winding
    vec3 ns{0.f, 0.f, 1.f};  // shading normal (interpolated vertex normal, or ng)
    // Texture coordinates and the world-space derivatives of the point with respect to them, as
    // Mitsuba 3 defines them for meshes: with vertex uvs, uv is interpolated and dp/du, dp/dv solve
    // p1-p0 = dpdu du1 + dpdv dv1, p2-p0 = dpdu du2 + dpdv dv2 (an orthonormal pair around ng when
    // the uv triangle is degenerate); without, uv = (b1, b2), dpdu = p1-p0, dpdv = p2-p0.
    // Analytic shapes set uv by their own Mitsuba parameterisation (geometry/analytic.cpp).
    vec2 uv{0.f};
    vec3 dpdu{1.f, 0.f, 0.f}, dpdv{0.f, 1.f, 0.f};
    uint32_t prim = ~0u;
    uint32_t shape = ~0u;
    PrimKind kind = PrimKind::Triangle;
    uint32_t instance = ~0u;  // as Hit::instance (p, normals, dpdu/dpdv in world space regardless)
};

// Offsets p along the normal by the point's error bound, on the side of w, then rounds away from
// the surface (pbrt-v4 OffsetRayOrigin). The offset scales with the coordinates themselves, so it
// works at any scene scale, unlike a fixed epsilon.
inline vec3 offset_ray_origin(vec3 p, vec3 p_error, vec3 n, vec3 w) {
    float d = glm::dot(abs3(n), p_error);
    vec3 offset = d * n;
    if (glm::dot(w, n) < 0.f) offset = -offset;
    vec3 po = p + offset;
    for (int i = 0; i < 3; ++i) {
        if (offset[i] > 0.f) po[i] = next_float_up(po[i]);
        else if (offset[i] < 0.f) po[i] = next_float_down(po[i]);
    }
    return po;
}

// A ray leaving the surface in direction w (any length).
inline Ray spawn_ray(const SurfaceInteraction& si, vec3 w) {
    Ray r;
    r.o = offset_ray_origin(si.p, si.p_error, si.ng, w);
    r.d = w;
    return r;
}

// Both ends offset: for shadow rays between two surface points. tmax stops just short of the
// (offset) target so that the target's own surface is never reported as an occluder.
constexpr float kShadowEpsilon = 1e-4f;
inline Ray spawn_ray_to(const SurfaceInteraction& from, vec3 to_p, vec3 to_error, vec3 to_n) {
    Ray r;
    r.o = offset_ray_origin(from.p, from.p_error, from.ng, to_p - from.p);
    vec3 pt = offset_ray_origin(to_p, to_error, to_n, r.o - to_p);
    r.d = pt - r.o;
    r.tmax = 1.f - kShadowEpsilon;
    return r;
}

}  // namespace candela
