// PCG32 against its definition, the independent sampler's determinism and stream separation, and
// DiscreteDistribution's frequencies and remapping (chi-square, with rejection checks).
#include <gtest/gtest.h>
#include <set>
#include "sampling/distribution.h"
#include "sampling/pcg32.h"
#include "sampling/sampler.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;

// PCG32 written out from O'Neill's reference (pcg32_srandom_r / pcg32_random_r in pcg-c-basic),
// independently of src/sampling/pcg32.h: the generator must reproduce it bit for bit.
struct ReferencePcg {
    uint64_t state, inc;
    ReferencePcg(uint64_t initstate, uint64_t initseq) {
        state = 0;
        inc = (initseq << 1) | 1;
        next();
        state += initstate;
        next();
    }
    uint32_t next() {
        uint64_t old = state;
        state = old * 6364136223846793005ULL + inc;  // the multiplier, in decimal as in the paper
        uint32_t xorshifted = uint32_t(((old >> 18) ^ old) >> 27);
        uint32_t rot = uint32_t(old >> 59);
        return rot == 0 ? xorshifted : (xorshifted >> rot) | (xorshifted << (32 - rot));
    }
};

// Chi-square of values in [0, 1) over equal bins.
ChiSquareResult uniform_bins(const std::vector<float>& v, int bins) {
    std::vector<double> obs(size_t(bins), 0.0), expct(size_t(bins), double(v.size()) / bins);
    for (float x : v) obs[size_t(std::min(int(x * float(bins)), bins - 1))] += 1;
    return chi_square_counts(obs, expct);
}

}  // namespace

TEST(Pcg32, MatchesTheReferenceDefinition) {
    // Seeding by hand for (initstate 42, initseq 54): inc = 2*54+1; one step from state 0 gives
    // inc; adding the seed and one more step gives the state below.
    PCG32 rng(54u, 42u);
    const uint64_t inc = 109u;
    const uint64_t state = (inc + 42u) * PCG32::kMult + inc;
    EXPECT_EQ(rng.inc(), inc);
    EXPECT_EQ(rng.state(), state);
    EXPECT_EQ(PCG32::kMult, 6364136223846793005ULL);

    // The first outputs printed by O'Neill's pcg32-demo for this seed.
    const uint32_t demo[6] = {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u, 0x83d2f293u, 0xbfa4784bu, 0xcbed606eu};
    for (uint32_t v : demo) EXPECT_EQ(rng.next_u32(), v);

    // A longer stretch and other seeds against the reference written out above.
    for (auto [seq, seed] : {std::pair<uint64_t, uint64_t>{54u, 42u}, {0u, 0u}, {~0ull, 12345u}, {7u, ~0ull}}) {
        PCG32 a(seq, seed);
        ReferencePcg b(seed, seq);
        for (int i = 0; i < 1000; ++i) ASSERT_EQ(a.next_u32(), b.next()) << seq << " " << seed << " step " << i;
    }
}

TEST(Pcg32, AdvanceEqualsSteps) {
    for (uint64_t n : {0ull, 1ull, 2ull, 3ull, 17ull, 1000ull, 65543ull}) {
        PCG32 a(3u, 99u), b(3u, 99u);
        for (uint64_t i = 0; i < n; ++i) a.next_u32();
        b.advance(n);
        EXPECT_EQ(a.state(), b.state()) << n;
        EXPECT_EQ(a.next_u32(), b.next_u32()) << n;
    }
    // The period is 2^64: going forward n and then 2^64 - n comes back to the start.
    PCG32 c(5u, 6u);
    uint64_t start = c.state();
    c.advance(123456789u);
    EXPECT_NE(c.state(), start);
    c.advance(0ull - 123456789ull);
    EXPECT_EQ(c.state(), start);
}

