// Film accumulation (double sums, non-finite samples, counts) and the image block z-test of
// tests/support/stats.h that image regression tests use against a committed reference.
#include <gtest/gtest.h>
#include "film/film.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

TEST(Film, MillionEqualSamplesAverageExactly) {
    Film film(2, 1);
    const float v = 0.1f;  // not a dyadic fraction: every float addition would round
    for (int i = 0; i < 1000000; ++i) film.add_sample(ivec2(0, 0), vec3(v, 3.f * v, 7.f * v));
    EXPECT_EQ(film.sample_count(0, 0), 1000000u);
    vec3 m = film.pixel(0, 0);
    EXPECT_EQ(m.x, v);
    EXPECT_EQ(m.y, 3.f * v);
    EXPECT_EQ(m.z, 7.f * v);
    // The test has teeth: a float accumulator is already off by far more than an ulp.
    float fsum = 0.f;
    for (int i = 0; i < 1000000; ++i) fsum += v;
    EXPECT_GT(std::abs(fsum / 1e6f - v), 1e-4f);
    // Widely different magnitudes: 1e-3 and 1e3 alternating average to 500.0005.
    for (int i = 0; i < 1000000; ++i) film.add_sample(ivec2(1, 0), vec3(i % 2 ? 1e3f : 1e-3f));
    EXPECT_FLOAT_EQ(film.pixel(1, 0).x, float(0.5 * (double(1e3f) + double(1e-3f))));
}

TEST(Film, NonFiniteSamplesAreCountedNotSummed) {
    Film film(3, 2);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = kInfinity;
    film.add_sample(ivec2(1, 1), vec3(2.f));
    film.add_sample(ivec2(1, 1), vec3(nan, 0.f, 0.f));
    film.add_sample(ivec2(1, 1), vec3(0.f, inf, 0.f));
    film.add_sample(ivec2(1, 1), vec3(0.f, 0.f, -inf));
    film.add_sample(ivec2(1, 1), vec3(4.f));
    EXPECT_EQ(film.nonfinite_count(), 3u);
    // They count as samples of zero radiance (the sample was taken), so the mean is 6 / 5.
    EXPECT_EQ(film.sample_count(1, 1), 5u);
    EXPECT_EQ(film.pixel_sum(1, 1), dvec3(6.0));
    EXPECT_TRUE(all_finite(film.pixel(1, 1)));
    EXPECT_FLOAT_EQ(film.pixel(1, 1).x, 1.2f);
    // Splats too; a splat outside the film is dropped.
    film.add_splat(vec2(0.5f, 0.5f), vec3(nan));
    film.add_splat(vec2(-1.f, 0.5f), vec3(1.f));
    film.add_splat(vec2(3.5f, 0.5f), vec3(1.f));
    EXPECT_EQ(film.nonfinite_count(), 4u);
    for (float x : film.resolve()) EXPECT_TRUE(std::isfinite(x));
}

TEST(Film, SampleCounts) {
    Film film(4, 3);
    EXPECT_EQ(film.total_samples(), 0u);
    EXPECT_EQ(film.pixel(2, 2), vec3(0.f));  // no samples: black, not NaN
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x)
            for (int s = 0; s <= x + y; ++s) film.add_sample(ivec2(x, y), vec3(float(x), float(y), 1.f));
    uint64_t total = 0;
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x) {
            EXPECT_EQ(film.sample_count(x, y), uint32_t(x + y + 1));
            EXPECT_EQ(film.pixel(x, y), vec3(float(x), float(y), 1.f));
            total += uint64_t(x + y + 1);
        }
    EXPECT_EQ(film.total_samples(), total);
    std::vector<float> rgb = film.resolve();
    ASSERT_EQ(rgb.size(), 4u * 3u * 3u);
    EXPECT_EQ(rgb[(1 * 4 + 3) * 3 + 0], 3.f);  // row-major from the top-left
    EXPECT_EQ(rgb[(1 * 4 + 3) * 3 + 1], 1.f);
    film.clear();
    EXPECT_EQ(film.total_samples(), 0u);
    EXPECT_EQ(film.nonfinite_count(), 0u);
}

// ---- block z-test ------------------------------------------------------------------------------

