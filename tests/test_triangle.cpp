// Watertight ray-triangle intersection: hits with their t and barycentrics, misses, edges and
// vertices (exactly, and shared between neighbours), back faces, parallel rays, [tmin, tmax]
// limits, and degenerate triangles.
#include <gtest/gtest.h>
#include "geometry/triangle.h"
#include "sampling/pcg32.h"

using namespace candela;

namespace {

bool hit(const Ray& r, vec3 p0, vec3 p1, vec3 p2, TriangleHit& h) { return intersect_triangle(r, RayShear(r.d), p0, p1, p2, h); }
bool hit(const Ray& r, vec3 p0, vec3 p1, vec3 p2) {
    TriangleHit h;
    return hit(r, p0, p1, p2, h);
}
Ray ray(vec3 o, vec3 d, float tmin = 0.f, float tmax = kInfinity) {
    Ray r;
    r.o = o;
    r.d = d;
    r.tmin = tmin;
    r.tmax = tmax;
    return r;
}
vec3 random_vec(PCG32& rng, float lo, float hi) {
    float a = rng.next_float(), b = rng.next_float(), c = rng.next_float();
    return vec3(lo + (hi - lo) * a, lo + (hi - lo) * b, lo + (hi - lo) * c);
}

const vec3 A(0.f, 0.f, 0.f), B(1.f, 0.f, 0.f), C(0.f, 1.f, 0.f);

}  // namespace

TEST(Triangle, HitReportsDistanceAndBarycentrics) {
    TriangleHit h;
    ASSERT_TRUE(hit(ray(vec3(0.2f, 0.3f, -1.f), vec3(0.f, 0.f, 1.f)), A, B, C, h));
    EXPECT_FLOAT_EQ(h.t, 1.f);
    EXPECT_FLOAT_EQ(h.b1, 0.2f);
    EXPECT_FLOAT_EQ(h.b2, 0.3f);
    // t is in units of d: a direction twice as long halves it.
    ASSERT_TRUE(hit(ray(vec3(0.2f, 0.3f, -1.f), vec3(0.f, 0.f, 2.f)), A, B, C, h));
    EXPECT_FLOAT_EQ(h.t, 0.5f);

    // Random triangles and rays towards random interior points: t and the barycentrics rebuild
    // the aimed-at point.
    PCG32 rng(1u, 2u);
    for (int i = 0; i < 100000; ++i) {
        vec3 p0 = random_vec(rng, -2.f, 2.f), p1 = random_vec(rng, -2.f, 2.f), p2 = random_vec(rng, -2.f, 2.f);
        float u = rng.next_float(), v = rng.next_float();
        if (u + v > 1.f) u = 1.f - u, v = 1.f - v;
        if (u < 1e-3f || v < 1e-3f || u + v > 0.999f) continue;  // stay clear of the edges
        vec3 target = (1.f - u - v) * p0 + u * p1 + v * p2;
        vec3 o = random_vec(rng, -5.f, 5.f), d = target - o;
        vec3 n = glm::cross(p1 - p0, p2 - p0);
        // Skip nearly edge-on views, where the barycentrics are ill-conditioned.
        if (std::abs(glm::dot(glm::normalize(n), glm::normalize(d))) < 0.05f) continue;
        ASSERT_TRUE(hit(ray(o, d), p0, p1, p2, h)) << i;
        EXPECT_NEAR(h.t, 1.f, 1e-4f);
        vec3 p = (1.f - h.b1 - h.b2) * p0 + h.b1 * p1 + h.b2 * p2;
        EXPECT_NEAR(glm::length(p - target), 0.f, 1e-4f) << i;
        EXPECT_NEAR(h.b1, u, 2e-3f);
        EXPECT_NEAR(h.b2, v, 2e-3f);
    }
}

TEST(Triangle, Misses) {
    const vec3 down(0.f, 0.f, -1.f), up(0.f, 0.f, 1.f);
    EXPECT_FALSE(hit(ray(vec3(-0.01f, 0.5f, 1.f), down), A, B, C));
    EXPECT_FALSE(hit(ray(vec3(0.5f, -0.01f, 1.f), down), A, B, C));
    EXPECT_FALSE(hit(ray(vec3(0.51f, 0.51f, 1.f), down), A, B, C));
    EXPECT_FALSE(hit(ray(vec3(0.2f, 0.2f, 1.f), up), A, B, C));  // the triangle is behind the origin
    EXPECT_FALSE(hit(ray(vec3(5.f, 5.f, 1.f), vec3(1.f, 1.f, -0.1f)), A, B, C));
}

TEST(Triangle, EdgesAndVerticesAreHit) {
    const vec3 down(0.f, 0.f, -1.f);
    for (vec3 p : {A, B, C, 0.5f * (A + B), 0.5f * (B + C), 0.5f * (A + C), vec3(0.25f, 0.75f, 0.f)}) {
        TriangleHit h;
        EXPECT_TRUE(hit(ray(p + vec3(0.f, 0.f, 1.f), down), A, B, C, h)) << p.x << "," << p.y;
        EXPECT_FLOAT_EQ(h.t, 1.f);
    }
}

