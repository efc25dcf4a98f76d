// Property test: a ray leaving a surface point never hits the triangle it starts on.
//
// The renderer rebuilds hit points from barycentrics (Scene::interaction, with an error bound per
// axis) and offsets ray origins by that bound (offset_ray_origin, pbrt-v4 style); the triangle test
// rejects t inside its own rounding bound. Together they must keep a spawned ray off its own
// triangle in every direction, at every scale and offset. We check it on random triangles (general
// position, tiny, huge, far from the origin, axis-aligned with the plane coordinate exactly 0 or
// 1e5, slivers) and on the Stanford bunny (assets/meshes):
//   * spawn_ray in random directions on both sides of the surface;
//   * spawn_ray_to towards random points (including points on the start triangle's own plane side
//     and on other triangles), where the shadow ray must also not report the target's triangle.
// The start point comes both from random barycentrics and from an actual intersection of a ray
// shot at the triangle, so that the barycentrics carry the intersector's own rounding.
//
// The tests can fail: with the origin offset disabled (raw hit point), the same loops find
// self-hits (checked by SelfIntersection.DetectsMissingOffset).
#include <gtest/gtest.h>
#include <cstdio>
#include <cstdlib>
#include <glm/gtc/matrix_transform.hpp>
#include "geometry/analytic.h"
#include "geometry/triangle.h"
#include "sampling/pcg32.h"
#include "sampling/warp.h"
#include "scene/obj.h"
#include "scene/scene.h"

using namespace candela;

