// The k-d tree and the hybrid grid against the brute-force oracle: the same closest t, bit for bit
// (the triangle may differ only where t ties), and the same any-hit answer, on random triangle
// soups and on the scanned meshes in assets/meshes, 100k rays in all (fewer on the big meshes,
// where brute force is slow); plus watertightness: rays
// aimed exactly at shared edges and vertices of closed and tessellated meshes always hit.
#include <gtest/gtest.h>
#include <hwy/targets.h>
#include <omp.h>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>
#include "accel/brute.h"
#include "accel/grid.h"
#include "accel/kdtree.h"
#include "geometry/triangle.h"
#include "sampling/pcg32.h"

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
    m.positions.push_back(a);
    m.positions.push_back(b);
    m.positions.push_back(c);
    m.triangles.emplace_back(base, base + 1, base + 2);
    m.tri_shape.push_back(0);
}

// Triangles of random size (long slivers included) in the unit cube.
Mesh random_soup(uint32_t n, uint64_t seed) {
    PCG32 rng(seed, 7);
    Mesh m;
    for (uint32_t i = 0; i < n; ++i) {
        vec3 c = rand_vec(rng);
        float s = 0.01f + 0.2f * rng.next_float() * rng.next_float();
        add_tri(m, c + s * rand_dir(rng), c + s * rand_dir(rng), c + s * rand_dir(rng));
    }
    return m;
}

// "Teapot in a stadium": a dense cluster of tiny triangles inside a few huge ones.
Mesh clustered_soup(uint32_t n, uint64_t seed) {
    PCG32 rng(seed, 11);
    Mesh m;
    for (uint32_t i = 0; i < n; ++i) {
        vec3 c = vec3(0.5f) + 0.01f * rand_vec(rng);
        float s = 0.0005f + 0.002f * rng.next_float();
        add_tri(m, c + s * rand_dir(rng), c + s * rand_dir(rng), c + s * rand_dir(rng));
    }
    for (int i = 0; i < 40; ++i)
        add_tri(m, 100.f * (2.f * rand_vec(rng) - 1.f), 100.f * (2.f * rand_vec(rng) - 1.f),
                100.f * (2.f * rand_vec(rng) - 1.f));
    return m;
}

// Positions and faces only (faces as fans); enough for the scanned meshes.
bool load_obj(const std::string& path, Mesh& m) {
    std::ifstream f(path);
    if (!f) return false;
    std::string line;
    while (std::getline(f, line)) {
        if (line.size() < 2) continue;
        std::istringstream ss(line.substr(2));
        if (line[0] == 'v' && line[1] == ' ') {
            vec3 p;
            ss >> p.x >> p.y >> p.z;
            m.positions.push_back(p);
        } else if (line[0] == 'f' && line[1] == ' ') {
            std::vector<uint32_t> idx;
            std::string tok;
            while (ss >> tok) idx.push_back(uint32_t(std::stoul(tok.substr(0, tok.find('/')))) - 1);
            for (size_t k = 2; k < idx.size(); ++k) {
                m.triangles.emplace_back(idx[0], idx[k - 1], idx[k]);
                m.tri_shape.push_back(0);
            }
        }
    }
    return !m.triangles.empty();
}

// A mix of the rays that break traversals: from outside towards the geometry, from points on
// triangles in any direction (bounce rays), along the axes from origins on split-candidate planes,
// lying in such planes (a zero direction component), and with a [tmin, tmax] window.
// A uniformly random point on a uniformly chosen triangle of m.
vec3 random_surface_point(const Mesh& m, PCG32& rng) {
    const uint32_t t = rng.next_u32() % uint32_t(m.triangles.size());
    vec3 p0, p1, p2;
    m.vertices(t, p0, p1, p2);
    float u = rng.next_float(), v = rng.next_float();
    if (u + v > 1.f) u = 1.f - u, v = 1.f - v;
    return p0 + u * (p1 - p0) + v * (p2 - p0);
}

