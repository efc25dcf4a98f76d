// Degenerate input for every accelerator: zero-area and duplicated triangles, all triangles in one
// plane, an axis-aligned flat mesh, a single triangle, an empty mesh. Each must build, never crash,
// and answer exactly as brute force does. NaN or Inf vertices are rejected when the scene is
// built, with a clear error.
#include <gtest/gtest.h>
#include <string>
#include <vector>
#include "accel/brute.h"
#include "accel/grid.h"
#include "accel/kdtree.h"
#include "core/error.h"
#include "sampling/pcg32.h"
#include "scene/scene.h"

using namespace candela;

namespace {

vec3 rand_vec(PCG32& rng) { return vec3(rng.next_float(), rng.next_float(), rng.next_float()); }

vec3 rand_dir(PCG32& rng) {
    for (;;) {
        vec3 v = 2.f * rand_vec(rng) - 1.f;
        float l2 = glm::dot(v, v);
        if (l2 > 1e-4f && l2 <= 1.f) return v / std::sqrt(l2);
    }
}

void add_tri(Mesh& m, vec3 a, vec3 b, vec3 c) {
    uint32_t base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {a, b, c});
    m.triangles.emplace_back(base, base + 1, base + 2);
    m.tri_shape.push_back(0);
}

std::vector<std::unique_ptr<Accel>> all_accels(const Mesh& m) {
    std::vector<std::unique_ptr<Accel>> v;
    v.push_back(std::make_unique<KdTreeAccel>(m));
    v.push_back(std::make_unique<HybridGridAccel>(m));
    GridOptions fine;
    fine.tris_per_cell = 4.f;
    v.push_back(std::make_unique<HybridGridAccel>(m, fine));
    v.push_back(make_accel("auto", m));
#ifdef CANDELA_HAS_EMBREE
    v.push_back(make_accel("embree", m));  // builds and answers without crashing; not compared
#endif
    return v;
}

// Rays from around the bounds towards it, from inside it, and grazing along each axis through
// vertices (which hit flat meshes edge-on).
std::vector<Ray> rays_around(const Mesh& m, size_t n, uint64_t seed) {
    PCG32 rng(seed, 5);
    AABB b = m.positions.empty() ? AABB(vec3(0.f), vec3(1.f)) : m.bounds();
    vec3 c = b.center();
    float r = std::max(glm::length(b.extent()), 1e-3f);
    std::vector<Ray> rays;
    for (size_t i = 0; i < n; ++i) {
        Ray ray;
        if (i % 3 == 0 && !m.positions.empty()) {
            int a = int(rng.next_u32() % 3);
            ray.o = m.positions[rng.next_u32() % m.positions.size()];
            ray.o[a] -= r;
            ray.d = vec3(0.f);
            ray.d[a] = 1.f;
        } else if (i % 3 == 1) {
            ray.o = b.min + b.extent() * rand_vec(rng);
            ray.d = rand_dir(rng);
        } else {
            ray.o = c + 1.5f * r * rand_dir(rng);
            ray.d = (b.min + b.extent() * rand_vec(rng)) - ray.o;
            if (ray.d == vec3(0.f)) ray.d = vec3(0.f, 0.f, 1.f);
        }
        rays.push_back(ray);
    }
    return rays;
}

// `ulps` > 0 accepts a closest t that many float steps from brute force's. Only for stacks of
// coplanar overlapping triangles: their hit distances differ in the last bits, and which of them
// brute force keeps depends on the order it tests them in (intersect_triangle compares against
// tmax before dividing, so the comparison and the quotient can round differently).
void expect_same_as_brute(const Mesh& m, const std::string& what, size_t nrays = 4000, int ulps = 0) {
    BruteForceAccel brute(m);
    std::vector<Ray> rays = rays_around(m, nrays, 9);
    size_t hits = 0;
    for (const auto& acc : all_accels(m)) {
        const bool compare = acc->name() != "embree";  // Embree's triangle test is its own
        size_t bad = 0;
        for (const Ray& ray : rays) {
            Ray a = ray, b = ray;
            Hit ha, hb;
            bool hit_a = acc->intersect(a, ha), hit_b = brute.intersect(b, hb);
            bool occ = acc->occluded(ray);
            if (!compare) continue;
            hits += hit_b;
            const bool t_ok = ha.t == hb.t || (hit_a && hit_b && std::abs(int64_t(float_to_bits(ha.t)) -
                                                                            int64_t(float_to_bits(hb.t))) <= ulps);
            if (hit_a != hit_b || !t_ok || occ != hit_b) {
                if (bad++ < 3)
                    ADD_FAILURE() << what << " " << acc->name() << ": o=(" << ray.o.x << "," << ray.o.y << "," << ray.o.z
                                  << ") d=(" << ray.d.x << "," << ray.d.y << "," << ray.d.z << "): " << hit_a << " t=" << ha.t
                                  << " prim " << ha.prim << " any " << occ << "; brute force " << hit_b << " t=" << hb.t
                                  << " prim " << hb.prim;
            }
        }
        EXPECT_EQ(bad, 0u) << what << ": " << acc->name() << " differs from brute force";
    }
    if (!m.triangles.empty() && what != "zero-area only") {
        EXPECT_GT(hits, 0u) << what << ": rays should hit";
    }
}

}  // namespace