namespace {

vec3 random_dir(PCG32& rng) { return square_to_uniform_sphere(vec2(rng.next_float(), rng.next_float())); }

// True when the ray meets triangle `tri` of the mesh (the one under test only).
bool hits_triangle(const Mesh& mesh, uint32_t tri, const Ray& ray) {
    vec3 p0, p1, p2;
    mesh.vertices(tri, p0, p1, p2);
    TriangleHit th;
    return intersect_triangle(ray, RayShear(ray.d), p0, p1, p2, th);
}

// A scene holding the given triangles as one shape (no emitters, brute-force accelerator).
std::shared_ptr<const Scene> make_scene(const std::vector<vec3>& pos, const std::vector<uvec3>& tris,
                                        const std::string& accel = "brute") {
    auto sc = std::make_unique<SceneDescription>();
    sc->source = "<self-intersection>";
    sc->materials.push_back(Material{"white", DiffuseBsdf{vec3(0.5f)}, false});
    sc->add_shape("mesh", pos, {}, tris, 0, -1);
    sc->settings.width = sc->settings.height = 1;
    return build_scene(std::move(*sc), accel);
}

struct Counts {
    uint64_t rays = 0, self_hits = 0, target_hits = 0, points = 0;
    uint64_t rounding_target_hits = 0;  // of target_hits: the target triangle's own float t error
};

// The ray's t at the plane of triangle (p0, p1, p2), in double from the same float inputs.
double plane_t(const Ray& r, vec3 p0, vec3 p1, vec3 p2) {
    const dvec3 n = glm::cross(dvec3(p1) - dvec3(p0), dvec3(p2) - dvec3(p0));
    return glm::dot(n, dvec3(p0) - dvec3(r.o)) / glm::dot(n, dvec3(r.d));
}

// Random start points on random triangles of the scene; `offset` false spawns from the raw point
// (the control that shows the test can fail).
Counts probe(const Scene& sc, uint64_t seed, int n_points, int dirs_per_point, bool offset = true) {
    PCG32 rng(seed, 1);
    const Mesh& mesh = sc.mesh;
    const uint32_t n_tris = uint32_t(mesh.triangle_count());
    Counts c;
    for (int i = 0; i < n_points; ++i) {
        uint32_t tri = std::min(uint32_t(rng.next_float() * float(n_tris)), n_tris - 1);
        vec3 p0, p1, p2;
        mesh.vertices(tri, p0, p1, p2);
        if (mesh.triangle_area(tri) == 0.f) continue;
        vec2 b = square_to_uniform_triangle(vec2(rng.next_float(), rng.next_float()));
        Hit hit;
        hit.prim = tri;
        hit.b1 = b.x;
        hit.b2 = b.y;
        if (i % 2 == 1) {
            // The same point as the intersector finds it: shoot at it from a random direction.
            vec3 target = (1.f - b.x - b.y) * p0 + b.x * p1 + b.y * p2;
            float ext = max_component(glm::abs(p0 - p1)) + max_component(glm::abs(p2 - p1)) + 1e-30f;
            Ray r;
            vec3 d = random_dir(rng);
            r.o = target - 4.f * ext * d;
            r.d = d;
            TriangleHit th;
            if (!intersect_triangle(r, RayShear(r.d), p0, p1, p2, th)) continue;
            hit.b1 = th.b1;
            hit.b2 = th.b2;
        }
        SurfaceInteraction si = sc.interaction(hit);
        if (!offset) si.p_error = vec3(0.f);
        ++c.points;
        for (int k = 0; k < dirs_per_point; ++k) {
            // Directions from uniform over the sphere plus near-grazing ones (the worst case).
            vec3 w = random_dir(rng);
            if (k % 4 == 3) w = glm::normalize(w - glm::dot(w, si.ng) * si.ng * (1.f - 1e-4f * rng.next_float()));
            if (!all_finite(w)) continue;
            Ray ray = spawn_ray(si, w);
            ++c.rays;
            if (hits_triangle(mesh, tri, ray)) ++c.self_hits;

            // Towards a point on another (random) triangle, as a shadow ray to a light would go.
            uint32_t other = std::min(uint32_t(rng.next_float() * float(n_tris)), n_tris - 1);
            if (other == tri || mesh.triangle_area(other) == 0.f) continue;
            Hit oh;
            oh.prim = other;
            vec2 ob = square_to_uniform_triangle(vec2(rng.next_float(), rng.next_float()));
            oh.b1 = ob.x;
            oh.b2 = ob.y;
            SurfaceInteraction to = sc.interaction(oh);
            if (!offset) to.p_error = vec3(0.f);
            // Points within their rounding error of each other's plane are geometrically
            // ambiguous: offsetting the target by its error bound can move it across the start
            // triangle's plane (the ray must then cross it), which no offset scheme can prevent.
            // Such pairs are skipped; at 1e5 from the origin that is ~0.1 units (measured: about
            // 2% of the pairs of overlapping unit triangles there hit the start triangle).
            const float err = glm::dot(glm::abs(si.ng), si.p_error) + glm::dot(glm::abs(to.ng), to.p_error);
            if (std::abs(glm::dot(to.p - si.p, si.ng)) <= 2.f * err ||
                std::abs(glm::dot(si.p - to.p, to.ng)) <= 2.f * err)
                continue;
            Ray shadow = spawn_ray_to(si, to.p, to.p_error, to.ng);
            ++c.rays;
            if (hits_triangle(mesh, tri, shadow)) ++c.self_hits;
            if (hits_triangle(mesh, other, shadow)) {
                ++c.target_hits;
                // The target triangle reported short of tmax although its plane is crossed at or
                // beyond tmax: the intersector's rounding of t (see SliverShadowRayEndsAtItsTarget).
                vec3 q0, q1, q2;
                mesh.vertices(other, q0, q1, q2);
                if (plane_t(shadow, q0, q1, q2) >= double(shadow.tmax)) ++c.rounding_target_hits;
                if (std::getenv("CANDELA_DEBUG_SELF"))
                    std::printf("target hit: from (%.9g %.9g %.9g) n (%g %g %g) to (%.9g %.9g %.9g) err (%g %g %g) n (%g %g %g)\n",
                                si.p.x, si.p.y, si.p.z, si.ng.x, si.ng.y, si.ng.z, to.p.x, to.p.y, to.p.z, to.p_error.x,
                                to.p_error.y, to.p_error.z, to.ng.x, to.ng.y, to.ng.z);
            }
        }
    }
    return c;
}

// Random triangles of one family, each its own shape in one scene.
std::shared_ptr<const Scene> triangle_family(const char* kind, uint64_t seed, int n) {
    PCG32 rng(seed, 1);
    std::vector<vec3> pos;
    std::vector<uvec3> tris;
    auto u = [&] { return rng.next_float(); };
    for (int i = 0; i < n; ++i) {
        vec3 a, b, c;
        std::string k = kind;
        if (k == "unit") {
            a = vec3(u(), u(), u()); b = vec3(u(), u(), u()); c = vec3(u(), u(), u());
        } else if (k == "tiny") {  // 1e-4 scale, near the origin
            a = 1e-4f * vec3(u(), u(), u()); b = 1e-4f * vec3(u(), u(), u()); c = 1e-4f * vec3(u(), u(), u());
        } else if (k == "huge") {  // 1e5 scale
            a = 1e5f * vec3(u(), u(), u()); b = 1e5f * vec3(u(), u(), u()); c = 1e5f * vec3(u(), u(), u());
        } else if (k == "far") {  // unit size, 1e5 from the origin
            vec3 o(1e5f, -1e5f, 1e5f);
            a = o + vec3(u(), u(), u()); b = o + vec3(u(), u(), u()); c = o + vec3(u(), u(), u());
        } else if (k == "axis0" || k == "axis1e5") {
            // Plane coordinate exactly 0 or exactly 1e5 (an exact coordinate has zero error: the
            // offset is then only the rounding away from the surface).
            int axis = i % 3;
            float plane = k == "axis0" ? 0.f : 1e5f;
            float s = (i / 3) % 2 ? 1.f : 1000.f;
            for (vec3* v : {&a, &b, &c}) {
                *v = s * vec3(u() - 0.5f, u() - 0.5f, u() - 0.5f);
                (*v)[axis] = plane;
            }
        } else {  // "sliver": angles ~1e-6 rad
            a = vec3(u(), u(), u());
            vec3 d = random_dir(rng), e = random_dir(rng);
            b = a + d;
            c = a + 0.5f * d + 1e-6f * glm::normalize(glm::cross(d, e));
        }
        uint32_t base = uint32_t(pos.size());
        pos.insert(pos.end(), {a, b, c});
        tris.push_back(uvec3(base, base + 1, base + 2));
    }
    return make_scene(pos, tris);
}

constexpr const char* kFamilies[] = {"unit", "tiny", "huge", "far", "axis0", "axis1e5", "sliver"};

}  // namespace