std::vector<Ray> make_rays(const Mesh& m, size_t n, uint64_t seed) {
    PCG32 rng(seed, 3);
    AABB b = m.bounds();
    vec3 c = b.center(), e = b.extent();
    std::vector<Ray> rays;
    rays.reserve(n);
    auto vertex_coord = [&](int a) { return m.positions[rng.next_u32() % m.positions.size()][a]; };
    auto surface_point = [&]() { return random_surface_point(m, rng); };
    for (size_t i = 0; i < n; ++i) {
        Ray r;
        switch (i % 6) {
            case 0: {  // from outside
                r.o = c + 1.5f * e * (rand_vec(rng) - 0.5f) + 0.6f * glm::length(e) * rand_dir(rng);
                r.d = (b.min + e * rand_vec(rng)) - r.o;
                break;
            }
            case 1:
            case 2: {  // from the surface, any direction
                r.o = surface_point();
                r.d = rand_dir(rng);
                break;
            }
            case 3: {  // along an axis, origin on vertex coordinates
                int a = int(rng.next_u32() % 3);
                r.o = b.min + e * rand_vec(rng);
                r.o[(a + 1) % 3] = vertex_coord((a + 1) % 3);
                r.o[(a + 2) % 3] = vertex_coord((a + 2) % 3);
                r.d = vec3(0.f);
                r.d[a] = rng.next_float() < 0.5f ? -1.f : 1.f;
                break;
            }
            case 4: {  // lying in a candidate plane
                int a = int(rng.next_u32() % 3);
                r.o = surface_point();
                r.o[a] = vertex_coord(a);
                r.d = rand_dir(rng);
                r.d[a] = 0.f;
                break;
            }
            default: {  // a window [tmin, tmax] from inside the bounds
                r.o = b.min + e * rand_vec(rng);
                r.d = rand_dir(rng);
                r.tmin = 0.3f * glm::length(e) * rng.next_float();
                r.tmax = r.tmin + 0.5f * glm::length(e) * rng.next_float();
                break;
            }
        }
        if (r.d == vec3(0.f)) r.d = vec3(0.f, 0.f, 1.f);
        rays.push_back(r);
    }
    return rays;
}

struct Reference {
    std::vector<bool> hit;
    std::vector<float> t;
    std::vector<uint32_t> prim;
};

Reference brute_force(const Mesh& m, const std::vector<Ray>& rays) {
    BruteForceAccel brute(m);
    Reference ref;
    ref.hit.resize(rays.size());
    ref.t.resize(rays.size());
    ref.prim.resize(rays.size());
    std::vector<char> hit(rays.size());
#pragma omp parallel for schedule(dynamic, 64)
    for (int64_t i = 0; i < int64_t(rays.size()); ++i) {
        Ray r = rays[size_t(i)];
        Hit h;
        hit[size_t(i)] = brute.intersect(r, h);
        ref.t[size_t(i)] = h.t;
        ref.prim[size_t(i)] = h.prim;
    }
    for (size_t i = 0; i < rays.size(); ++i) ref.hit[i] = hit[i] != 0;
    return ref;
}

void expect_matches(const Accel& acc, const Mesh& m, const std::vector<Ray>& rays, const Reference& ref,
                    const std::string& what) {
    std::vector<char> bad_closest(rays.size()), bad_any(rays.size());
#pragma omp parallel for schedule(dynamic, 256)
    for (int64_t i = 0; i < int64_t(rays.size()); ++i) {
        const size_t k = size_t(i);
        Ray r = rays[k];
        Hit h;
        bool hit = acc.intersect(r, h);
        bad_closest[k] = hit != ref.hit[k] || (hit && (h.t != ref.t[k] || r.tmax != h.t));
        bad_any[k] = acc.occluded(rays[k]) != ref.hit[k];
    }
    size_t nc = 0, na = 0;
    for (size_t k = 0; k < rays.size(); ++k) {
        if (bad_closest[k] && nc++ < 5) {
            Ray r = rays[k];
            Hit h;
            bool hit = acc.intersect(r, h);
            ADD_FAILURE() << what << " " << acc.name() << ": ray " << k << " o=(" << rays[k].o.x << "," << rays[k].o.y
                          << "," << rays[k].o.z << ") d=(" << rays[k].d.x << "," << rays[k].d.y << "," << rays[k].d.z
                          << ") [" << rays[k].tmin << "," << rays[k].tmax << "]: got " << (hit ? "hit" : "miss")
                          << " t=" << h.t << " prim " << h.prim << ", brute force " << (ref.hit[k] ? "hit" : "miss")
                          << " t=" << ref.t[k] << " prim " << ref.prim[k];
        }
        na += bad_any[k] != 0;
    }
    EXPECT_EQ(nc, 0u) << what << " " << acc.name() << ": closest hits differing from brute force";
    EXPECT_EQ(na, 0u) << what << " " << acc.name() << ": any-hit answers differing from brute force";
    (void)m;
}

