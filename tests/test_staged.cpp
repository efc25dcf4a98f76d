// The staged path loop (integrator/path/wavefront.h, work in progress) against the per-path loop:
// the same film bit for bit.
#include <gtest/gtest.h>
#include <cstring>
#include "integrator/path/wavefront.h"
#include "integrator/sampled_pass.h"
#include "render/launch.h"

using namespace candela;

namespace {

// `min_lit`: pixels that must be non-black, so that the comparison is not between black images.
void expect_same_films(const Scene& scene, int w, int h, int spp, int threads, int min_lit, const char* what) {
    Film a(w, h), b(w, h);
    ASSERT_TRUE(staged_pass_applies(scene, b)) << what;
    PassStats pa = render_sampled_pass<PathIntegrator>(scene, a, 0, spp, threads, nullptr);
    PassStats pb = render_tiles_staged(scene, b, 0, spp, threads, nullptr,
                                       make_sampler<IndependentSampler>(sampler_setup(scene, b)));
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
}

}  // namespace

TEST(Staged, SameFilmAsThePerPathLoop) {
    SceneOverrides ov;
    ov.width = 40;  // tiles of 16: partial tiles too
    ov.height = 24;
    std::shared_ptr<const Scene> box = prepare_scene("", ov);  // the built-in Cornell box: all diffuse
    ASSERT_TRUE(scene_is_diffuse_only(*box));
    for (SamplingMode mode : {SamplingMode::Mis, SamplingMode::Light, SamplingMode::Bsdf})
        for (int depth : {-1, 1, 2, 7}) {
            SceneParams p = box->params();
            p.settings.sampling = mode;
            p.settings.max_depth = depth;
            std::shared_ptr<const Scene> s = box->with_params(p);
            const std::string what = "mode " + std::to_string(int(mode)) + " depth " + std::to_string(depth);
            // BSDF sampling alone lights a pixel only through paths that hit the small emitter.
            const int min_lit = mode == SamplingMode::Bsdf ? (depth == -1 || depth == 7 ? 30 : 1) : 40 * 24 / 2;
            expect_same_films(*s, 40, 24, 3, 2, min_lit, what.c_str());
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