TEST(SelfIntersection, RandomTrianglesNeverHitThemselves) {
    uint64_t seed = 1;
    for (const char* fam : kFamilies) {
        auto sc = triangle_family(fam, seed++, 2000);
        Counts c = probe(*sc, 100 + seed, 10000, 16);
        std::printf("  %-8s points %llu rays %llu self-hits %llu target-hits %llu\n", fam,
                    (unsigned long long)c.points, (unsigned long long)c.rays, (unsigned long long)c.self_hits,
                    (unsigned long long)c.target_hits);
        // Half the points come from shooting at the triangle, which misses most slivers.
        EXPECT_GT(c.points, std::string(fam) == "sliver" ? 4500u : 9000u) << fam;
        EXPECT_EQ(c.self_hits, 0u) << fam;
        // No shadow ray may report its target's own triangle, but for the one ray of "axis0" whose
        // target is on a sliver: the ray does not cross the sliver's plane before tmax, the float
        // t of the watertight test is 2.7e-4 short, more than kShadowEpsilon
        // (SelfIntersection.SliverShadowRayEndsAtItsTarget derives it). Exactly that one, with
        // these seeds; any other target hit is a failure.
        EXPECT_EQ(c.target_hits - c.rounding_target_hits, 0u) << fam;
        EXPECT_EQ(c.rounding_target_hits, std::string(fam) == "axis0" ? 1u : 0u) << fam;
    }
}

