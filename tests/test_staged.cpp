// The staged path loop (integrator/path/wavefront.h, work in progress) against the per-path loop:
// the same film bit for bit.
#include <gtest/gtest.h>
#include <cstring>
#include <random>
#include <hwy/targets.h>
#include "integrator/path/hit_soa.h"
#include "integrator/path/wavefront.h"
#include "scene/cornell.h"
#include "scene/loaders.h"
#include "integrator/sampled_pass.h"
#include "render/launch.h"
#include "support/furnace.h"

using namespace candela;

namespace {

// `min_lit`: pixels that must be non-black, so that the comparison is not between black images.
// `weighted`: both films in the weighted layout (the scene's pixel filter splats each sample).
void expect_same_films(const Scene& scene, int w, int h, int spp, int threads, int min_lit, const char* what,
                       bool weighted = false) {
    Film a(w, h), b(w, h);
    if (weighted) a.set_layout(true, 0), b.set_layout(true, 0);
    ASSERT_TRUE(staged_pass_applies(scene, b)) << what;
    PassStats pa = render_sampled_pass<PathIntegrator>(scene, a, 0, spp, threads, nullptr);
    PassStats pb = render_staged_sampled_pass(scene, b, 0, spp, threads, nullptr);
    EXPECT_EQ(pa.rays, pb.rays) << what;
    EXPECT_EQ(pa.samples, pb.samples) << what;
    int lit = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const dvec3 sa = a.pixel_sum(x, y), sb = b.pixel_sum(x, y);
            ASSERT_EQ(std::memcmp(&sa, &sb, sizeof sa), 0) << what << " at " << x << "," << y;
            ASSERT_EQ(a.sample_count(x, y), b.sample_count(x, y));
            lit += sa != dvec3(0.0);
        }
    EXPECT_GE(lit, min_lit) << what << ": the comparison is between lit images";
    ASSERT_EQ(a.weights().size(), b.weights().size());
    EXPECT_EQ(weighted, !a.weights().empty()) << what;
    if (!a.weights().empty()) {  // (memcmp of an empty vector's null data is undefined)
        EXPECT_EQ(std::memcmp(a.weights().data(), b.weights().data(), a.weights().size() * sizeof(double)), 0) << what;
    }
}

}  // namespace

TEST(Staged, SameFilmAsThePerPathLoop) {
    SceneOverrides ov;
    ov.width = 40;  // tiles of 16: partial tiles too
    ov.height = 24;
    std::shared_ptr<const Scene> box = prepare_scene("", ov);  // the built-in Cornell box: all diffuse
    ASSERT_TRUE(scene_is_diffuse_only(*box));
    struct Restore {
        ~Restore() { hwy::SetSupportedTargetsForTest(0); }
    } restore;
    // The SIMD stages on every target this CPU runs (the k-d tree's too).
    for (int64_t target : hwy::SupportedAndGeneratedTargets())
    for (SamplingMode mode : {SamplingMode::Mis, SamplingMode::Light, SamplingMode::Bsdf})
        for (int depth : {-1, 1, 2, 7}) {
            hwy::SetSupportedTargetsForTest(target);
            SceneParams p = box->params();
            p.settings.sampling = mode;
            p.settings.max_depth = depth;
            std::shared_ptr<const Scene> s = box->with_params(p);
            const std::string what = std::string(hwy::TargetName(target)) + " mode " + std::to_string(int(mode)) +
                                     " depth " + std::to_string(depth);
            // BSDF sampling alone lights a pixel only through paths that hit the small emitter.
            const int min_lit = mode == SamplingMode::Bsdf ? (depth == -1 || depth == 7 ? 30 : 1) : 40 * 24 / 2;
            expect_same_films(*s, 40, 24, 3, 2, min_lit, what.c_str());
        }
}

TEST(Staged, WeightedFilmsWithTheScenesFilter) {
    // Gaussian (matpreview's own) and a wide Lanczos: samples splat across tiles, one sample index
    // at a time, on one and two threads.
    auto mp = build_scene(load_scene(candela::test_paths::asset("scenes-public/mdata_matpreview/matpreview.xml")));
    ASSERT_FALSE(mp->settings.filter.is_box());
    expect_same_films(*mp, 40, 24, 3, 2, 40 * 24 / 2, "matpreview, its gaussian filter", true);
    SceneOverrides ov;
    ov.width = 36;
    ov.height = 20;
    std::shared_ptr<const Scene> box = prepare_scene("", ov);
    SceneParams p = box->params();
    p.settings.filter.type = FilterType::Lanczos;
    p.settings.filter.radius = 3.f;
    std::shared_ptr<const Scene> s = box->with_params(p);
    expect_same_films(*s, 36, 20, 2, 1, 36 * 20 / 2, "cornell box, lanczos radius 3, one thread", true);
    expect_same_films(*s, 36, 20, 2, 2, 36 * 20 / 2, "cornell box, lanczos radius 3", true);
}

