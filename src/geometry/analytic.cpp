#include "geometry/analytic.h"
#include <glm/gtc/matrix_transform.hpp>
#include "core/error.h"
#include "core/frame.h"
#include "sampling/warp.h"

namespace candela {

namespace {

using glm::dmat3;
using glm::dvec2;

// Error bound of a point refined onto a sphere of centre c: q = p - c is the double-precision
// reprojection rounded to float (<= 1 ulp of |q| per axis), p = c + q one more rounding. pbrt-v4
// uses gamma(5) |q| for its float reprojection; the extra gamma(2) |p| covers the centre's offset.
vec3 sphere_point_error(vec3 q, vec3 p) { return gamma_bound(5) * abs3(q) + gamma_bound(2) * abs3(p); }

// Columns of the linear part of m.
void columns(const mat4& m, vec3& a, vec3& b, vec3& c) {
    a = vec3(m[0]);
    b = vec3(m[1]);
    c = vec3(m[2]);
}

bool nearly_orthogonal(vec3 a, vec3 b) {
    return std::abs(glm::dot(a, b)) <= 1e-4f * glm::length(a) * glm::length(b);
}

bool all_finite_matrix(const mat4& m) {
    for (int i = 0; i < 4; ++i)
        if (!all_finite(vec3(m[i])) || !std::isfinite(m[i][3])) return false;
    return true;
}

// The first root of (ray.o + t d - centre) restricted to the plane perpendicular to the axis (2D
// for the cylinder), solved from the point of closest approach: o is moved along the ray to the
// foot of the perpendicular from the centre, so that the quadratic never subtracts two large
// numbers (Mitsuba's sphere does the same; pbrt-v4 section 6.8.4). Returns both roots.
bool solve_from_foot(dvec3 o, dvec3 d, double r, double& t0, double& t1) {
    double dd = glm::dot(d, d);
    if (!(dd > 0.0)) return false;
    double tc = -glm::dot(o, d) / dd;
    double l = glm::length(o + tc * d);
    double h2 = (r - l) * (r + l);
    if (!(h2 >= 0.0)) return false;
    double s = std::sqrt(h2 / dd);
    t0 = tc - s;
    t1 = tc + s;
    return true;
}

double wrap_phi(double y, double x) {
    double phi = std::atan2(y, x);
    return phi < 0.0 ? phi + 2.0 * 3.14159265358979323846 : phi;
}

// The ray in the shape's object space, in double.
void to_object(const AnalyticShape& s, const Ray& ray, dvec3& o, dvec3& d) {
    o = dvec3(s.to_object * glm::dvec4(dvec3(ray.o), 1.0));
    d = dmat3(s.to_object) * dvec3(ray.d);
}

// The entering hit of a linear curve segment (geometry/analytic.h): the first entry into its end
// sphere(s) or into the lateral cone between them, whichever comes first. The earliest entry into one
// of these convex pieces is the entry into their union, so overlaps (the cone and the spheres, and
// neighbouring segments at a joint) need no special case; the joint's sphere is tested once, by the
// segment that ends there. Solved in double around the foot of the
// ray on the segment's midpoint; the point returned is p - p0, reprojected onto the sphere of the
// v found (v in [0, 1]: 0 and 1 on the caps).
bool curve_hit(const AnalyticShape& s, const Ray& ray, double& t_out, dvec3& q_out, double& v_out) {
    const dvec3 a(s.center), b(s.p1), d(ray.d);
    const double ra = s.radius, rb = s.radius1;
    const double dd = glm::dot(d, d);
    if (!(dd > 0.0)) return false;
    const dvec3 o0(ray.o);
    const double ts = glm::dot(0.5 * (a + b) - o0, d) / dd;
    const dvec3 oa = o0 + ts * d - a;  // the shifted origin, relative to p0
    const double tmin = double(ray.tmin) - ts;
    double best = double(ray.tmax) - ts, v_best = 0.0;
    bool found = false;
    auto sphere = [&](dvec3 c_rel, double r, double v) {
        if (!(r > 0.0)) return;
        double t0, t1;
        if (!solve_from_foot(oa - c_rel, d, r, t0, t1)) return;
        if (t0 > tmin && t0 < best) best = t0, v_best = v, found = true;  // entering root only
    };
    if (s.start_cap) sphere(dvec3(0.0), ra, 0.0);  // else the previous segment's end sphere
    sphere(b - a, rb, 1.0);
    const dvec3 ba = b - a;
    const double L = glm::length(ba);
    if (L > std::abs(ra - rb)) {
        // The lateral surface: rho(z) = A + B z around the axis w, z measured from p0; the sphere of
        // parameter v touches it at z = k ra + v L (1 - k^2), k = (ra - rb) / L.
        const dvec3 w = ba / L;
        const double k = (ra - rb) / L, s2 = 1.0 - k * k, sq = std::sqrt(s2);
        const double A = ra / sq, B = -k / sq;
        const double oz = glm::dot(oa, w), dz = glm::dot(d, w), c0 = A + B * oz;
        const double qa = dd - dz * dz * (1.0 + B * B);
        const double qb = glm::dot(oa, d) - oz * dz - B * dz * c0;  // half the linear coefficient
        const double qc = glm::dot(oa, oa) - oz * oz - c0 * c0;
        double roots[2];
        int n = 0;
        if (std::abs(qa) > 1e-12 * dd) {
            const double disc = qb * qb - qa * qc;
            if (disc >= 0.0) {
                const double q = -(qb + std::copysign(std::sqrt(disc), qb));
                roots[0] = q / qa;
                roots[1] = q != 0.0 ? qc / q : roots[0];
                if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
                n = 2;
            }
        } else if (qb != 0.0) {
            roots[0] = -qc / (2.0 * qb);
            n = 1;
        }
        const double z0 = k * ra, span = L * s2;
        for (int i = 0; i < n; ++i) {
            const double t = roots[i];
            if (!(t > tmin && t < best)) continue;
            const dvec3 p = oa + t * d;
            const double z = glm::dot(p, w);
            if (!(z >= z0 && z <= z0 + span)) continue;
            const double v = (z - z0) / span;
            if (glm::dot(p - v * ba, d) >= 0.0) continue;  // leaving the surface: culled
            best = t, v_best = v, found = true;
            break;
        }
    }
    if (!found) return false;
    t_out = best + ts;
    if (!(t_out > double(ray.tmin) && t_out < double(ray.tmax))) return false;
    const dvec3 c_rel = v_best * ba, p = oa + best * d - c_rel;
    const double l = glm::length(p);
    q_out = l > 0.0 ? c_rel + p * ((ra + v_best * (rb - ra)) / l) : c_rel + p;
    v_out = v_best;
    return true;
}

// The closest valid t of the shape in (tmin, tmax), and its refined local point.
bool find_hit(const AnalyticShape& s, const Ray& ray, double& t, dvec3& local) {
    const double tmin = ray.tmin, tmax = ray.tmax;
    switch (s.kind) {
        case PrimKind::Sphere: {
            dvec3 o = dvec3(ray.o) - dvec3(s.center), d(ray.d);
            double t0, t1;
            if (!solve_from_foot(o, d, s.radius, t0, t1)) return false;
            t = t0 > tmin ? t0 : t1;
            if (!(t > tmin && t < tmax)) return false;
            local = o + t * d;
            double l = glm::length(local);
            if (l > 0.0) local *= double(s.radius) / l;
            return true;
        }
        case PrimKind::Disk: {
            dvec3 o, d;
            to_object(s, ray, o, d);
            if (d.z == 0.0) return false;
            t = -o.z / d.z;
            if (!(t > tmin && t < tmax)) return false;
            double x = o.x + t * d.x, y = o.y + t * d.y;
            if (!(x * x + y * y <= 1.0)) return false;
            local = dvec3(x, y, 0.0);
            return true;
        }
        case PrimKind::Cylinder: {
            dvec3 o, d;
            to_object(s, ray, o, d);
            double t0, t1;
            if (!solve_from_foot(dvec3(o.x, o.y, 0.0), dvec3(d.x, d.y, 0.0), s.radius, t0, t1)) return false;
            for (double tc : {t0, t1}) {
                if (!(tc > tmin && tc < tmax)) continue;
                double z = o.z + tc * d.z;
                if (!(z >= 0.0 && z <= double(s.length))) continue;
                t = tc;
                double x = o.x + tc * d.x, y = o.y + tc * d.y, l = std::sqrt(x * x + y * y);
                if (l > 0.0) {
                    x *= double(s.radius) / l;
                    y *= double(s.radius) / l;
                }
                local = dvec3(x, y, z);
                return true;
            }
            return false;
        }
        case PrimKind::Curve: {
            double v;
            return curve_hit(s, ray, t, local, v);
        }
        case PrimKind::Triangle: break;
    }
    return false;
}

// World normal of the cylinder at an object-space point (to_world is rigid there), flip applied.
vec3 cylinder_normal(const AnalyticShape& s, vec3 local) {
    vec3 n = glm::normalize(glm::mat3(s.to_world) * vec3(local.x, local.y, 0.f));
    return s.flip ? -n : n;
}

// Solid-angle density of area sampling: dist^2 / (area |cos theta at the light|).
float area_pdf_to_solid_angle(float area, vec3 ref_p, vec3 p, vec3 n) {
    vec3 d = p - ref_p;
    float dist2 = glm::dot(d, d);
    float cos_l = std::abs(glm::dot(n, d)) / std::sqrt(dist2);
    if (!(cos_l > 0.f) || !(area > 0.f)) return 0.f;
    return dist2 / (area * cos_l);
}

// 1 - cos(theta_max) of the cone a sphere subtends from a point at squared distance dc2 > r^2,
// without the cancellation of 1 - sqrt(1 - sin^2) for small cones.
double one_minus_cos_max(double r, double dc2) {
    double sin2 = r * r / dc2;
    return sin2 / (1.0 + std::sqrt(std::max(0.0, 1.0 - sin2)));
}

}  // namespace

vec3 transform_point_error(const mat4& m, vec3 p, vec3 pe, vec3* error_out) {
    vec3 out = vec3(m * glm::vec4(p, 1.f));
    if (error_out) {
        vec3 e;
        for (int i = 0; i < 3; ++i) {
            float a = std::abs(m[0][i] * p.x) + std::abs(m[1][i] * p.y) + std::abs(m[2][i] * p.z) + std::abs(m[3][i]);
            float b = std::abs(m[0][i]) * pe.x + std::abs(m[1][i]) * pe.y + std::abs(m[2][i]) * pe.z;
            e[i] = gamma_bound(3) * a + (gamma_bound(3) + 1.f) * b;
        }
        *error_out = e;
    }
    return out;
}

AABB AnalyticShape::bounds() const {
    AABB box;
    switch (kind) {
        case PrimKind::Sphere:
            box = AABB(center - vec3(radius), center + vec3(radius));
            break;
        case PrimKind::Disk: {
            // The ellipse o + a cos + b sin reaches o_i +- sqrt(a_i^2 + b_i^2) along axis i.
            vec3 o = vec3(to_world[3]), a = vec3(to_world[0]), b = vec3(to_world[1]);
            vec3 e = glm::sqrt(a * a + b * b);
            box = AABB(o - e, o + e);
            break;
        }
        case PrimKind::Cylinder: {
            vec3 a = radius * vec3(to_world[0]), b = radius * vec3(to_world[1]);
            vec3 x = glm::sqrt(a * a + b * b);
            vec3 p0 = vec3(to_world[3]), p1 = p0 + length * vec3(to_world[2]);
            box = AABB(glm::min(p0, p1) - x, glm::max(p0, p1) + x);
            break;
        }
        case PrimKind::Curve:
            box = AABB(glm::min(center - vec3(radius), p1 - vec3(radius1)), glm::max(center + vec3(radius), p1 + vec3(radius1)));
            break;
        case PrimKind::Triangle: break;
    }
    // Rounding of the corners must not cut off the surface.
    vec3 pad = gamma_bound(3) * glm::max(abs3(box.min), abs3(box.max));
    return AABB(box.min - pad, box.max + pad);
}

AnalyticShape make_sphere(const mat4& to_world, vec3 center, float radius, bool flip) {
    mat4 m = to_world * glm::translate(mat4(1.f), center) * glm::scale(mat4(1.f), vec3(radius));
    if (!all_finite_matrix(m)) throw Error("the sphere's to_world, center or radius is not finite");
    vec3 a, b, c;
    columns(m, a, b, c);
    float la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    if (!(la > 0.f && lb > 0.f && lc > 0.f) || !(std::abs(glm::determinant(glm::mat3(m))) > 0.f))
        throw Error("the sphere is degenerate (zero radius or a singular to_world)");
    if (std::abs(la - lb) > 1e-4f * la || std::abs(la - lc) > 1e-4f * la)
        throw Error("a sphere's to_world must scale uniformly (Mitsuba 3 does not support it either)");
    if (!nearly_orthogonal(a, b) || !nearly_orthogonal(b, c) || !nearly_orthogonal(a, c))
        throw Error("a sphere's to_world must not shear (Mitsuba 3 does not support it either)");
    AnalyticShape s;
    s.kind = PrimKind::Sphere;
    s.center = vec3(m[3]);
    s.radius = la;  // Mitsuba: |to_world (1, 0, 0)|
    // A mirroring to_world turns the sphere inside out (Mitsuba: a negative polar scale flips).
    s.flip = flip != (glm::determinant(glm::mat3(m)) < 0.f);
    s.to_world = m;
    s.to_object = glm::inverse(glm::dmat4(m));
    s.area = 4.f * kPi * s.radius * s.radius;
    return s;
}

AnalyticShape make_disk(const mat4& to_world, bool flip) {
    if (!all_finite_matrix(to_world)) throw Error("the disk's to_world is not finite");
    vec3 a, b, c;
    columns(to_world, a, b, c);
    glm::mat3 lin(to_world);
    if (!(std::abs(glm::determinant(lin)) > 0.f)) throw Error("the disk's to_world is singular");
    vec3 n = glm::normalize(glm::transpose(glm::inverse(lin)) * vec3(0.f, 0.f, 1.f));
    if (!nearly_orthogonal(a, b) || !nearly_orthogonal(a, n))
        throw Error("a disk's to_world must not shear (Mitsuba 3 refuses it too)");
    AnalyticShape s;
    s.kind = PrimKind::Disk;
    s.flip = flip;
    s.normal = flip ? -n : n;
    s.to_world = to_world;
    s.to_object = glm::inverse(glm::dmat4(to_world));
    s.area = kPi * glm::length(a) * glm::length(b);
    s.center = vec3(to_world[3]);
    return s;
}

AnalyticShape make_cylinder(const mat4& to_world, vec3 p0, vec3 p1, float radius, bool flip) {
    vec3 d = p1 - p0;
    float len = glm::length(d);
    if (!(len > 0.f) || !std::isfinite(len)) throw Error("the cylinder's p0 and p1 must differ");
    Frame f(d / len);
    mat4 frame(1.f);
    frame[0] = glm::vec4(f.s, 0.f);
    frame[1] = glm::vec4(f.t, 0.f);
    frame[2] = glm::vec4(f.n, 0.f);
    mat4 m = to_world * glm::translate(mat4(1.f), p0) * frame * glm::scale(mat4(1.f), vec3(radius, radius, len));
    if (!all_finite_matrix(m)) throw Error("the cylinder's to_world, p0, p1 or radius is not finite");
    vec3 a, b, c;
    columns(m, a, b, c);
    float la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    float det = glm::determinant(glm::mat3(m));
    if (!(la > 0.f && lb > 0.f && lc > 0.f) || !(std::abs(det) > 0.f))
        throw Error("the cylinder is degenerate (zero radius or length, or a singular to_world)");
    if (std::abs(la - lb) > 1e-4f * la)
        throw Error("a cylinder's to_world must scale its cross-section uniformly (Mitsuba 3 does not support it either)");
    if (!nearly_orthogonal(a, b) || !nearly_orthogonal(b, c) || !nearly_orthogonal(a, c))
        throw Error("a cylinder's to_world must not shear (Mitsuba 3 does not support it either)");
    if (det < 0.f) throw Error("a mirroring to_world (negative determinant) on a cylinder is not supported");
    AnalyticShape s;
    s.kind = PrimKind::Cylinder;
    s.flip = flip;
    s.radius = la;
    s.length = lc;
    // The rigid frame: rotation and translation, the scale moved into radius and length.
    mat4 rigid(1.f);
    rigid[0] = glm::vec4(a / la, 0.f);
    rigid[1] = glm::vec4(b / lb, 0.f);
    rigid[2] = glm::vec4(c / lc, 0.f);
    rigid[3] = m[3];
    s.to_world = rigid;
    s.to_object = glm::inverse(glm::dmat4(rigid));
    s.area = 2.f * kPi * s.radius * s.length;
    s.center = vec3(m[3]);
    return s;
}

AnalyticShape make_curve_segment(vec3 p0, float r0, vec3 p1, float r1, uint32_t segment, uint32_t segments,
                                 bool start_cap) {
    if (!all_finite(p0) || !all_finite(p1) || !std::isfinite(r0) || !std::isfinite(r1) || r0 < 0.f || r1 < 0.f)
        throw Error("a curve's control point or radius is not finite, or a radius is negative");
    AnalyticShape s;
    s.kind = PrimKind::Curve;
    s.center = p0;
    s.radius = r0;
    s.p1 = p1;
    s.radius1 = r1;
    s.segment = segment;
    s.segments = segments;
    s.start_cap = start_cap;
    // The lateral area of the cone (slant length times the mean circumference); the caps are shared
    // with the neighbours. Only reported (curves take no emitter).
    const float L = glm::length(p1 - p0);
    s.area = kPi * (r0 + r1) * std::sqrt(std::max(0.f, L * L - (r0 - r1) * (r0 - r1)));
    return s;
}

bool intersect_analytic(const AnalyticShape& s, Ray& ray, Hit& hit) {
    double t, v = 0.0;
    dvec3 local;
    if (s.kind == PrimKind::Curve ? !curve_hit(s, ray, t, local, v) : !find_hit(s, ray, t, local)) return false;
    hit.t = float(t);
    hit.kind = s.kind;
    hit.local = vec3(local);
    hit.b1 = float(v);
    hit.b2 = 0.f;
    ray.tmax = hit.t;
    return true;
}

bool occluded_analytic(const AnalyticShape& s, const Ray& ray) {
    double t;
    dvec3 local;
    return find_hit(s, ray, t, local);
}

SurfaceInteraction analytic_interaction(const AnalyticShape& s, const Hit& hit) {
    SurfaceInteraction si;
    si.prim = hit.prim;
    si.shape = s.shape;
    si.kind = s.kind;
    const vec3 q = hit.local;
    switch (s.kind) {
        case PrimKind::Sphere: {
            si.p = s.center + q;
            si.p_error = sphere_point_error(q, si.p);
            vec3 n = glm::normalize(q);
            si.ng = si.ns = s.flip ? -n : n;
            // Mitsuba: local = to_object(p), theta = acos(z), phi = atan2(y, x) in [0, 2pi).
            dvec3 l = glm::normalize(dmat3(s.to_object) * dvec3(q));
            double theta = std::acos(std::clamp(l.z, -1.0, 1.0));
            si.uv = vec2(float(wrap_phi(l.y, l.x) / (2.0 * 3.14159265358979323846)),
                         float(theta / 3.14159265358979323846));
            // Mitsuba's dp/du = 2 pi r R (-y, x, 0), dp/dv = pi r R (z cos phi, z sin phi, -rd) of
            // the local point, (1, 0, 0) for dp/dv at the poles; R = to_object^T (a rotation).
            const dmat3 R = glm::transpose(dmat3(s.to_object));
            const double rd = std::sqrt(l.x * l.x + l.y * l.y), pi = 3.14159265358979323846;
            si.dpdu = vec3(R * dvec3(-l.y, l.x, 0.0) * (2.0 * pi * s.radius));
            si.dpdv = vec3(R * (rd > 0.0 ? dvec3(l.z * l.x / rd, l.z * l.y / rd, -rd) : dvec3(1.0, 0.0, 0.0)) * (pi * s.radius));
            break;
        }
        case PrimKind::Disk: {
            // z = 0 exactly: the object-space point is on the surface, only the transform rounds.
            si.p = transform_point_error(s.to_world, vec3(q.x, q.y, 0.f), vec3(0.f), &si.p_error);
            si.ng = si.ns = s.normal;
            si.uv = vec2(std::sqrt(q.x * q.x + q.y * q.y),
                         float(wrap_phi(q.y, q.x) / (2.0 * 3.14159265358979323846)));
            {   // Mitsuba's: dp/du = L (cos phi, sin phi, 0), dp/dv = 2 pi r L (-sin phi, cos phi, 0)
                const float r = si.uv.x, c = r > 0.f ? q.x / r : 1.f, sn = r > 0.f ? q.y / r : 0.f;
                const glm::mat3 L(s.to_world);
                si.dpdu = L * vec3(c, sn, 0.f);
                si.dpdv = L * vec3(-sn, c, 0.f) * (2.f * kPi * r);
            }
            break;
        }
        case PrimKind::Cylinder: {
            // pbrt-v4 Cylinder: gamma(3) |(x, y, 0)| for the radial reprojection in object space.
            vec3 pe = gamma_bound(3) * abs3(vec3(q.x, q.y, 0.f));
            si.p = transform_point_error(s.to_world, q, pe, &si.p_error);
            si.ng = si.ns = cylinder_normal(s, q);
            si.uv = vec2(float(wrap_phi(q.y, q.x) / (2.0 * 3.14159265358979323846)), q.z / s.length);
            {   // Mitsuba's: dp/du = 2 pi F (-y, x, 0), dp/dv = F (0, 0, length) in the rigid frame F
                const glm::mat3 F(s.to_world);
                si.dpdu = F * vec3(-q.y, q.x, 0.f) * (2.f * kPi);
                si.dpdv = F * vec3(0.f, 0.f, s.length);
            }
            break;
        }
        case PrimKind::Curve: {
            si.p = s.center + q;
            si.p_error = sphere_point_error(q, si.p);
            const vec3 ba = s.p1 - s.center, c_rel = hit.b1 * ba;
            vec3 n = q - c_rel;
            const float nl = glm::length(n);
            n = nl > 0.f ? n / nl : vec3(0.f, 0.f, 1.f);
            si.ng = si.ns = n;
            // Mitsuba's local_frame: v_rot is +z made orthogonal to the axis ((0, 1, 0) when they are
            // parallel), v_rad = v_rot x axis; u is the angle of n from v_rad towards v_rot.
            const vec3 axis = glm::normalize(ba);
            const vec3 guide(0.f, 0.f, 1.f);
            vec3 v_rot = std::abs(glm::dot(guide, axis)) == 1.f ? vec3(0.f, 1.f, 0.f)
                                                                 : glm::normalize(guide - axis * glm::dot(axis, guide));
            const vec3 v_rad = glm::cross(v_rot, axis);
            si.uv = vec2(float(wrap_phi(glm::dot(v_rot, n), glm::dot(v_rad, n)) / (2.0 * 3.14159265358979323846)),
                         (hit.b1 + float(s.segment)) / float(s.segments));
            // Mitsuba 3.9.1 leaves dp/du and dp/dv of curves zero (measured), so that its shading
            // frame, and with it an anisotropic lobe, is Frame(n); candela does the same. (Its later
            // sources set dp/du = 2 pi axis x (p - c) and the frame from it.)
            si.dpdu = si.dpdv = vec3(0.f);
            break;
        }
        case PrimKind::Triangle: break;
    }
    return si;
}

bool sample_analytic(const AnalyticShape& s, vec3 ref_p, vec2 u, AnalyticSample& out) {
    switch (s.kind) {
        case PrimKind::Sphere: {
            dvec3 dc = dvec3(s.center) - dvec3(ref_p);
            double dc2 = glm::dot(dc, dc), r = s.radius;
            if (dc2 > r * r) {
                // Uniform in the cone: 1 - cos theta = u (1 - cos theta_max), so sin^2 theta =
                // x (2 - x); the point is where that direction first meets the sphere, found by its
                // angle alpha at the centre (Akalin, "Sampling the visible sphere").
                double inv_dc = 1.0 / std::sqrt(dc2);
                double sin_max = r * inv_dc, sin2_max = sin_max * sin_max;
                double omc_max = one_minus_cos_max(r, dc2);
                double x = double(u.x) * omc_max;
                double sin2 = x * (2.0 - x), cos_t = 1.0 - x;
                double cos_a = sin2 / sin_max + cos_t * std::sqrt(std::max(0.0, 1.0 - sin2 / sin2_max));
                double sin_a = std::sqrt(std::max(0.0, 1.0 - cos_a * cos_a));
                double phi = 2.0 * 3.14159265358979323846 * double(u.y);
                Frame f(vec3(-dc * inv_dc));
                vec3 w = glm::normalize(f.to_world(vec3(float(std::cos(phi) * sin_a), float(std::sin(phi) * sin_a),
                                                        float(cos_a))));
                vec3 q = s.radius * w;
                out.p = s.center + q;
                out.p_error = sphere_point_error(q, out.p);
                out.n = s.flip ? -w : w;
                out.pdf = float(1.0 / (2.0 * 3.14159265358979323846 * omc_max));
                return std::isfinite(out.pdf) && out.pdf > 0.f;
            }
            vec3 w = square_to_uniform_sphere(u);
            vec3 q = s.radius * w;
            out.p = s.center + q;
            out.p_error = sphere_point_error(q, out.p);
            out.n = s.flip ? -w : w;
            break;
        }
        case PrimKind::Disk: {
            vec2 d = square_to_uniform_disk_concentric(u);
            out.p = transform_point_error(s.to_world, vec3(d, 0.f), vec3(0.f), &out.p_error);
            out.n = s.normal;
            break;
        }
        case PrimKind::Cylinder: {
            float phi = 2.f * kPi * u.y;
            vec3 q(s.radius * std::cos(phi), s.radius * std::sin(phi), u.x * s.length);
            out.p = transform_point_error(s.to_world, q, gamma_bound(3) * abs3(vec3(q.x, q.y, 0.f)), &out.p_error);
            out.n = cylinder_normal(s, q);
            break;
        }
        case PrimKind::Curve:  // the loader gives curves no emitter
        case PrimKind::Triangle: return false;
    }
    out.pdf = area_pdf_to_solid_angle(s.area, ref_p, out.p, out.n);
    return std::isfinite(out.pdf) && out.pdf > 0.f;
}

float pdf_analytic(const AnalyticShape& s, vec3 ref_p, vec3 p, vec3 n) {
    if (s.kind == PrimKind::Sphere) {
        dvec3 dc = dvec3(s.center) - dvec3(ref_p);
        double dc2 = glm::dot(dc, dc), r = s.radius;
        if (dc2 > r * r) return float(1.0 / (2.0 * 3.14159265358979323846 * one_minus_cos_max(r, dc2)));
    }
    return area_pdf_to_solid_angle(s.area, ref_p, p, n);
}

}  // namespace candela