// The same property on a real mesh, through the whole scene as well: the closest hit of a spawned
// ray is never its own triangle (neighbours sharing an edge may legitimately be hit).
TEST(SelfIntersection, BunnyNeverHitsItself) {
    const std::string path = candela::test_paths::asset("meshes/bunny.obj");
    ObjData obj = read_obj(path, false);
    std::vector<uvec3> tris;
    for (const ObjGroup& g : obj.groups) tris.insert(tris.end(), g.triangles.begin(), g.triangles.end());
    for (float scale : {1.f, 1e-4f, 1e5f}) {
        std::vector<vec3> pos;
        for (const vec3& p : obj.positions) pos.push_back(scale * p + vec3(scale == 1.f ? 1e4f : 0.f));
        auto sc = make_scene(pos, tris, "kdtree");
        Counts c = probe(*sc, 7, 10000, 8);
        EXPECT_EQ(c.self_hits, 0u) << "scale " << scale;
        EXPECT_EQ(c.target_hits, 0u) << "scale " << scale;
        // And through the accelerator.
        PCG32 rng(11, 1);
        uint64_t own = 0;
        for (int i = 0; i < 10000; ++i) {
            Hit h;
            h.prim = std::min(uint32_t(rng.next_float() * float(tris.size())), uint32_t(tris.size() - 1));
            vec2 b = square_to_uniform_triangle(vec2(rng.next_float(), rng.next_float()));
            h.b1 = b.x;
            h.b2 = b.y;
            if (sc->mesh.triangle_area(h.prim) == 0.f) continue;
            SurfaceInteraction si = sc->interaction(h);
            Ray r = spawn_ray(si, random_dir(rng));
            Hit out;
            if (sc->accel->intersect(r, out) && out.prim == h.prim) ++own;
        }
        std::printf("  bunny x%g (+%g): %llu rays, self-hits %llu, target-hits %llu, own closest hits %llu\n",
                    scale, scale == 1.f ? 1e4 : 0.0, (unsigned long long)c.rays, (unsigned long long)c.self_hits,
                    (unsigned long long)c.target_hits, (unsigned long long)own);
        EXPECT_EQ(own, 0u) << "scale " << scale;
    }
}

// The shadow ray of "axis0" that reports its target's triangle: from (0.214, -0.121, 0) on the
// plane z = 0 to a point on a sliver of the plane y = 0 (edges 0.8 long, area 1e-4: its vertices
// are nearly collinear). It is not a self-intersection, and no origin offset could change it:
//   * both ends have zero error along their normals (the plane coordinate of every vertex is
//     exactly 0), so neither is offset, and o.y + d.y = 0.121282294 - 0.121282294 = 0 exactly: in
//     exact arithmetic on the float ray the sliver's plane is crossed at t = 1 > tmax = 1 - 1e-4;
//   * the watertight test shears the sliver along the ray, where its edge functions are
//     differences of products of ~0.06 that cancel to det = -7.4e-5 (a factor ~3000), so float
//     rounding (~1e-8 in each sheared coordinate) moves t by ~1e-4 relative: t = 0.99973;
//   * the test's own error bound says as much: delta_t (pbrt-v4 6.8.7) is 0.1 here, so its t
//     cannot tell 0.99973 from 1. A shadow ray ending on such a sliver can be shadowed by it
//     (once in ~270k rays between random axis-plane triangles; a sliver light is not realistic).
// Not fixed: refining such hits in double (tried) changes which of several triangles hit within
// ulps of a shared vertex is the closest, depending on the order they are met in, so brute force
// and the k-d tree disagree (KdTree.CoherentOriginsMatchBruteForce); doing it right needs the
// float interval tests widened by delta_t in both the scalar and the 4-wide test.
TEST(SelfIntersection, SliverShadowRayEndsAtItsTarget) {
    const vec3 q0(0.491201222f, 0.f, 0.427544057f), q1(0.387188911f, 0.f, 0.395229101f),
        q2(-0.315971136f, 0.f, 0.178404927f);
    Ray r;
    r.o = vec3(0.214067101f, -0.121282294f, 0.f);
    r.d = vec3(-0.27948913f, 0.121282294f, 0.255722135f);
    r.tmax = 1.f - kShadowEpsilon;
    EXPECT_EQ(r.o.y + r.d.y, 0.f);
    EXPECT_EQ(plane_t(r, q0, q1, q2), 1.0);
    TriangleHit th;
    ASSERT_TRUE(intersect_triangle(r, RayShear(r.d), q0, q1, q2, th));
    EXPECT_NEAR(th.t, 0.99973f, 1e-5f);
    // A well-conditioned triangle of the same plane through the same target ends the ray at tmax.
    const vec3 target = r.o + r.d;
    EXPECT_FALSE(intersect_triangle(r, RayShear(r.d), target + vec3(-0.5f, 0.f, -0.5f), target + vec3(0.5f, 0.f, -0.5f),
                                    target + vec3(0.f, 0.f, 0.5f), th));
}