// Rays as a path tracer makes them (and neighbouring pixels do): runs of rays from one surface point
// or from points a little apart, in random directions or aimed at the mesh's vertices (which lie on
// split planes, often on several at once), so that they cross leaves through edges and corners.
std::vector<Ray> make_coherent_rays(const Mesh& m, size_t n, uint64_t seed) {
    PCG32 rng(seed, 7);
    const AABB b = m.bounds();
    const float jitter = 1e-3f * glm::length(b.extent());
    std::vector<Ray> rays;
    rays.reserve(n);
    while (rays.size() < n) {
        const vec3 p = random_surface_point(m, rng);
        for (int j = 0; j < 8 && rays.size() < n; ++j) {
            Ray r;
            r.o = j < 4 ? p : p + jitter * (2.f * rand_vec(rng) - 1.f);
            if (j % 2 == 0) {
                r.d = rand_dir(rng);
            } else {
                r.d = m.positions[rng.next_u32() % m.positions.size()] - r.o;
                if (r.d == vec3(0.f)) r.d = rand_dir(rng);
            }
            rays.push_back(r);
        }
    }
    return rays;
}

void check_all(const Mesh& m, size_t nrays, uint64_t seed, const std::string& what) {
    std::vector<Ray> rays = make_rays(m, nrays, seed);
    Reference ref = brute_force(m, rays);
    size_t hits = 0;
    for (bool h : ref.hit) hits += h;
    EXPECT_GT(hits, nrays / 20) << what << ": the ray set should hit something";
    KdTreeAccel kd(m);
    expect_matches(kd, m, rays, ref, what);
    HybridGridAccel grid(m);
    expect_matches(grid, m, rays, ref, what);
    // A fine grid (few triangles per cell) exercises the walk across many cells; on the soups only,
    // where it builds fast.
    if (m.triangles.size() > 20000) return;
    GridOptions fine;
    fine.tris_per_cell = 8.f;
    HybridGridAccel grid_fine(m, fine);
    expect_matches(grid_fine, m, rays, ref, what + " (fine grid)");
}

std::string asset_mesh(const char* name) { return candela::test_paths::asset(std::string("meshes/") + name); }

// Icosahedron subdivided `levels` times with shared vertices: a closed, watertight sphere.
Mesh icosphere(int levels, vec3 center, float radius) {
    const float t = (1.f + std::sqrt(5.f)) / 2.f;
    std::vector<vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    std::vector<uvec3> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                            {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (vec3& p : v) p = glm::normalize(p);
    for (int l = 0; l < levels; ++l) {
        std::vector<uvec3> nf;
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            auto key = std::make_pair(std::min(a, b), std::max(a, b));
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            return mid[key] = uint32_t(v.size() - 1);
        };
        for (const uvec3& tri : f) {
            uint32_t a = midpoint(tri.x, tri.y), b = midpoint(tri.y, tri.z), c = midpoint(tri.z, tri.x);
            nf.insert(nf.end(), {{tri.x, a, c}, {tri.y, b, a}, {tri.z, c, b}, {a, b, c}});
        }
        f = std::move(nf);
    }
    Mesh m;
    for (vec3 p : v) m.positions.push_back(center + radius * p);
    m.triangles = f;
    m.tri_shape.assign(f.size(), 0);
    return m;
}

std::vector<vec3> vertices_and_edge_midpoints(const Mesh& m) {
    std::vector<vec3> targets(m.positions);
    for (const uvec3& t : m.triangles)
        for (int k = 0; k < 3; ++k) targets.push_back(0.5f * (m.positions[t[k]] + m.positions[t[(k + 1) % 3]]));
    return targets;
}

