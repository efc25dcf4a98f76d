// AABB slab test: hits from outside and inside, misses, axis-parallel rays (zero direction
// components, +-0), rays grazing faces and edges, the [tmin, tmax] interval, and conservativeness
// for rays aimed at the surface.
#include <gtest/gtest.h>
#include "core/aabb.h"
#include "sampling/pcg32.h"

using namespace candela;

namespace {

const AABB kBox(vec3(-1.f), vec3(1.f));

bool hits(const AABB& b, vec3 o, vec3 d, float& t0, float& t1, float tmin = 0.f, float tmax = kInfinity) {
    Ray r;
    r.o = o;
    r.d = d;
    r.tmin = tmin;
    r.tmax = tmax;
    return b.intersect(r, vec3(1.f) / d, t0, t1);
}
bool hits_any(const AABB& b, vec3 o, vec3 d, float tmin = 0.f, float tmax = kInfinity) {
    float t0, t1;
    return hits(b, o, d, t0, t1, tmin, tmax);
}

}  // namespace

TEST(AABB, HitFromOutsideGivesEntryAndExit) {
    float t0, t1;
    ASSERT_TRUE(hits(kBox, vec3(-5.f, 0.2f, 0.3f), vec3(1.f, 0.f, 0.f), t0, t1));
    EXPECT_FLOAT_EQ(t0, 4.f);
    EXPECT_NEAR(t1, 6.f, 6.f * 4 * gamma_bound(3));  // the exit is widened a few ulps on purpose
    EXPECT_GE(t1, 6.f);
    ASSERT_TRUE(hits(kBox, vec3(3.f, 4.f, 5.f), vec3(-1.f, -1.f, -1.f) * 0.5f, t0, t1));
    EXPECT_FLOAT_EQ(t0, 8.f);  // the z slab is entered last
    EXPECT_NEAR(t1, 8.f, 1e-5f);  // and the x slab left first
}

TEST(AABB, OriginInside) {
    float t0, t1;
    ASSERT_TRUE(hits(kBox, vec3(0.1f, -0.2f, 0.3f), vec3(0.f, 0.f, 1.f), t0, t1));
    EXPECT_EQ(t0, 0.f);  // clamped to tmin
    EXPECT_NEAR(t1, 0.7f, 1e-6f);
    EXPECT_TRUE(kBox.contains(vec3(0.1f, -0.2f, 0.3f)));
}

TEST(AABB, Misses) {
    EXPECT_FALSE(hits_any(kBox, vec3(-5.f, 2.f, 0.f), vec3(1.f, 0.f, 0.f)));       // passes beside
    EXPECT_FALSE(hits_any(kBox, vec3(-5.f, 0.f, 0.f), vec3(-1.f, 0.f, 0.f)));      // points away
    EXPECT_FALSE(hits_any(kBox, vec3(-5.f, 0.f, 0.f), vec3(1.f, 1.f, 0.f)));       // diagonal, misses
    EXPECT_FALSE(hits_any(kBox, vec3(-3.f, -3.f, 0.f), vec3(1.f, -0.01f, 0.f)));
}

TEST(AABB, AxisParallelRays) {
    // Zero direction components make 1/d infinite; the slab of that axis either contains the
    // origin (no constraint) or not (miss). Both signs of zero.
    for (float zero : {0.f, -0.f}) {
        EXPECT_TRUE(hits_any(kBox, vec3(-5.f, 0.5f, -0.5f), vec3(1.f, zero, zero)));
        EXPECT_FALSE(hits_any(kBox, vec3(-5.f, 1.5f, -0.5f), vec3(1.f, zero, zero)));
        EXPECT_FALSE(hits_any(kBox, vec3(-5.f, 0.5f, -1.5f), vec3(1.f, zero, zero)));
        EXPECT_TRUE(hits_any(kBox, vec3(0.2f, 0.3f, 9.f), vec3(zero, zero, -1.f)));
        EXPECT_FALSE(hits_any(kBox, vec3(0.2f, 3.f, 9.f), vec3(zero, zero, -1.f)));
    }
}

TEST(AABB, GrazingRaysHit) {
    // Along a face, along an edge, and with the origin exactly on a slab boundary (where
    // (min - o) * inf is 0 * inf = NaN, which must not discard the hit).
    EXPECT_TRUE(hits_any(kBox, vec3(-5.f, 1.f, 0.f), vec3(1.f, 0.f, 0.f)));
    EXPECT_TRUE(hits_any(kBox, vec3(-5.f, -1.f, 0.f), vec3(1.f, 0.f, 0.f)));
    EXPECT_TRUE(hits_any(kBox, vec3(-5.f, 1.f, 1.f), vec3(1.f, 0.f, 0.f)));
    EXPECT_TRUE(hits_any(kBox, vec3(1.f, 0.f, -5.f), vec3(0.f, 0.f, 1.f)));
    // Touching a corner diagonally.
    EXPECT_TRUE(hits_any(kBox, vec3(-2.f, 0.f, 1.f), vec3(1.f, 1.f, 0.f)));
}

TEST(AABB, RespectsTminAndTmax) {
    const vec3 o(-5.f, 0.f, 0.f), d(1.f, 0.f, 0.f);  // inside for t in [4, 6]
    EXPECT_FALSE(hits_any(kBox, o, d, 0.f, 3.9f));
    EXPECT_TRUE(hits_any(kBox, o, d, 0.f, 4.1f));
    EXPECT_FALSE(hits_any(kBox, o, d, 6.1f, kInfinity));
    EXPECT_TRUE(hits_any(kBox, o, d, 5.9f, kInfinity));
    float t0, t1;
    ASSERT_TRUE(hits(kBox, o, d, t0, t1, 4.5f, 5.5f));
    EXPECT_EQ(t0, 4.5f);
    EXPECT_EQ(t1, 5.5f);
}

// Conservative: a ray aimed at any point of the box's surface (or just inside it) is never culled
// by rounding, and its [t0, t1] contains the aimed-at t = 1 (up to the rounding of d).
TEST(AABB, RaysAimedAtTheSurfaceAlwaysHit) {
    PCG32 rng(1u, 1u);
    const AABB box(vec3(-3.f, 0.5f, 100.f), vec3(-1.f, 7.f, 100.5f));
    for (int i = 0; i < 200000; ++i) {
        // Clear of the edges: there the rounded direction may truly pass outside.
        vec3 u(rng.next_float(), rng.next_float(), rng.next_float());
        vec3 p = box.min + (0.01f + 0.98f * u) * box.extent();
        int axis = int(rng.next_u32() % 3);
        p[axis] = (rng.next_u32() & 1) ? box.max[axis] : box.min[axis];  // onto a face
        vec3 o(rng.next_float() * 200.f - 100.f, rng.next_float() * 200.f - 100.f, rng.next_float() * 400.f - 100.f);
        float t0, t1;
        ASSERT_TRUE(hits(box, o, p - o, t0, t1)) << i;
        ASSERT_LE(t0, 1.f + 1e-5f);
        ASSERT_GE(t1, 1.f - 1e-5f);
    }
}
