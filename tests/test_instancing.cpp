// shapegroup + instance: the two-level accelerator against the same geometry flattened into world
// space, memory that grows with the instance count, the XML side and its bad input, and a render
// against Mitsuba 3.
#include <gtest/gtest.h>
#include <cstdio>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include "core/error.h"
#include "film/film.h"
#include "film/image_io.h"
#include "render/renderer.h"
#include "sampling/pcg32.h"
#include "scene/scene.h"
#include "support/render.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;  // per test, after Sidak over blocks and channels

float uni(PCG32& r) { return r.next_float(); }

// A group of random triangles and a sphere, shown by `n` random instances (positive determinant,
// rotation, non-uniform scale, translation), and the same thing flattened into world space.
struct Pair {
    std::shared_ptr<const Scene> instanced, flat;
};

Pair make_pair_scenes(int n, uint64_t seed) {
    PCG32 rng(seed, 1);
    std::vector<vec3> pos;
    std::vector<uvec3> tris;
    for (int t = 0; t < 40; ++t) {
        vec3 c(uni(rng) * 2 - 1, uni(rng) * 2 - 1, uni(rng) * 2 - 1);
        for (int k = 0; k < 3; ++k) pos.push_back(c + 0.4f * vec3(uni(rng) - 0.5f, uni(rng) - 0.5f, uni(rng) - 0.5f));
        tris.push_back(uvec3(3 * t, 3 * t + 1, 3 * t + 2));
    }
    std::vector<mat4> xf;
    for (int i = 0; i < n; ++i) {
        mat4 m = glm::translate(mat4(1.f), vec3(uni(rng) * 8 - 4, uni(rng) * 8 - 4, uni(rng) * 8 - 4));
        m = glm::rotate(m, uni(rng) * 6.f, glm::normalize(vec3(uni(rng) - 0.5f, uni(rng) - 0.5f, uni(rng) + 0.1f)));
        m = glm::scale(m, vec3(0.5f + uni(rng), 0.5f + uni(rng), 0.5f + uni(rng)));
        xf.push_back(m);
    }
    auto base = [] {
        SceneDescription d;
        d.source = "test";
        d.materials.push_back(Material{});
        return d;
    };
    SceneDescription a = base();
    uint32_t s = a.add_shape("tris", pos, {}, tris, 0, -1);
    ShapeGroup g;
    g.id = "g";
    g.mesh.positions = pos;
    g.mesh.triangles = tris;
    g.mesh.tri_shape.assign(tris.size(), s);
    a.shapes[s].group = 0;
    a.shapes[s].first_triangle = 0;
    a.mesh = Mesh{};
    a.groups.push_back(g);
    for (const mat4& m : xf) a.instances.push_back(Instance{0, m, glm::inverse(m), AABB()});
    SceneDescription b = base();
    for (const mat4& m : xf) {
        std::vector<vec3> w;
        for (vec3 p : pos) w.push_back(vec3(m * glm::vec4(p, 1.f)));
        b.add_shape("tris", w, {}, tris, 0, -1);
    }
    return {build_scene(std::move(a), "kdtree"), build_scene(std::move(b), "brute")};
}

}  // namespace