// Rays from `origin` aimed exactly at each target (shared vertices, edge midpoints): each must hit.
void expect_watertight(const Mesh& m, vec3 origin, const std::vector<vec3>& targets, const std::string& what) {    BruteForceAccel brute(m);
    KdTreeAccel kd(m);
    HybridGridAccel grid(m);
    const Accel* accels[] = {&brute, &kd, &grid};
    for (const Accel* acc : accels) {
        size_t misses = 0;
        for (vec3 p : targets) {
            Ray r;
            r.o = origin;
            r.d = p - origin;
            Hit h;
            if (!acc->occluded(r)) ++misses;
            if (!acc->intersect(r, h)) ++misses;
        }
        EXPECT_EQ(misses, 0u) << what << ": " << acc->name() << " let rays through shared edges or vertices";
    }
}

}  // namespace

// The traversal is compiled once per SIMD target and chosen at run time (kdtree_trace.cpp). Each
// target this CPU can run is forced in turn (Highway's test hook) and checked against brute force:
// the 4-lane kernels (SSE4, SSSE3; NEON on aarch64) and the scalar fallback, which this machine's
// dispatch would never pick, run too. Rays include directions with -0 components (inv_d = -inf:
// the box test must take the upper plane as the near one), and a mesh that is one leaf (the root
// box test instead of the node step).
TEST(KdTree, EverySimdTargetMatchesBruteForce) {
    const Mesh soup = random_soup(2000, 5);
    std::vector<Ray> rays = make_rays(soup, 12000, 5);
    for (size_t i = 0, n = rays.size(); i < n; ++i) {
        Ray r = rays[i];
        bool zero = false;
        for (int a = 0; a < 3; ++a)
            if (r.d[a] == 0.f) {
                r.d[a] = -0.f;
                zero = true;
            }
        if (zero) rays.push_back(r);
    }
    ASSERT_GT(rays.size(), 14000u) << "the ray set should have axis-parallel and in-plane rays";
    const Reference ref = brute_force(soup, rays);
    const Mesh small = random_soup(12, 6);  // one leaf
    const std::vector<Ray> small_rays = make_rays(small, 3000, 6);
    const Reference small_ref = brute_force(small, small_rays);
    struct Restore {
        ~Restore() { hwy::SetSupportedTargetsForTest(0); }
    } restore;
    const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
#if defined(__x86_64__)
    EXPECT_GE(targets.size(), 3u) << "x86-64: at least SSSE3, SSE4 and the fallback";
#endif
    for (int64_t target : targets) {
        hwy::SetSupportedTargetsForTest(target);
        const std::string name = hwy::TargetName(target);
        KdTreeAccel kd(soup);
        expect_matches(kd, soup, rays, ref, "random soup, forcing target " + name);
        KdTreeAccel kd_small(small);
        EXPECT_EQ(kd_small.tree().stats().nodes, 1u) << "the small mesh should be one leaf";
        expect_matches(kd_small, small, small_rays, small_ref, "one leaf, forcing target " + name);
    }
}

TEST(KdTree, RandomSoupMatchesBruteForce) { check_all(random_soup(3000, 1), 50000, 1, "random soup"); }

TEST(KdTree, TeapotInStadiumMatchesBruteForce) { check_all(clustered_soup(3000, 2), 40000, 2, "clustered soup"); }

TEST(KdTree, BunnyMatchesBruteForce) {
    Mesh m;
    ASSERT_TRUE(load_obj(asset_mesh("bunny.obj"), m)) << asset_mesh("bunny.obj");
    check_all(m, 6000, 3, "bunny");
}

// Leaves of more than eight triangles are split into groups with boxes of their own, one wide-node
// lane each, where lanes are free. Large leaves (a low triangle cost) make many such splits; the hits
// must still be brute force's, and a tree that is one leaf keeps its single lane.
TEST(KdTree, LeavesSplitIntoLanesMatchBruteForce) {
    Mesh m;
    ASSERT_TRUE(load_obj(asset_mesh("bunny.obj"), m)) << asset_mesh("bunny.obj");
    std::vector<Ray> rays = make_rays(m, 6000, 11);
    Reference ref = brute_force(m, rays);
    for (float ki : {0.02f, 0.1f}) {
        KdBuildOptions opt;
        opt.intersection_cost = ki;
        KdTreeAccel kd(m, opt);
        const KdTreeStats& s = kd.tree().stats();
        EXPECT_GT(s.leaf_lanes, s.leaves - s.empty_leaves + s.leaves / 10) << "KI " << ki << ": few leaves were split";
        expect_matches(kd, m, rays, ref, "bunny, KI " + std::to_string(ki));
    }
    Mesh soup = random_soup(40, 5);
    KdBuildOptions one_leaf;
    // No split pays, not even into lanes (a node step costs 125 blocks): one leaf of 40, one lane.
    one_leaf.intersection_cost = 0.001f;
    KdTreeAccel kd(soup, one_leaf);
    EXPECT_EQ(kd.tree().stats().leaves, 1u);
    EXPECT_EQ(kd.tree().stats().leaf_lanes, 1u);
    std::vector<Ray> soup_rays = make_rays(soup, 4000, 12);
    expect_matches(kd, soup, soup_rays, brute_force(soup, soup_rays), "one-leaf soup");
}