namespace {

// A synthetic "rendering": pixel (x, y) has mean m(x, y) and exponentially distributed samples (a
// skewed, path-tracer-like noise). `bias` scales the mean inside the rectangle [bx0, bx1) x [by0, by1).
struct Synthetic {
    int w = 64, h = 48;
    double bias = 1.0;
    int bx0 = 0, by0 = 0, bx1 = 0, by1 = 0;
    vec3 mean(int x, int y) const {
        float m = 1.f + 0.5f * std::sin(0.2f * float(x)) * std::cos(0.15f * float(y));
        vec3 c(m, 0.5f * m, 2.f * m);
        if (x >= bx0 && x < bx1 && y >= by0 && y < by1) c *= float(bias);
        return c;
    }
    void render(Film& film, int spp, uint64_t seed) const {
        film.resize(w, h);
        PCG32 rng(seed, 77u);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int s = 0; s < spp; ++s) {
                    float e = -std::log(1.f - rng.next_float());  // Exp(1)
                    film.add_sample(ivec2(x, y), mean(x, y) * e);
                }
    }
    // K films of spp samples each, as an ImageEstimate by batch means.
    ImageEstimate estimate(int batches, int spp, uint64_t seed) const {
        std::vector<Film> films(static_cast<size_t>(batches));
        std::vector<const Film*> ptrs;
        for (int k = 0; k < batches; ++k) {
            render(films[size_t(k)], spp, seed * 1000 + uint64_t(k));
            ptrs.push_back(&films[size_t(k)]);
        }
        return ImageEstimate::from_batches(ptrs);
    }
};

constexpr double kAlpha = 0.01;

}  // namespace

TEST(BlockZTest, AgreesOnTheSameImageAndIsCalibrated) {
    Synthetic s;
    // 20 independent pairs: under the null the family-wise p is uniform, so about 20% of the pairs
    // fall below 0.2 (binomial: 4 +- 1.8); a broken variance estimate gives 0 or 20.
    int below = 0;
    for (uint64_t seed = 1; seed <= 20; ++seed) {
        BlockTestResult r = block_z_test(s.estimate(4, 8, seed), s.estimate(4, 8, seed + 100), 8, kAlpha);
        if (seed == 1) {
            EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
            EXPECT_EQ(r.tests, 8 * 6 * 3);
            std::printf("  same image: %s\n", r.describe().c_str());
        }
        if (r.p_family < 0.2) ++below;
    }
    EXPECT_GE(below, 1);
    EXPECT_LE(below, 10);
}

TEST(BlockZTest, RejectsAGlobalAndALocalBias) {
    Synthetic ref, global, local;
    global.bias = 1.05;  // 5% everywhere
    global.bx1 = global.w;
    global.by1 = global.h;
    local.bias = 1.10;  // 10% in one 8 x 8 region
    local.bx0 = 16, local.bx1 = 24, local.by0 = 24, local.by1 = 32;
    // 4 batches of 32 spp: a block's relative standard error is 1 / sqrt(64 * 128) = 1.1%.
    ImageEstimate a = ref.estimate(4, 32, 1);
    BlockTestResult g = block_z_test(a, global.estimate(4, 32, 2), 8, kAlpha);
    BlockTestResult l = block_z_test(a, local.estimate(4, 32, 3), 8, kAlpha);
    EXPECT_FALSE(g.passed(kAlpha)) << g.describe();
    EXPECT_GT(g.failing_fraction, 0.2) << "a global bias shows in many blocks";
    EXPECT_FALSE(l.passed(kAlpha)) << l.describe();
    EXPECT_EQ(l.worst_x, 16);
    EXPECT_EQ(l.worst_y, 24);
    EXPECT_LT(l.failing_fraction, 0.1) << "a local bias shows in few blocks";
    std::printf("  5%% global bias: %s\n  10%% local bias: %s\n", g.describe().c_str(), l.describe().c_str());
}

TEST(BlockZTest, FromMomentsAndFromReference) {
    // The same comparison through per-pixel second moments, and against a "committed reference"
    // (a film plus its variance image).
    Synthetic s;
    const int n = 64;
    std::vector<dvec3> sum(size_t(s.w * s.h), dvec3(0.0)), sum_sq(sum.size(), dvec3(0.0));
    std::vector<uint32_t> count(sum.size(), uint32_t(n));
    PCG32 rng(9u, 9u);
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x)
            for (int k = 0; k < n; ++k) {
                dvec3 v(s.mean(x, y) * -std::log(1.f - rng.next_float()));
                sum[size_t(y * s.w + x)] += v;
                sum_sq[size_t(y * s.w + x)] += v * v;
            }
    ImageEstimate a = ImageEstimate::from_moments(s.w, s.h, sum, sum_sq, count);
    // Exponential noise: the per-sample variance is mean^2; the reference has 256 spp.
    Film ref;
    s.render(ref, 256, 5);
    std::vector<dvec3> ref_var(sum.size());
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x) ref_var[size_t(y * s.w + x)] = dvec3(s.mean(x, y) * s.mean(x, y)) / 256.0;
    ImageEstimate b = ImageEstimate::from_film(ref, ref_var);
    BlockTestResult r = block_z_test(a, b, 8, kAlpha);
    EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
    // Scaled by 10%, the same data fails (a block's relative standard error is 1.8%).
    for (dvec3& m : a.mean) m *= 1.10;
    EXPECT_FALSE(block_z_test(a, b, 8, kAlpha).passed(kAlpha));
}