TEST(Instancing, HitsAgreeWithFlattenedGeometry) {
    Pair s = make_pair_scenes(60, 7);
    ASSERT_EQ(s.instanced->memory().triangles, 40u);
    ASSERT_EQ(s.flat->memory().triangles, 2400u);
    PCG32 rng(11, 1);
    int hits = 0, mismatched = 0, edge_cases = 0;
    double worst_t = 0, worst_p = 0, worst_n = 0, worst_plane = 0;
    const int kRays = 20000;
    for (int i = 0; i < kRays; ++i) {
        Ray r;
        r.o = vec3(uni(rng) * 16 - 8, uni(rng) * 16 - 8, uni(rng) * 16 - 8);
        r.d = glm::normalize(vec3(uni(rng) - 0.5f, uni(rng) - 0.5f, uni(rng) - 0.5f));
        Ray r2 = r;
        Hit ha, hb;
        bool a = s.instanced->accel->intersect(r, ha), b = s.flat->accel->intersect(r2, hb);
        // A ray through an edge may pick either neighbour (or none) in either space: only those
        // may disagree.
        bool near_edge = b && std::min({hb.b1, hb.b2, 1.f - hb.b1 - hb.b2}) < 1e-4f;
        if (a != b) {
            (near_edge ? edge_cases : mismatched)++;
            continue;
        }
        if (!a) continue;
        ++hits;
        ASSERT_NE(ha.instance, ~0u);
        if (ha.instance * 40 + ha.prim != hb.prim) {
            (near_edge ? edge_cases : mismatched)++;
            continue;
        }
        SurfaceInteraction sa = s.instanced->interaction(ha), sb = s.flat->interaction(hb);
        worst_t = std::max(worst_t, double(std::abs(ha.t - hb.t) / hb.t));
        worst_p = std::max(worst_p, double(glm::length(sa.p - sb.p)));
        worst_n = std::max(worst_n, double(glm::length(sa.ng - sb.ng)));
        // The instanced point lies on the flattened triangle's plane within its error bound carried
        // through the transform (plus the rounding of the flattened vertices themselves, a few ulps
        // of their coordinates). Along the plane the two points differ by the ray's own rounding
        // into group space, which no bound on p covers.
        float plane = std::abs(glm::dot(sa.p - sb.p, sb.ng));
        float bound = glm::dot(glm::abs(sb.ng), sa.p_error + sb.p_error) +
                      4.f * gamma_bound(3) * std::max({std::abs(sb.p.x), std::abs(sb.p.y), std::abs(sb.p.z), 1.f});
        EXPECT_LE(plane, bound);
        worst_plane = std::max(worst_plane, double(plane / bound));
        // Occlusion agrees too.
        Ray sh = r;
        sh.tmax = ha.t * 0.999f;
        Ray sh2 = sh;
        EXPECT_EQ(s.instanced->accel->occluded(sh), s.flat->accel->occluded(sh2));
    }
    std::printf("  %d rays, %d hits, %d mismatches, %d at edges; worst relative t %.2e, |p| %.2e, |ng| %.2e, "
                "off-plane / bound %.3f\n",
                kRays, hits, mismatched, edge_cases, worst_t, worst_p, worst_n, worst_plane);
    EXPECT_GT(hits, 1000);
    EXPECT_EQ(mismatched, 0);
    EXPECT_LE(edge_cases, 5);
    EXPECT_LT(worst_t, 1e-4);
    EXPECT_LT(worst_n, 1e-4);
}

