#pragma once
// Analytic shapes as Mitsuba 3 defines them (src/shapes/sphere.cpp, disk.cpp, cylinder.cpp):
// intersected exactly, never tessellated.
//
//   sphere    centre c and radius r in world space; object space is to_object = (T R)^-1 without
//             the scale, so that local = R^T (p - c) / r is a unit vector. uv = (phi / 2pi,
//             theta / pi) of local (theta from +z, phi = atan2(y, x) in [0, 2pi)). Normal outwards.
//   disk      the unit disk z = 0, x^2 + y^2 <= 1 of object space, under an affine to_world (which
//             may scale x and y apart: an ellipse). Normal: to_world^-T (0, 0, 1), normalised.
//             uv = (r, phi / 2pi) of the object-space point.
//   cylinder  the side (no caps) x^2 + y^2 = r^2, 0 <= z <= length of a rigid object frame; normal
//             outwards; uv = (phi / 2pi, z / length).
//   curve     one segment of Mitsuba's `linearcurve` (Embree's round linear curve): the volume
//             swept by a sphere whose centre c(v) = p0 + v (p1 - p0) and radius r(v) = r0 + v (r1 - r0)
//             run over v in [0, 1], i.e. a cone tangent to two end spheres. As in Embree, a joint's
//             sphere belongs to the segment that ends there (v = 1), and a segment has its start
//             sphere only when it starts its curve (start_cap). Only the surface's
//             entering side is hit (a ray from inside sees nothing, as Embree culls it). The normal
//             is p - c(v) for the v whose sphere touches p (v = 0, 1 on the end caps). Mitsuba's
//             parameterisation: u = the angle around the axis in the frame of its local_frame
//             (guide +z) over 2 pi, v = (segment + v) / segments of the whole shape; dp/du and
//             dp/dv zero, as Mitsuba 3.9.1 has them (its shading frame is then Frame(n)).
//             Curves take no emitter and no flip_normals (Mitsuba ignores it on curves).
// flip_normals turns every normal (geometric and shading) around, and with it the side an area
// emitter on the shape lights.
//
// Intersection is computed in double (as Mitsuba's scalar variants do), and the hit point is
// refined onto the surface (reprojected on the sphere or cylinder, z = 0 on the disk) before it is
// rounded to float, so that the error bound of SurfaceInteraction::p is a few ulps whatever the
// scene's scale (pbrt-v4, section 6.8.5).
#include <cstdint>
#include "core/aabb.h"
#include "core/ray.h"
#include "geometry/interaction.h"

namespace candela {

struct AnalyticShape {
    PrimKind kind = PrimKind::Sphere;
    uint32_t shape = 0;  // index into Scene::shapes
    bool flip = false;   // normals inwards (sphere, cylinder) or towards -z (disk)
    vec3 center{0.f};    // sphere: world centre
    float radius = 1.f;  // sphere: world radius; cylinder: radius in its (unscaled) object frame
    float length = 1.f;  // cylinder: length along object z
    mat4 to_world{1.f};  // object to world (sphere and cylinder: rotation and translation only)
    glm::dmat4 to_object{1.0};
    vec3 normal{0.f, 0.f, 1.f};  // disk: world normal (flip applied)
    float area = 0.f;    // world surface area
    // curve: center and radius are p0 and r0; these the other end and the segment's place in its
    // shape (for uv.v).
    vec3 p1{0.f};
    float radius1 = 0.f;
    uint32_t segment = 0, segments = 1;
    bool start_cap = true;  // the sphere at p0 belongs to this segment: it starts its curve

    AABB bounds() const;
};

// Builds a shape from Mitsuba's parameters (object-space parameters first, then to_world); the
// caller has checked the input (see the XML factory). Sphere: to_world x translate(center) x
// scale(radius), of uniform scale and without shear; a mirroring to_world flips the normals as in
// Mitsuba. Disk: to_world without shear. Cylinder: to_world x translate(p0) x frame(p1 - p0) x
// scale(radius, radius, |p1 - p0|), without shear and with the same scale along x and y.
AnalyticShape make_sphere(const mat4& to_world, vec3 center, float radius, bool flip);
AnalyticShape make_disk(const mat4& to_world, bool flip);
AnalyticShape make_cylinder(const mat4& to_world, vec3 p0, vec3 p1, float radius, bool flip);
// A linear curve segment in world space (the caller has applied to_world to the points; the radii
// are not transformed, as in Mitsuba). segment < segments; start_cap for the first of a curve.
AnalyticShape make_curve_segment(vec3 p0, float r0, vec3 p1, float r1, uint32_t segment, uint32_t segments,
                                 bool start_cap = true);

// Closest intersection with ray.tmin < t < ray.tmax (the ray direction need not be unit). On a hit
// sets hit.t (shrinks ray.tmax to it), hit.kind and hit.local (the point refined onto the surface:
// sphere p - c and curve p - p0 in world axes, disk and cylinder object space; a curve's v in
// hit.b1); the caller sets hit.prim.
bool intersect_analytic(const AnalyticShape& s, Ray& ray, Hit& hit);
bool occluded_analytic(const AnalyticShape& s, const Ray& ray);

// The interaction at a hit reported by intersect_analytic: p with its per-axis error bound, unit
// normals, uv as Mitsuba's.
SurfaceInteraction analytic_interaction(const AnalyticShape& s, const Hit& hit);

// A point on the shape for next-event estimation from ref_p, with the solid-angle density (at
// ref_p) of the strategy that drew it:
//   sphere, ref_p outside: uniform in the cone of directions the sphere subtends (pbrt-v4
//     Sphere::Sample, Mitsuba Sphere::sample_direction); pdf = 1 / (2 pi (1 - cos theta_max)).
//   otherwise: uniform by area; pdf = dist^2 / (area |cos theta_light|).
// p_error bounds the point, n is the (possibly flipped) normal there. u in [0,1)^2.
struct AnalyticSample {
    vec3 p{0.f}, p_error{0.f}, n{0.f};
    float pdf = 0.f;  // solid angle at ref_p
};
bool sample_analytic(const AnalyticShape& s, vec3 ref_p, vec2 u, AnalyticSample& out);
// The density sample_analytic has of drawing the point `p` with normal `n` from ref_p (solid angle).
float pdf_analytic(const AnalyticShape& s, vec3 ref_p, vec3 p, vec3 n);

// Transforms a point with an error bound (pbrt-v4 Transform::operator()(Point3fi)).
vec3 transform_point_error(const mat4& m, vec3 p, vec3 p_error, vec3* error_out);

}  // namespace candela