TEST(Staged, ManySamplesPerPassGoInChunks) {
    // 37 samples per pixel in one pass: batches of at most 4096 paths, 16 samples of a full tile
    // at a time (16 + 16 + 5), each pixel's samples still in index order.
    SceneOverrides ov;
    ov.width = 20;
    ov.height = 18;
    std::shared_ptr<const Scene> box = prepare_scene("", ov);
    expect_same_films(*box, 20, 18, 37, 2, 20 * 18 * 9 / 10, "37 samples per pixel in one pass");
}

TEST(Staged, EverySampler) {
    // Each path's sampler is a copy of the pass's prototype, seeded per pixel sample: the numbers
    // are those of the per-path loop's one sampler per tile, for every sampler type.
    SceneOverrides ov;
    ov.width = 24;
    ov.height = 20;
    std::shared_ptr<const Scene> box = prepare_scene("", ov);
    const SamplerType types[] = {SamplerType::Independent, SamplerType::Stratified, SamplerType::Multijitter,
                                 SamplerType::LdSampler,   SamplerType::Sobol,      SamplerType::ZSobol,
                                 SamplerType::Orthogonal};
    for (SamplerType t : types) {
        SceneParams p = box->params();
        p.settings.sampler.type = t;
        p.settings.spp = 16;
        std::shared_ptr<const Scene> s = box->with_params(p);
        expect_same_films(*s, 24, 20, 4, 2, 24 * 20 / 2, ("sampler " + std::to_string(int(t))).c_str());
    }
}

TEST(Staged, HiddenEmittersAndOneThread) {
    SceneOverrides ov;
    ov.width = 20;
    ov.height = 20;
    std::shared_ptr<const Scene> box = prepare_scene("", ov);
    SceneParams p = box->params();
    p.settings.integrator.hide_emitters = true;
    std::shared_ptr<const Scene> s = box->with_params(p);
    expect_same_films(*s, 20, 20, 2, 1, 20 * 20 / 2, "hide_emitters");
}

TEST(Staged, BackFacesOfOneAndTwoSidedMaterials) {
    // The box's walls and blocks wound the other way (their normals point out of the box): the
    // paths inside see their backs. White and red are two-sided, so shading turns the frame to
    // the path's side; green is one-sided and black from the back.
    SceneDescription d = make_cornell_box();
    d.materials[0].two_sided = d.materials[1].two_sided = true;
    for (size_t t = 0; t < d.mesh.triangles.size(); ++t)
        if (d.shapes[d.mesh.tri_shape[t]].emitter < 0) std::swap(d.mesh.triangles[t].y, d.mesh.triangles[t].z);
    d.settings.width = d.settings.height = 24;
    auto sc = build_scene(std::move(d));
    for (SamplingMode mode : {SamplingMode::Mis, SamplingMode::Light, SamplingMode::Bsdf}) {
        SceneParams p = sc->params();
        p.settings.sampling = mode;
        p.settings.max_depth = -1;
        auto s = sc->with_params(p);
        const int min_lit = mode == SamplingMode::Bsdf ? 10 : 24 * 24 / 2;
        expect_same_films(*s, 24, 24, 3, 2, min_lit, ("back faces, mode " + std::to_string(int(mode))).c_str());
    }
}

TEST(Staged, OtherMaterialsPerPathInTheSameRounds) {
    // Glossy, rough, specular, layered and textured materials (their bounces made per path in the
    // rounds), beside untextured diffuse ones in lanes; lights that are triangles, spheres, a
    // point, an environment map and a constant.
    const std::string src = CANDELA_SOURCE_DIR, pub = candela::test_paths::asset("scenes-public/");
    struct Case {
        std::string file;
        int lit_mis, lit_bsdf;  // pixels that must be lit (-1: mode not tried: a point light only)
    };
    const Case cases[] = {{src + "/scenes/cornell-materials/glossy-glass.xml", 24 * 20 / 2, 5},
                          {src + "/scenes/cornell-materials/mirror-glass.xml", 24 * 20 / 2, 5},
                          {src + "/scenes/cornell-materials/rough.xml", 24 * 20 / 2, 5},
                          {pub + "tutorials_cbox/cbox.xml", 24 * 20 / 2, 5},
                          {pub + "bitterli_veach_mis/scene.xml", 24 * 20 / 2, 5},
                          {pub + "mdata_matpreview/matpreview.xml", 24 * 20 / 2, 24 * 20 / 2},
                          {pub + "mdata_test_orthographic/test_orthographic_path.xml", 24 * 20 / 2, 24 * 20 / 2},
                          {pub + "blender_export_test1/test1.xml", 20, -1}};
    int textured = 0;
    for (const Case& c : cases) {
        auto sc = build_scene(load_scene(c.file));
        bool plain_diffuse_only = true;
        for (const Material& m : sc->materials) {
            plain_diffuse_only = plain_diffuse_only && m.plain() && !m.textured() && std::holds_alternative<DiffuseBsdf>(m.bsdf);
            textured += m.textured();
        }
        EXPECT_FALSE(plain_diffuse_only) << c.file << ": some hits are shaded per path";
        for (SamplingMode mode : {SamplingMode::Mis, SamplingMode::Bsdf}) {
            const int lit = mode == SamplingMode::Mis ? c.lit_mis : c.lit_bsdf;
            if (lit < 0) continue;
            SceneParams p = sc->params();
            p.settings.sampling = mode;
            p.settings.max_depth = 7;
            auto s = sc->with_params(p);
            expect_same_films(*s, 24, 20, 2, 2, lit, (c.file + ", mode " + std::to_string(int(mode))).c_str());
        }
    }
    EXPECT_GE(textured, 2) << "textured materials among the cases";
}