// A room (an open-fronted box of five walls, each two triangles, and two blocks standing on its
// floor: the Cornell box's layout) is small enough for the SAH to make it one leaf. That leaf's
// triangles go into lanes of their own grouped as a BVH would (a flat box per wall), and the hits
// must still be brute force's, for rays from the walls' own surfaces as a path tracer makes them.
TEST(KdTree, OneLeafRoomSplitIntoLanesMatchesBruteForce) {
    Mesh m;
    auto quad = [&](vec3 a, vec3 b, vec3 c, vec3 d) {
        add_tri(m, a, b, c);
        add_tri(m, a, c, d);
    };
    const float W = 5.5f, H = 5.4f, D = 5.6f;
    quad({0, 0, 0}, {W, 0, 0}, {W, 0, D}, {0, 0, D});  // floor
    quad({0, H, 0}, {0, H, D}, {W, H, D}, {W, H, 0});  // ceiling
    quad({0, 0, D}, {W, 0, D}, {W, H, D}, {0, H, D});  // back
    quad({0, 0, 0}, {0, 0, D}, {0, H, D}, {0, H, 0});  // left
    quad({W, 0, 0}, {W, H, 0}, {W, H, D}, {W, 0, D});  // right
    auto block = [&](vec3 lo, vec3 hi) {
        quad({lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z});  // top
        quad({lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z});
        quad({lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z});
        quad({lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {lo.x, lo.y, hi.z});
        quad({hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z});
    };
    block({0.8f, 0.f, 0.7f}, {2.4f, 1.65f, 2.7f});
    block({2.9f, 0.f, 2.5f}, {4.6f, 3.3f, 4.5f});
    KdTreeAccel kd(m);
    const KdTreeStats& s = kd.tree().stats();
    ASSERT_EQ(s.leaves, 1u) << "the room should be one leaf";
    EXPECT_GE(s.leaf_lanes, 6u) << "the walls should have lanes of their own";
    std::vector<Ray> rays = make_coherent_rays(m, 20000, 21);
    std::vector<Ray> more = make_rays(m, 10000, 22);
    rays.insert(rays.end(), more.begin(), more.end());
    expect_matches(kd, m, rays, brute_force(m, rays), "room");
}

TEST(KdTree, DragonMatchesBruteForce) {
    Mesh m;
    ASSERT_TRUE(load_obj(asset_mesh("dragon_100k.obj"), m)) << asset_mesh("dragon_100k.obj");
    check_all(m, 4000, 4, "dragon");
}

TEST(KdTree, CoherentOriginsMatchBruteForce) {
    // Runs of rays from shared origins, many through vertices on split planes, on a soup and on the
    // scanned meshes.
    std::vector<std::pair<std::string, Mesh>> meshes;
    meshes.emplace_back("random soup", random_soup(3000, 5));
    for (const char* name : {"bunny.obj", "dragon_100k.obj"}) {
        Mesh m;
        ASSERT_TRUE(load_obj(asset_mesh(name), m)) << name;
        meshes.emplace_back(name, std::move(m));
    }
    for (const auto& [what, m] : meshes) {
        const std::vector<Ray> rays = make_coherent_rays(m, m.triangles.size() > 20000 ? 2000 : 20000, 11);
        const Reference ref = brute_force(m, rays);
        KdTreeAccel kd(m);
        // Odd rays are aimed at a vertex, where several triangles are hit within an ulp or two of
        // each other: which one is the closest then depends on the order they are met in (a
        // candidate at t shrinks tmax, and the next triangle's interval test is done on scaled
        // distances), for brute force as for the tree. There the tree's hit must be one of those
        // triangles, at its own distance, within 4 ulps of brute force's. Everything else exactly.
        size_t bad = 0, ties = 0;
        for (size_t k = 0; k < rays.size(); ++k) {
            Ray r = rays[k];
            Hit h;
            const bool hit = kd.intersect(r, h);
            bool ok = hit == ref.hit[k] && (!hit || h.t == ref.t[k]);
            if (!ok && k % 2 == 1 && hit && ref.hit[k]) {
                vec3 p0, p1, p2;
                m.vertices(h.prim, p0, p1, p2);
                Ray alone = rays[k];
                TriangleHit th;
                const float ulp = std::nextafter(ref.t[k], kInfinity) - ref.t[k];
                ok = intersect_triangle(alone, RayShear(alone.d), p0, p1, p2, th) && th.t == h.t &&
                     std::abs(h.t - ref.t[k]) <= 4.f * ulp;
                ties += ok;
            }
            ok = ok && kd.occluded(rays[k]) == ref.hit[k];
            if (!ok && bad++ < 5)
                ADD_FAILURE() << what << ": ray " << k << " got " << (hit ? "hit" : "miss") << " t=" << h.t << " prim "
                              << h.prim << ", brute force " << (ref.hit[k] ? "hit" : "miss") << " t=" << ref.t[k]
                              << " prim " << ref.prim[k];
        }
        EXPECT_EQ(bad, 0u) << what << ": coherent rays differing from brute force";
        EXPECT_LT(ties, rays.size() / 10) << what << ": rounding ties at vertices";
        std::printf("%s: %zu coherent rays, %zu vertex ties within 4 ulps\n", what.c_str(), rays.size(), ties);
    }
}

TEST(KdTree, WatertightIcosphere) {
    Mesh m = icosphere(3, vec3(0.1f, -0.2f, 0.3f), 1.7f);
    const std::vector<vec3> targets = vertices_and_edge_midpoints(m);
    expect_watertight(m, vec3(0.1f, -0.2f, 0.3f) + vec3(0.013f, 0.021f, -0.017f), targets, "icosphere from inside");
    expect_watertight(m, vec3(0.1f, -0.2f, 0.3f), targets, "icosphere from its centre");
}

TEST(KdTree, WatertightTessellatedGrid) {
    // A 32 x 32 tessellated square, tilted so that no edge is axis-aligned; rays from above.
    Mesh m;
    const int n = 32;
    auto at = [&](int i, int j) {
        float x = float(i) / n, y = float(j) / n;
        return vec3(x + 0.1f * y, y, 0.3f * x + 0.2f * y + 0.05f * std::sin(9.f * x * y));
    };
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) m.positions.push_back(at(i, j));
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
            m.triangles.emplace_back(a, b, d);
            m.triangles.emplace_back(a, d, c);
        }
    m.tri_shape.assign(m.triangles.size(), 0);
    // Interior vertices and the midpoints of interior edges (rays at the outer boundary may
    // rightly graze off it).
    std::vector<vec3> targets;
    for (int j = 1; j < n; ++j)
        for (int i = 1; i < n; ++i) {
            targets.push_back(at(i, j));
            targets.push_back(0.5f * (at(i, j) + at(i + 1, j)));
            targets.push_back(0.5f * (at(i, j) + at(i, j + 1)));
            targets.push_back(0.5f * (at(i, j) + at(i + 1, j + 1)));
        }
    expect_watertight(m, vec3(0.37f, 0.61f, 3.f), targets, "tessellated grid");
    expect_watertight(m, vec3(-2.f, 0.3f, 0.9f), targets, "tessellated grid, grazing");
}

TEST(KdTree, DefaultAccelIsKdTree) {
    Mesh m = random_soup(10, 5);
    EXPECT_EQ(make_accel("auto", m)->name(), "kdtree");
    EXPECT_EQ(make_accel("kdtree", m)->name(), "kdtree");
    EXPECT_EQ(make_accel("hybrid", m)->name(), "hybrid");
    EXPECT_EQ(make_accel("brute", m)->name(), "brute");
    EXPECT_ANY_THROW(make_accel("octree", m));
}