TEST(Pcg32, NextFloatIsUniform) {
    PCG32 rng(1u, 2u);
    std::vector<float> v(1000000);
    for (float& x : v) {
        x = rng.next_float();
        ASSERT_GE(x, 0.f);
        ASSERT_LT(x, 1.f);
    }
    ChiSquareResult good = uniform_bins(v, 100);
    // The same test must reject a slightly non-uniform generator (x^1.01).
    std::vector<float> bent(v);
    for (float& x : bent) x = std::pow(x, 1.01f);
    ChiSquareResult bad = uniform_bins(bent, 100);
    const double level = sidak_level(kAlpha, 2);
    EXPECT_GE(good.p_value, level) << good.describe();
    EXPECT_LT(bad.p_value, level) << bad.describe();
    std::printf("  next_float: p = %g; x^1.01: p = %g\n", good.p_value, bad.p_value);
}

TEST(IndependentSampler, DeterministicPerPixelAndIndex) {
    auto draw = [](uint64_t seed, ivec2 px, uint32_t index) {
        IndependentSampler s(seed);
        s.start_pixel_sample(px, index);
        std::vector<float> v;
        for (int i = 0; i < 8; ++i) v.push_back(s.next_1d());
        vec2 u = s.next_2d();
        v.push_back(u.x);
        v.push_back(u.y);
        return v;
    };
    // Same (pixel, index, seed): the same numbers, whatever was drawn before (a fresh sampler or
    // one that has served other pixels).
    IndependentSampler reused(7);
    reused.start_pixel_sample(ivec2(100, 3), 9);
    for (int i = 0; i < 50; ++i) reused.next_1d();
    reused.start_pixel_sample(ivec2(3, 4), 5);
    std::vector<float> v;
    for (int i = 0; i < 8; ++i) v.push_back(reused.next_1d());
    vec2 u = reused.next_2d();
    v.push_back(u.x);
    v.push_back(u.y);
    EXPECT_EQ(v, draw(7, ivec2(3, 4), 5));

    // Different pixels (including transposed and negative coordinates), indices and seeds: all
    // different streams.
    std::set<std::vector<float>> seen;
    int n = 0;
    for (uint64_t seed : {0ull, 1ull, 7ull})
        for (ivec2 px : {ivec2(0, 0), ivec2(1, 0), ivec2(0, 1), ivec2(3, 4), ivec2(4, 3), ivec2(-1, 0), ivec2(0, -1)})
            for (uint32_t index : {0u, 1u, 2u, 65535u, 65536u}) {
                seen.insert(draw(seed, px, index));
                ++n;
            }
    EXPECT_EQ(int(seen.size()), n);

    // Sample i + 1 starts 2^16 draws after sample i in the same stream: its numbers are not the
    // tail of sample i's numbers.
    IndependentSampler a(3), b(3);
    a.start_pixel_sample(ivec2(5, 5), 0);
    b.start_pixel_sample(ivec2(5, 5), 1);
    float b0 = b.next_1d();
    int equal_run = 0;
    for (int i = 0; i < 1000; ++i) equal_run += a.next_1d() == b0;
    EXPECT_LT(equal_run, 2);
}