namespace {

// Random hits on the scene's own triangles, reconstructed in lanes, against Scene::interaction.
// Returns how many lanes had a shading normal other than the geometric one.
int expect_same_interactions(const Scene& scene, const std::string& what) {
    const Mesh& mesh = scene.mesh;
    EXPECT_GT(mesh.triangle_count(), 0u);
    std::vector<int32_t> smooth(scene.shapes.size());
    for (size_t s = 0; s < scene.shapes.size(); ++s) smooth[s] = scene.shapes[s].smooth ? 1 : 0;
    const size_t n = 1001, padded = (n + kHitBatchAlign - 1) / kHitBatchAlign * kHitBatchAlign;
    std::vector<uint32_t> prim(padded, 0), shape(padded);
    std::vector<float> b1(padded, 0.f), b2(padded, 0.f);
    std::vector<float> f[12];
    for (auto& v : f) v.assign(padded, 0.f);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (size_t i = 0; i < n; ++i) {
        prim[i] = uint32_t(rng() % mesh.triangle_count());
        float x = u(rng), y = u(rng);
        if (x + y > 1.f) x = 1.f - x, y = 1.f - y;
        b1[i] = x;
        b2[i] = y;
    }
    reconstruct_triangle_hits(mesh, smooth.data(), n, HitBatch{prim.data(), b1.data(), b2.data()},
                              SurfaceBatch{{f[0].data(), f[1].data(), f[2].data()},
                                           {f[3].data(), f[4].data(), f[5].data()},
                                           {f[6].data(), f[7].data(), f[8].data()},
                                           {f[9].data(), f[10].data(), f[11].data()},
                                           shape.data()});
    int curved = 0;
    for (size_t i = 0; i < n; ++i) {
        Hit h;
        h.prim = prim[i];
        h.b1 = b1[i];
        h.b2 = b2[i];
        const SurfaceInteraction si = scene.interaction(h);
        const vec3 got[4] = {vec3(f[0][i], f[1][i], f[2][i]), vec3(f[3][i], f[4][i], f[5][i]),
                             vec3(f[6][i], f[7][i], f[8][i]), vec3(f[9][i], f[10][i], f[11][i])};
        const vec3 want[4] = {si.p, si.p_error, si.ng, si.ns};
        bool same = shape[i] == si.shape;
        for (int k = 0; k < 4; ++k) same = same && std::memcmp(&got[k], &want[k], sizeof(vec3)) == 0;
        if (!same) {
            ADD_FAILURE() << what << ": lane " << i << " differs from Scene::interaction";
            return curved;
        }
        curved += si.ns != si.ng;
    }
    return curved;
}

}  // namespace

TEST(Staged, HitReconstructionInLanesMatchesScene) {
    SceneOverrides ov;
    ov.width = 8;
    ov.height = 8;
    auto box = prepare_scene("", ov);
    // Smooth shading normals: matpreview's meshes.
    auto mp = build_scene(load_scene(candela::test_paths::asset("scenes-public/mdata_matpreview/matpreview.xml")));
    struct Restore {
        ~Restore() { hwy::SetSupportedTargetsForTest(0); }
    } restore;
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        const std::string name = hwy::TargetName(target);
        EXPECT_EQ(expect_same_interactions(*box, "cornell box, " + name), 0);
        EXPECT_GT(expect_same_interactions(*mp, "matpreview, " + name), 500) << "most lanes on smooth shapes";
    }
}

TEST(Staged, AnalyticShapesAndAnInfiniteLight) {
    // No mesh at all (an analytic sphere) and a light that is not an emissive triangle: hits are
    // reconstructed per path and light samples drawn per path, still in the staged rounds.
    auto sc = build_scene(candela::test::sphere_under_sky(0.7f));
    ASSERT_TRUE(sc->mesh.positions.empty());
    expect_same_films(*sc, 16, 16, 3, 2, 16 * 16, "analytic sphere, constant light");
}