TEST(AccelDegenerate, EmptyMeshNeverHits) {
    Mesh m;
    for (const auto& acc : all_accels(m)) {
        Ray r;
        r.o = vec3(0.f);
        r.d = vec3(1.f, 0.f, 0.f);
        Hit h;
        EXPECT_FALSE(acc->intersect(r, h)) << acc->name();
        EXPECT_FALSE(acc->occluded(r)) << acc->name();
        EXPECT_EQ(r.tmax, kInfinity) << acc->name();
    }
}

TEST(AccelDegenerate, SingleTriangle) {
    Mesh m;
    add_tri(m, vec3(0.f), vec3(1.f, 0.f, 0.f), vec3(0.f, 1.f, 0.5f));
    expect_same_as_brute(m, "single triangle");
}

TEST(AccelDegenerate, ZeroAreaAndDuplicatedTriangles) {
    PCG32 rng(3, 3);
    Mesh m;
    for (int i = 0; i < 300; ++i) {
        vec3 a = rand_vec(rng), b = rand_vec(rng), c = rand_vec(rng);
        add_tri(m, a, b, c);
        add_tri(m, a, b, c);                    // duplicate
        add_tri(m, a, a, a);                    // a point
        add_tri(m, a, b, 0.5f * (a + b));       // collinear
        add_tri(m, a, b, a);                    // two equal vertices
    }
    expect_same_as_brute(m, "zero-area and duplicated");

    Mesh only;
    for (int i = 0; i < 200; ++i) {
        vec3 a = rand_vec(rng), b = rand_vec(rng);
        add_tri(only, a, a, a);
        add_tri(only, a, b, 0.25f * a + 0.75f * b);
    }
    expect_same_as_brute(only, "zero-area only");
}

TEST(AccelDegenerate, AllTrianglesInOnePlane) {
    // A tilted plane: no axis is flat, but every triangle is coplanar with every other.
    PCG32 rng(4, 4);
    const vec3 u = glm::normalize(vec3(1.f, 0.3f, -0.2f)), v = glm::normalize(glm::cross(u, vec3(0.2f, 1.f, 0.4f)));
    Mesh m;
    for (int i = 0; i < 2000; ++i) {
        vec2 c(rng.next_float(), rng.next_float());
        auto p = [&](vec2 q) { return vec3(0.1f, 0.2f, 0.3f) + q.x * u + q.y * v; };
        float s = 0.02f + 0.05f * rng.next_float();
        add_tri(m, p(c), p(c + s * vec2(rng.next_float(), rng.next_float())), p(c + s * vec2(-rng.next_float(), rng.next_float())));
    }
    expect_same_as_brute(m, "one tilted plane", 4000, 4);
}

TEST(AccelDegenerate, AxisAlignedFlatMesh) {
    // A tessellated square in z = 0.25: the bounds, and every node box, are flat in z.
    Mesh m;
    const int n = 40;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) m.positions.emplace_back(float(i) / n, float(j) / n, 0.25f);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
            m.triangles.emplace_back(a, b, d);
            m.triangles.emplace_back(a, d, c);
        }
    m.tri_shape.assign(m.triangles.size(), 0);
    expect_same_as_brute(m, "axis-aligned flat mesh", 4000, 4);

    // Rays straight down onto shared vertices and edges of the flat mesh all hit (Embree's test is
    // not watertight in this sense and is left out).
    for (const auto& acc : all_accels(m)) {
        if (acc->name() == "embree") continue;
        size_t misses = 0;
        for (int j = 1; j < n; ++j) {
            for (int i = 1; i < n; ++i) {
                for (vec2 off : {vec2(0.f), vec2(0.5f, 0.f), vec2(0.f, 0.5f), vec2(0.5f, 0.5f)}) {
                    Ray r;
                    r.o = vec3((float(i) + off.x) / n, (float(j) + off.y) / n, 1.f);
                    r.d = vec3(0.f, 0.f, -1.f);
                    Hit h;
                    misses += !acc->intersect(r, h);
                }
            }
        }
        EXPECT_EQ(misses, 0u) << acc->name();
    }
}

TEST(AccelDegenerate, NonFiniteVerticesAreRejected) {
    for (float bad : {std::numeric_limits<float>::quiet_NaN(), kInfinity}) {
        SceneDescription scene;
        scene.source = "test";
        scene.add_shape("bad", {vec3(0.f), vec3(1.f, 0.f, 0.f), vec3(0.f, bad, 0.f)}, {}, {uvec3(0, 1, 2)}, 0, -1);
        try {
            build_scene(std::move(scene), "kdtree");
            ADD_FAILURE() << "a vertex with " << bad << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("NaN or infinite"), std::string::npos) << e.what();
        }
    }
}