// Neighbouring pixels must not have correlated streams: the pairs (first number of pixel (x, y),
// first number of pixel (x + 1, y)) must be uniform on the unit square, and the same for
// consecutive sample indices of one pixel. A perfectly correlated pair (u, u) must be rejected.
TEST(IndependentSampler, NeighbouringStreamsAreIndependent) {
    const int bins = 16;
    auto test_pairs = [&](const std::vector<vec2>& pairs) {
        std::vector<double> obs(size_t(bins * bins), 0.0), expct(obs.size(), double(pairs.size()) / (bins * bins));
        for (vec2 p : pairs) obs[size_t(int(p.x * bins) * bins + int(p.y * bins))] += 1;
        return chi_square_counts(obs, expct);
    };
    std::vector<vec2> across_pixels, across_indices, correlated;
    IndependentSampler s(11);
    for (int y = 0; y < 200; ++y)
        for (int x = 0; x < 250; ++x) {
            s.start_pixel_sample(ivec2(x, y), 0);
            float a = s.next_1d();
            s.start_pixel_sample(ivec2(x + 1, y), 0);
            float b = s.next_1d();
            s.start_pixel_sample(ivec2(x, y), 1);
            float c = s.next_1d();
            across_pixels.push_back(vec2(a, b));
            across_indices.push_back(vec2(a, c));
            correlated.push_back(vec2(a, std::fmod(a + 0.01f * b, 1.f)));
        }
    const double level = sidak_level(kAlpha, 3);
    ChiSquareResult r1 = test_pairs(across_pixels), r2 = test_pairs(across_indices), r3 = test_pairs(correlated);
    EXPECT_GE(r1.p_value, level) << r1.describe();
    EXPECT_GE(r2.p_value, level) << r2.describe();
    EXPECT_LT(r3.p_value, level) << r3.describe();
    std::printf("  pixel pairs p = %g, index pairs p = %g, correlated pairs p = %g\n", r1.p_value, r2.p_value, r3.p_value);
}

// ---- DiscreteDistribution --------------------------------------------------------------------------

namespace {
const std::vector<float> kWeights = {0.f, 1.f, 0.f, 3.f, 0.5f, 0.f, 0.f, 2.5f, 1e-3f, 0.f};
}

TEST(DiscreteDistribution, FrequenciesMatchPmf) {
    DiscreteDistribution d(kWeights);
    double total = 0;
    for (float w : kWeights) total += w;
    ASSERT_EQ(d.size(), kWeights.size());
    for (size_t i = 0; i < kWeights.size(); ++i) EXPECT_NEAR(d.pmf(i), kWeights[i] / total, 1e-7);

    PCG32 rng(17u, 4u);
    const int n = 1000000;
    std::vector<double> obs(kWeights.size(), 0.0), expct(kWeights.size()), wrong(kWeights.size());
    for (int k = 0; k < n; ++k) {
        float pmf;
        size_t i = d.sample(rng.next_float(), &pmf);
        ASSERT_LT(i, kWeights.size());
        ASSERT_EQ(pmf, d.pmf(i));
        obs[i] += 1;
    }
    for (size_t i = 0; i < kWeights.size(); ++i) {
        expct[i] = n * kWeights[i] / total;
        EXPECT_TRUE(kWeights[i] > 0 || obs[i] == 0) << "zero-weight entry " << i << " was returned";
    }
    // Rejection check: a pmf with 1% of entry 3's mass moved to entry 7.
    wrong = expct;
    wrong[3] -= 0.01 * expct[3];
    wrong[7] += 0.01 * expct[3];
    ChiSquareResult good = chi_square_counts(obs, expct), bad = chi_square_counts(obs, wrong);
    const double level = sidak_level(kAlpha, 2);
    EXPECT_GE(good.p_value, level) << good.describe();
    EXPECT_LT(bad.p_value, level) << bad.describe();
    std::printf("  frequencies p = %g; perturbed pmf p = %g\n", good.p_value, bad.p_value);
}

TEST(DiscreteDistribution, ZeroWeightsNeverReturnedAtBoundaries) {
    // u exactly on every cdf step, one float either side, and the extremes of [0, 1).
    DiscreteDistribution d(kWeights);
    std::vector<float> us = {0.f, 0x1p-24f, 0x1.fffffep-1f};
    double total = 0, c = 0;
    for (float w : kWeights) total += w;
    for (float w : kWeights) {
        c += w;
        float f = float(c / total);
        for (float u : {f, next_float_down(f), next_float_up(f)})
            if (u >= 0.f && u < 1.f) us.push_back(u);
    }
    for (float u : us) {
        float pmf, ur;
        size_t i = d.sample(u, &pmf, &ur);
        EXPECT_GT(kWeights[i], 0.f) << "u = " << u << " gave zero-weight entry " << i;
        EXPECT_GT(pmf, 0.f);
        EXPECT_GE(ur, 0.f);
        EXPECT_LT(ur, 1.f);
    }
    // Leading and trailing zeros alone.
    DiscreteDistribution lead({0.f, 0.f, 1.f}), trail({1.f, 0.f, 0.f});
    for (float u : {0.f, 0.5f, 0x1.fffffep-1f}) {
        EXPECT_EQ(lead.sample(u), 2u);
        EXPECT_EQ(trail.sample(u), 0u);
    }
}

