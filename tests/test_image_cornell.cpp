// Image test: candela's built-in Cornell box against a committed Mitsuba 3 reference of the same
// scene (scenes/cornell-box/scene.xml), within Monte Carlo noise.
//
// The reference (tests/data/cornell64_mean.exr, cornell64_var.exr) is the mean of 16 independent
// Mitsuba 3.9.1 llvm_ad_rgb renders of 4096 spp each at 64 x 64, unbounded depth, box filter, and
// the per-pixel variance of that mean from the spread of the 16 batches; tests/data/make_reference.py
// made it:
//   $PY tests/data/make_reference.py scenes/cornell-box/scene.xml --res 64 --batches 16 --spp 4096
//       --out tests/data/cornell64     (one command)
// candela renders 8 batches of 64 spp with different seeds; its variance comes from the batch
// spread too. Two checks: a block z-test (8 x 8 blocks, Sidak-corrected over blocks and channels)
// for local errors, and a whole-image z-test per channel for small global biases that no single
// block can resolve. A control with a 3% darker white albedo must fail, so the test has the power to
// see errors of that size.
#include <gtest/gtest.h>
#include <cstdio>
#include <memory>
#include "film/image_io.h"
#include "render/renderer.h"
#include "scene/cornell.h"
#include "support/render.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr int kRes = 64;
constexpr double kAlpha = 0.01;

ImageEstimate load_reference() { return ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/cornell64"); }

ImageEstimate render_candela(float white_scale) {
    SceneDescription scene = make_cornell_box();
    std::get<DiffuseBsdf>(scene.materials[0].bsdf).albedo *= white_scale;
    scene.settings.width = kRes;
    scene.settings.height = kRes;
    const std::shared_ptr<const Scene> built = build_scene(scene);
    return candela::test::render_batch_estimate(*built, built->params(), 8, 64);
}

}  // namespace

TEST(ImageCornell, BuiltinBoxMatchesMitsubaReference) {
    ImageEstimate ref = load_reference();
    ASSERT_EQ(ref.width, kRes);
    ImageEstimate test = render_candela(1.f);
    BlockTestResult r = block_z_test(test, ref, 8, kAlpha);
    dvec3 rel;
    double p_global = whole_image_p(test, ref, &rel);
    std::printf("  blocks: %s\n  whole image: p = %.3g, relative difference (%.4f, %.4f, %.4f)\n",
                r.describe().c_str(), p_global, rel.x, rel.y, rel.z);
    EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
    EXPECT_GE(p_global, kAlpha);
}

TEST(ImageCornell, DetectsThreePercentAlbedoError) {
    ImageEstimate ref = load_reference();
    ImageEstimate test = render_candela(0.97f);
    BlockTestResult r = block_z_test(test, ref, 8, kAlpha);
    double p_global = whole_image_p(test, ref, nullptr);
    std::printf("  3%% darker white: blocks %s, whole image p = %.3g\n", r.describe().c_str(), p_global);
    EXPECT_TRUE(!r.passed(kAlpha) || p_global < kAlpha);
    EXPECT_LT(p_global, kAlpha);
}