namespace {

std::string write_xml(const std::string& name, const std::string& body) {
    std::string path = std::string(::testing::TempDir()) + "/" + name;
    std::ofstream(path) << "<scene version=\"3.0.0\">\n" << body << "</scene>\n";
    return path;
}

std::string load_error(const std::string& path) {
    try {
        build_scene(load_scene(path));
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(Instancing, MemoryGrowsWithInstancesNotTriangles) {
    const std::string bunny = test_paths::asset("meshes/bunny.obj");
    size_t total[4], tris[4];
    const int counts[4] = {1, 10, 100, 1000};
    for (int c = 0; c < 4; ++c) {
        std::string body = "<shape type=\"shapegroup\" id=\"b\"><shape type=\"obj\"><string name=\"filename\" value=\"" +
                           bunny + "\"/></shape></shape>\n";
        for (int i = 0; i < counts[c]; ++i)
            body += "<shape type=\"instance\"><ref id=\"b\"/><transform name=\"to_world\"><translate x=\"" +
                    std::to_string(i % 32) + "\" z=\"" + std::to_string(i / 32) + "\"/></transform></shape>\n";
        auto s = build_scene(load_scene(write_xml("bunnies" + std::to_string(c) + ".xml", body)));
        Scene::Memory m = s->memory();
        total[c] = m.total();
        tris[c] = m.triangles;
        EXPECT_EQ(m.instances, size_t(counts[c]));
        std::printf("  %4d instances: %zu triangles stored, mesh %zu B, accel %zu B, total %zu B\n", counts[c],
                    m.triangles, m.mesh, m.accel, m.total());
    }
    for (int c = 1; c < 4; ++c) {
        EXPECT_EQ(tris[c], tris[0]);
        // Each further instance costs its record and its share of the top-level BVH: well under
        // 512 bytes (a flattened bunny would add its ~70k triangles each time).
        double per = double(total[c] - total[0]) / double(counts[c] - 1);
        std::printf("  %d instances: %.0f bytes per extra instance\n", counts[c], per);
        EXPECT_LT(per, 512.0);
    }
}

TEST(Instancing, XmlBadInputIsOneLineWithFileAndLine) {
    struct Case {
        const char *name, *xml, *line, *what;
    };
    const Case cases[] = {
        {"unknown.xml", "<shape type=\"instance\">\n<ref id=\"nope\"/>\n</shape>\n", ":3:", "unknown id 'nope'"},
        {"notgroup.xml",
         "<shape type=\"sphere\" id=\"s\"/>\n<shape type=\"instance\">\n<ref id=\"s\"/>\n</shape>\n", ":4:",
         "not a shapegroup"},
        {"empty.xml", "<shape type=\"instance\">\n</shape>\n", ":2:", "needs a shapegroup"},
        {"emitter.xml",
         "<shape type=\"shapegroup\" id=\"g\">\n<shape type=\"sphere\">\n<emitter type=\"area\"/>\n</shape>\n</shape>\n",
         ":3:", "emitters"},
        {"nested.xml",
         "<shape type=\"shapegroup\" id=\"g\">\n<shape type=\"shapegroup\" id=\"h\"/>\n</shape>\n", ":3:",
         "nested ShapeGroup"},
        {"nestedinst.xml",
         "<shape type=\"shapegroup\" id=\"g\"><shape type=\"sphere\"/></shape>\n<shape type=\"shapegroup\" id=\"h\">\n"
         "<shape type=\"instance\"><ref id=\"g\"/></shape>\n</shape>\n",
         ":4:", "nested instancing"},
        {"singular.xml",
         "<shape type=\"shapegroup\" id=\"g\"><shape type=\"sphere\"/></shape>\n<shape type=\"instance\">\n<ref id=\"g\"/>\n"
         "<transform name=\"to_world\"><scale x=\"0\"/></transform>\n</shape>\n",
         ":5:", "singular"},
    };
    for (const Case& c : cases) {
        std::string path = write_xml(c.name, c.xml);
        std::string e = load_error(path);
        std::printf("  %s\n", e.c_str());
        EXPECT_NE(e.find(path + c.line), std::string::npos) << c.name << ": " << e;
        EXPECT_NE(e.find(c.what), std::string::npos) << c.name << ": " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << c.name;
    }
}

// ---- agreement with Mitsuba 3 ----------------------------------------------------------------------
//
// tests/data/scenes/instancing.xml (one shapegroup of a cube and a sphere, four instances: a
// forward reference, rotated and scaled, non-uniformly scaled, mirrored) against the mean of 16
// Mitsuba 3.9.1 llvm_ad_rgb renders of 1024 spp at 32 x 32 and the variance of that mean, made by
//   $PY tests/data/make_reference.py tests/data/scenes/instancing.xml --res 32 --batches 16
//       --spp 1024 --out tests/data/instancing32
// candela renders 8 batches of 128 spp; block z-test on 8 x 8 blocks. Control: the light 5% dimmer
// must fail.

namespace {

ImageEstimate load_reference() { return ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/instancing32"); }

ImageEstimate render(float light_scale) {
    auto built = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/instancing.xml", {{"res", "32"}}));
    EXPECT_EQ(built->instances.size(), 4u);
    SceneParams p = built->params();
    for (AreaEmitter& e : p.emitters) e.radiance *= light_scale;
    return candela::test::render_batch_estimate(*built, p, 8, 128);
}

}  // namespace

TEST(Instancing, MitsubaAgreementRender) {
    ImageEstimate ref = load_reference();
    ASSERT_EQ(ref.width, 32);
    BlockTestResult r = block_z_test(render(1.f), ref, 8, kAlpha);
    std::printf("  blocks: %s\n", r.describe().c_str());
    EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
}

TEST(Instancing, MitsubaAgreementDetectsDimmerLight) {
    ImageEstimate ref = load_reference();
    BlockTestResult r = block_z_test(render(0.95f), ref, 8, kAlpha);
    std::printf("  light 5%% dimmer: blocks %s\n", r.describe().c_str());
    EXPECT_FALSE(r.passed(kAlpha));
}

// Pick reports the instance hit, with the point and normal in world space.
#include "viewer/pick.h"

TEST(Instancing, PickKnowsInstances) {
    auto scene_with = [](float x) {
        std::string body = "<shape type=\"shapegroup\" id=\"g\"><shape type=\"sphere\"/></shape>\n"
                           "<shape type=\"instance\"><ref id=\"g\"/></shape>\n"
                           "<shape type=\"instance\"><ref id=\"g\"/><transform name=\"to_world\"><translate x=\"" +
                           std::to_string(x) + "\"/></transform></shape>\n"
                           "<sensor type=\"perspective\"><transform name=\"to_world\"><lookat origin=\"0, 0, 10\" "
                           "target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>\n";
        return build_scene(load_scene(write_xml("fp" + std::to_string(int(x)) + ".xml", body)));
    };
    auto a = scene_with(3.f);
    Camera cam = a->camera;
    cam.set_film_size(64, 64);
    PickResult centre = pick(*a, cam, vec2(32.f, 32.f));
    ASSERT_TRUE(centre.hit);
    EXPECT_EQ(centre.instance, 0u);
    EXPECT_EQ(centre.kind, PrimKind::Sphere);
    EXPECT_NEAR(centre.position.z, 1.f, 1e-4f);  // the unit sphere's front, in world space
    EXPECT_NEAR(centre.normal.z, 1.f, 1e-4f);
    PickResult corner = pick(*a, cam, vec2(1.f, 1.f));
    EXPECT_FALSE(corner.hit);
}