// Watertightness: a ray through a point of a shared edge, or through a vertex shared by a fan of
// triangles, hits at least one of them, whatever its direction (the point of Woop et al.).
TEST(Triangle, SharedEdgesAndVerticesDoNotLeak) {
    PCG32 rng(3u, 4u);
    int rays = 0;
    for (int i = 0; i < 2000; ++i) {
        // A quad (p0, p1, p2, p3) split along the diagonal p0-p2, in a random non-planar-ish pose.
        vec3 p0 = random_vec(rng, -1.f, 1.f), p2 = random_vec(rng, -1.f, 1.f);
        vec3 p1 = random_vec(rng, -1.f, 1.f), p3 = p0 + p2 - p1 + 0.1f * random_vec(rng, -1.f, 1.f);
        for (int k = 0; k < 20; ++k) {
            float s = rng.next_float();
            vec3 on_edge = p0 + s * (p2 - p0);  // rounded: a float point as close to the edge as can be
            vec3 o = random_vec(rng, -4.f, 4.f);
            Ray r = ray(o, on_edge - o);
            if (glm::length(r.d) < 1e-2f) continue;
            // Where the two triangles face the ray with opposite orientations the bent quad folds
            // over in projection, and a ray may truly pass beside both: skip those views.
            float c1 = glm::dot(glm::normalize(glm::cross(p1 - p0, p2 - p0)), glm::normalize(r.d));
            float c2 = glm::dot(glm::normalize(glm::cross(p2 - p0, p3 - p0)), glm::normalize(r.d));
            if (c1 * c2 <= 0.f || std::abs(c1) < 0.05f || std::abs(c2) < 0.05f) continue;
            ++rays;
            EXPECT_TRUE(hit(r, p0, p1, p2) || hit(r, p0, p2, p3)) << "ray slipped between two triangles";
        }
        // A fan of 6 triangles around a shared vertex c (a closed ring, bumped out of plane).
        vec3 c = random_vec(rng, -1.f, 1.f);
        vec3 ring[6];
        for (int j = 0; j < 6; ++j) {
            float a = 2.f * kPi * float(j) / 6.f;
            ring[j] = c + vec3(std::cos(a), std::sin(a), 0.3f * (rng.next_float() - 0.5f));
        }
        // Steep enough (over 55 degrees) that the bumped fan does not fold over in projection.
        vec3 o = c + random_vec(rng, -1.f, 1.f);
        o.z = c.z + (rng.next_float() < 0.5f ? 2.f : -2.f);
        Ray r = ray(o, c - o);
        bool any = false;
        for (int j = 0; j < 6; ++j) any |= hit(r, c, ring[j], ring[(j + 1) % 6]);
        EXPECT_TRUE(any) << "ray through a shared vertex hit no triangle of the fan";
    }
    EXPECT_GT(rays, 30000);
}

TEST(Triangle, BackFacesAreHit) {
    // The test is double-sided: one-sidedness belongs to materials and emitters.
    TriangleHit front, back;
    ASSERT_TRUE(hit(ray(vec3(0.2f, 0.3f, 1.f), vec3(0.f, 0.f, -1.f)), A, B, C, front));
    ASSERT_TRUE(hit(ray(vec3(0.2f, 0.3f, -1.f), vec3(0.f, 0.f, 1.f)), A, B, C, back));
    EXPECT_FLOAT_EQ(front.t, back.t);
    EXPECT_FLOAT_EQ(front.b1, back.b1);
    EXPECT_FLOAT_EQ(front.b2, back.b2);
    // Reversing the winding must not change anything either.
    TriangleHit rev;
    ASSERT_TRUE(hit(ray(vec3(0.2f, 0.3f, 1.f), vec3(0.f, 0.f, -1.f)), A, C, B, rev));
    EXPECT_FLOAT_EQ(rev.b1, front.b2);
    EXPECT_FLOAT_EQ(rev.b2, front.b1);
}

TEST(Triangle, ParallelRaysMiss) {
    // In the triangle's plane (through its interior) and above it.
    TriangleHit h{-1.f, -1.f, -1.f};
    EXPECT_FALSE(hit(ray(vec3(-1.f, 0.2f, 0.f), vec3(1.f, 0.f, 0.f)), A, B, C, h));
    EXPECT_FALSE(hit(ray(vec3(-1.f, -1.f, 0.f), vec3(1.f, 1.f, 0.f)), A, B, C, h));
    EXPECT_FALSE(hit(ray(vec3(-1.f, 0.2f, 0.5f), vec3(1.f, 0.f, 0.f)), A, B, C, h));
    EXPECT_EQ(h.t, -1.f);  // untouched on a miss
    // A tilted triangle and a ray in its plane.
    vec3 p0(0.f, 0.f, 0.f), p1(1.f, 0.f, 1.f), p2(0.f, 1.f, 0.f);
    EXPECT_FALSE(hit(ray(vec3(-1.f, 0.3f, -1.f), vec3(1.f, 0.f, 1.f)), p0, p1, p2));
}