// Control: without the origin offset the same probe finds self-hits, so the tests above can fail.
TEST(SelfIntersection, DetectsMissingOffset) {
    uint64_t total = 0;
    for (const char* fam : {"unit", "far", "huge"}) {
        auto sc = triangle_family(fam, 5, 500);
        total += probe(*sc, 9, 5000, 16, false).self_hits;
    }
    std::printf("  without offsets: %llu self-hits\n", (unsigned long long)total);
    EXPECT_GT(total, 0u);
}

namespace {

mat4 rotation(float deg, vec3 axis) { return glm::rotate(mat4(1.f), glm::radians(deg), glm::normalize(axis)); }
mat4 translation(vec3 t) { return glm::translate(mat4(1.f), t); }
mat4 scaling(vec3 s) { return glm::scale(mat4(1.f), s); }

}  // namespace

// ---- analytic shapes (spheres, disks, cylinders) ---------------------------------------------------
//
// Their hit points are refined onto the surface in double and carry a bound of a few ulps
// (geometry/analytic.h); the same offset_ray_origin must then keep spawned rays off them at any
// scale.

namespace {

// Points found by shooting at each shape; rays spawned from them in random directions (and
// near-grazing ones) must not hit the same shape again within a small fraction of its size of the
// start (a legitimate re-hit, the far side of a sphere, is at least a chord away). Shadow rays
// towards points on another shape must not stop on the start shape or on the target.
struct OffsetCounts {
    uint64_t rays = 0, self_hits = 0, target_hits = 0;
};
OffsetCounts probe_offsets(const std::vector<AnalyticShape>& shapes, float size, uint64_t seed, int n, bool offset = true) {
    OffsetCounts c;
    PCG32 rng(seed, 7);
    for (int i = 0; i < n; ++i) {
        const AnalyticShape& s = shapes[size_t(i) % shapes.size()];
        const AnalyticShape& other = shapes[size_t(i + 1) % shapes.size()];
        AABB b = s.bounds();
        Ray r;
        r.o = b.center() + 3.f * glm::length(b.extent()) * random_dir(rng);
        r.d = b.center() + 0.3f * b.extent() * vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f) - r.o;
        Hit h;
        if (!intersect_analytic(s, r, h)) continue;
        h.prim = 0;
        SurfaceInteraction si = analytic_interaction(s, h);
        if (!offset) si.p_error = vec3(0.f);
        for (int k = 0; k < 8; ++k) {
            vec3 w = random_dir(rng);
            if (k % 4 == 3) w = glm::normalize(w - glm::dot(w, si.ng) * si.ng * (1.f - 1e-4f * rng.next_float()));
            Ray sr = spawn_ray(si, w);
            Hit sh;
            ++c.rays;
            // A legitimate re-hit (a sphere's or cylinder's far side) is at least a chord 2 r |w.n|
            // away; a disk has none.
            float chord = s.kind == PrimKind::Disk ? kInfinity : 2.f * s.radius * std::abs(glm::dot(w, si.ng));
            if (intersect_analytic(s, sr, sh) && sh.t * glm::length(sr.d) < 0.5f * chord) ++c.self_hits;
        }
        AnalyticSample as;
        if (&other != &s && sample_analytic(other, si.p, vec2(rng.next_float(), rng.next_float()), as)) {
            if (std::abs(glm::dot(as.p - si.p, si.ng)) < 1e-3f * size) continue;  // ambiguous side
            // The light set never aims at a point's back (its emission is one-sided); a segment to
            // a cylinder's far side crosses the near side.
            if (glm::dot(as.p - si.p, as.n) >= 0.f) continue;
            Ray shadow = spawn_ray_to(si, as.p, as.p_error, as.n);
            ++c.rays;
            if (occluded_analytic(s, shadow) && glm::dot(as.p - si.p, si.ng) > 0.f) ++c.self_hits;
            if (occluded_analytic(other, shadow)) {
                // The segment may legitimately cross the target shape elsewhere (a cylinder's far
                // side); only a hit at the target point counts.
                Hit th;
                Ray copy = shadow;
                if (intersect_analytic(other, copy, th) && th.t > 0.99f) {
                    ++c.target_hits;
                    if (std::getenv("CANDELA_DEBUG_SELF"))
                        std::printf("target hit: kind %d t %.9g cos_l %g\n", int(other.kind), th.t,
                                    glm::dot(glm::normalize(as.p - si.p), as.n));
                }
            }
        }
    }
    return c;
}

