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

// Every sampler against the same reference. zsobol correlates neighbouring pixels on purpose (blue
// noise: the samples of an aligned quad of pixels form one net), so the per-pixel variances cannot
// be summed over a block as block_z_test does. Here instead each of K = 8 renders with its own
// seed (an independent randomisation of every sampler) gives one estimate per 16 x 16 block, aligned
// with the Z-order quads so that the correlation stays inside a block; the block means' spread over
// the K renders is their standard error, whatever the correlation inside, and a t-test (K - 1
// degrees of freedom; the reference's own variance added) per block and channel, Sidak-corrected,
// plus one on the whole image. 16 spp per render (a complete stratified set for every sampler;
// orthogonal 25, its p^2).
// Control: a 3% darker white albedo is rejected with the sobol, zsobol and orthogonal samplers
// (measured whole-image p = 5e-7, 2e-6 and 3e-7, blocks p = 1e-7, 2e-7 and 5e-8).
namespace {

struct SamplerTest {
    double p_family = 1, p_whole = 1;
};

SamplerTest sampler_test(SamplerType type, float white_scale, const ImageEstimate& ref) {
    constexpr int kK = 8, kBlock = 16, kNb = kRes / kBlock;
    const int kSpp = int(sampler_sample_count(type, 16));  // orthogonal: 25
    SceneDescription scene = make_cornell_box();
    std::get<DiffuseBsdf>(scene.materials[0].bsdf).albedo *= white_scale;
    scene.settings.width = scene.settings.height = kRes;
    scene.settings.sampler.type = type;
    scene.settings.spp = kSpp;
    const std::shared_ptr<const Scene> built = build_scene(scene);
    SceneParams p = built->params();
    std::vector<RunningStats> blocks(size_t(kNb * kNb * 3)), whole(3);
    for (int b = 0; b < kK; ++b) {
        p.settings.seed = uint64_t(b + 1);
        Film film(kRes, kRes);
        Renderer::render_pass(*built->with_params(p), film, 0, kSpp, 0);
        std::vector<dvec3> m(size_t(kNb * kNb), dvec3(0.0));
        for (int y = 0; y < kRes; ++y)
            for (int x = 0; x < kRes; ++x) m[size_t((y / kBlock) * kNb + x / kBlock)] += dvec3(film.pixel(x, y));
        dvec3 all(0.0);
        for (size_t i = 0; i < m.size(); ++i) {
            all += m[i];
            for (int k = 0; k < 3; ++k) blocks[i * 3 + size_t(k)].add(m[i][k] / double(kBlock * kBlock));
        }
        for (int k = 0; k < 3; ++k) whole[size_t(k)].add(all[k] / double(kRes * kRes));
    }
    std::vector<dvec3> rm(size_t(kNb * kNb), dvec3(0.0)), rv(size_t(kNb * kNb), dvec3(0.0));
    dvec3 ra(0.0), rav(0.0);
    for (int y = 0; y < kRes; ++y)
        for (int x = 0; x < kRes; ++x) {
            const size_t i = size_t(y * kRes + x), j = size_t((y / kBlock) * kNb + x / kBlock);
            rm[j] += ref.mean[i] / double(kBlock * kBlock);
            rv[j] += ref.var_of_mean[i] / double(kBlock * kBlock * kBlock * kBlock);
            ra += ref.mean[i] / double(kRes * kRes);
            rav += ref.var_of_mean[i] / (double(kRes * kRes) * double(kRes * kRes));
        }
    SamplerTest r;
    double p_min = 1;
    int tests = 0;
    for (size_t j = 0; j < rm.size(); ++j)
        for (int k = 0; k < 3; ++k) {
            const RunningStats& s = blocks[j * 3 + size_t(k)];
            const double se = std::sqrt(s.std_error() * s.std_error() + rv[j][k]);
            if (!(se > 0)) continue;
            p_min = std::min(p_min, student_t_two_sided_p((s.mean() - rm[j][k]) / se, kK - 1));
            ++tests;
        }
    r.p_family = sidak_adjust(p_min, tests);
    double pw = 1;
    for (int k = 0; k < 3; ++k) {
        const double se = std::sqrt(whole[size_t(k)].std_error() * whole[size_t(k)].std_error() + rav[k]);
        pw = std::min(pw, student_t_two_sided_p((whole[size_t(k)].mean() - ra[k]) / se, kK - 1));
    }
    r.p_whole = sidak_adjust(pw, 3);
    return r;
}

}  // namespace

TEST(ImageCornell, EverySamplerMatchesMitsubaReference) {
    const ImageEstimate ref = load_reference();
    // Sidak over the samplers too.
    const double level = sidak_level(kAlpha, kSamplerTypeCount);
    for (int t = 0; t < kSamplerTypeCount; ++t) {
        const SamplerTest r = sampler_test(SamplerType(t), 1.f, ref);
        std::printf("  %-12s blocks p_family = %.3g, whole image p = %.3g\n", sampler_type_name(SamplerType(t)), r.p_family,
                    r.p_whole);
        EXPECT_GE(r.p_family, level) << sampler_type_name(SamplerType(t));
        EXPECT_GE(r.p_whole, level) << sampler_type_name(SamplerType(t));
    }
}

TEST(ImageCornell, SamplerTestDetectsThreePercentAlbedoError) {
    const ImageEstimate ref = load_reference();
    for (SamplerType t : {SamplerType::Sobol, SamplerType::ZSobol, SamplerType::Orthogonal}) {
        const SamplerTest r = sampler_test(t, 0.97f, ref);
        std::printf("  3%% darker white, %s: blocks p_family = %.3g, whole image p = %.3g\n", sampler_type_name(t), r.p_family,
                    r.p_whole);
        EXPECT_LT(r.p_whole, kAlpha) << sampler_type_name(t);
    }
}