TEST(Triangle, RespectsTminAndTmax) {
    const vec3 o(0.2f, 0.3f, -1.f), d(0.f, 0.f, 1.f);  // hit at t = 1
    EXPECT_TRUE(hit(ray(o, d, 0.f, 1.001f), A, B, C));
    EXPECT_FALSE(hit(ray(o, d, 0.f, 0.999f), A, B, C));
    EXPECT_FALSE(hit(ray(o, d, 0.f, 1.f), A, B, C));  // the interval is open: t < tmax
    EXPECT_TRUE(hit(ray(o, d, 0.999f, kInfinity), A, B, C));
    EXPECT_FALSE(hit(ray(o, d, 1.001f, kInfinity), A, B, C));
    EXPECT_FALSE(hit(ray(o, d, 1.f, kInfinity), A, B, C));  // and t > tmin
    // Negative direction: det changes sign, the comparisons must follow.
    EXPECT_TRUE(hit(ray(vec3(0.2f, 0.3f, 1.f), -d, 0.f, 1.001f), A, B, C));
    EXPECT_FALSE(hit(ray(vec3(0.2f, 0.3f, 1.f), -d, 0.f, 0.999f), A, B, C));
    EXPECT_FALSE(hit(ray(vec3(0.2f, 0.3f, 1.f), -d, 1.001f, kInfinity), A, B, C));
}

// A triangle whose hit is below tmax is hit, even when tmax is only an ulp or two above it: the
// check made before the division must not reject what the exact check after it accepts. Otherwise
// the closest of two hits an ulp apart depends on the order of the tests. The case: a ray in the
// plane of a room's back wall, aimed at the corner where it meets the floor and the left wall;
// the left wall's triangle is hit at 0.99999994, the floor's at 0.99999988.
TEST(Triangle, HitJustBelowTmaxIsKept) {
    const vec3 o(4.3116416931152344f, 2.2160022258758545f, 5.5999999046325684f);
    const vec3 d(-4.3116416931152344f, -2.2160022258758545f, 0.f);
    const vec3 floor0(0.f, 0.f, 0.f), floor1(5.5f, 0.f, 5.6f), floor2(0.f, 0.f, 5.6f);
    const vec3 left0(0.f, 0.f, 0.f), left1(0.f, 0.f, 5.6f), left2(0.f, 5.4f, 5.6f);
    Ray r = ray(o, d, 0.f, kInfinity);
    const RayShear sh(r.d);
    TriangleHit fl, lw;
    ASSERT_TRUE(intersect_triangle(r, sh, floor0, floor1, floor2, fl));
    ASSERT_TRUE(intersect_triangle(r, sh, left0, left1, left2, lw));
    ASSERT_LT(fl.t, lw.t) << "the floor is the closer of the two";
    ASSERT_LT(lw.t - fl.t, 4e-7f) << "and only ulps closer";
    r.tmax = lw.t;  // the left wall tested first
    TriangleHit again;
    ASSERT_TRUE(intersect_triangle(r, sh, floor0, floor1, floor2, again));
    EXPECT_EQ(again.t, fl.t);
    // The widened early check still rejects what is beyond tmax.
    r.tmax = fl.t;
    EXPECT_FALSE(intersect_triangle(r, sh, floor0, floor1, floor2, again));
}

// Zero-area triangles (coincident or collinear vertices) are never hit, whatever the ray, and
// never produce a NaN.
TEST(Triangle, DegenerateTrianglesAreNeverHit) {
    PCG32 rng(5u, 6u);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        vec3 p = random_vec(rng, -1.f, 1.f), q = random_vec(rng, -1.f, 1.f);
        // Collinear with exactly representable coordinates: p, p + k, p + 2k with k a power-of-two
        // multiple, so the middle point is exactly on the segment.
        vec3 k = glm::round((q - p) * 64.f) / 64.f;
        vec3 base = glm::round(p * 64.f) / 64.f;
        const vec3 tris[4][3] = {{base, base, base},
                                 {base, base, base + k},
                                 {base, base + k, base + 2.f * k},
                                 {base + 2.f * k, base, base + k}};
        vec3 target = base + 0.5f * k;  // on the degenerate triangle's "edge"
        vec3 o = random_vec(rng, -3.f, 3.f);
        for (const auto& t : tris) {
            TriangleHit h;
            Ray r = ray(o, target - o);
            if (hit(r, t[0], t[1], t[2], h)) {
                ++hits;
                EXPECT_TRUE(std::isfinite(h.t) && std::isfinite(h.b1) && std::isfinite(h.b2));
            }
            Ray r2 = ray(o, base - o);  // through a vertex
            if (hit(r2, t[0], t[1], t[2], h)) ++hits;
        }
    }
    EXPECT_EQ(hits, 0);
}