std::vector<AnalyticShape> shapes_at(float scale, vec3 offset) {
    return {make_sphere(translation(offset), vec3(0.f), scale, false),
            make_sphere(translation(offset), vec3(2.5f * scale, 0.f, 0.f), 0.7f * scale, true),
            make_disk(translation(offset + vec3(0, -2.f * scale, 0)) * rotation(30.f, vec3(1, 0, 0)) * scaling(vec3(scale)), false),
            make_cylinder(translation(offset + vec3(0, 2.5f * scale, 0)), vec3(0.f), vec3(0.3f, 0.2f, 1.f) * scale, 0.6f * scale, false)};
}

}  // namespace

TEST(SelfIntersection, AnalyticShapesNeverHitThemselves) {
    struct Case {
        const char* name;
        float scale;
        vec3 offset;
    } cases[] = {{"unit", 1.f, vec3(0.f)},
                 {"1e-4", 1e-4f, vec3(0.f)},
                 {"1e5", 1e5f, vec3(0.f)},
                 {"unit at 1e5", 1.f, vec3(1e5f, -1e5f, 1e5f)},
                 {"1e-4 at 1", 1e-4f, vec3(1.f, 0.5f, -0.7f)}};
    for (const Case& c : cases) {
        OffsetCounts n = probe_offsets(shapes_at(c.scale, c.offset), c.scale, 7, 20000);
        std::printf("  %-12s rays %llu self-hits %llu target-hits %llu\n", c.name, (unsigned long long)n.rays,
                    (unsigned long long)n.self_hits, (unsigned long long)n.target_hits);
        EXPECT_GT(n.rays, 100000u) << c.name;
        EXPECT_EQ(n.self_hits, 0u) << c.name;
        EXPECT_EQ(n.target_hits, 0u) << c.name;
    }
}

TEST(SelfIntersection, AnalyticShapesDetectMissingOffset) {
    OffsetCounts n = probe_offsets(shapes_at(1.f, vec3(1e5f, -1e5f, 1e5f)), 1.f, 7, 5000, false);
    std::printf("  without offsets: %llu self-hits in %llu rays\n", (unsigned long long)n.self_hits,
                (unsigned long long)n.rays);
    EXPECT_GT(n.self_hits, 0u);
}