TEST(DiscreteDistribution, BranchlessSearchIsUpperBound) {
    // sample() searches without branches; its index must be the one std::upper_bound gives on the
    // normalised cdf (minus one, clamped, then stepped off zero-width bins), for every u tried:
    // random ones, every cdf step and one float either side, and the ends.
    for (std::vector<float> w : {kWeights, std::vector<float>{2.f}, std::vector<float>{1.f, 3.f},
                                 std::vector<float>{1.f, 0.f, 2.f}, std::vector<float>(1000, 1.f)}) {
        if (w.size() == 1000)
            for (size_t i = 0; i < w.size(); ++i) w[i] = float((i * 7919) % 13);
        DiscreteDistribution d(w);
        std::vector<double> cdf(w.size() + 1, 0.0);
        for (size_t i = 0; i < w.size(); ++i) cdf[i + 1] = cdf[i] + double(w[i]);
        std::vector<float> cdf_f(cdf.size());
        for (size_t i = 0; i < cdf.size(); ++i) cdf_f[i] = float(cdf[i] / cdf.back());
        cdf_f.back() = 1.f;
        std::vector<float> us = {0.f, 0x1p-24f, 0.5f, 0x1.fffffep-1f};
        for (float f : cdf_f)
            for (float u : {f, next_float_down(f), next_float_up(f)})
                if (u >= 0.f && u < 1.f) us.push_back(u);
        PCG32 rng(5u, 9u);
        for (int k = 0; k < 20000; ++k) us.push_back(rng.next_float());
        for (float u : us) {
            auto it = std::upper_bound(cdf_f.begin(), cdf_f.end(), u);
            size_t want = size_t(std::max<std::ptrdiff_t>(it - cdf_f.begin() - 1, 0));
            want = std::min(want, w.size() - 1);
            while (w[want] == 0.f && want > 0) --want;
            while (w[want] == 0.f && want + 1 < w.size()) ++want;
            ASSERT_EQ(d.sample(u), want) << "u = " << u << " with " << w.size() << " weights";
        }
    }
}

TEST(DiscreteDistribution, RemappedUIsUniform) {
    // Given the chosen entry, the remapped u must be uniform on [0, 1) and independent of it.
    DiscreteDistribution d(kWeights);
    PCG32 rng(8u, 9u);
    const int bins = 20;
    std::vector<std::vector<float>> per_entry(kWeights.size());
    for (int k = 0; k < 1000000; ++k) {
        float ur;
        size_t i = d.sample(rng.next_float(), nullptr, &ur);
        per_entry[i].push_back(ur);
    }
    int tested = 0;
    double p_min = 1;
    for (const auto& v : per_entry)
        if (v.size() >= size_t(bins) * 5) {
            p_min = std::min(p_min, uniform_bins(v, bins).p_value);
            ++tested;
        }
    ASSERT_EQ(tested, 5);  // every entry of non-zero weight (the 1e-3 one gets ~140 samples)
    // A remapping whose density is off by up to 2% is rejected.
    std::vector<float> wrong;
    for (float u : per_entry[3]) wrong.push_back(std::min(u * 0.98f + 0.02f * u * u, 0x1.fffffep-1f));
    double p_wrong = uniform_bins(wrong, bins).p_value;
    const double level = sidak_level(kAlpha, tested + 1);
    EXPECT_GE(p_min, level);
    EXPECT_LT(p_wrong, level);
    std::printf("  remapped u: min p over entries = %g; distorted remap p = %g\n", p_min, p_wrong);
}
