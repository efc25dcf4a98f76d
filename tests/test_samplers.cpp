// The samplers of sampling/samplers.h: each one's points are stratified as its comment claims
// (per-stratum counts: exactly one point per stratum, which independent points fail), Owen
// scrambling keeps the Sobol (0, 2)-sequence property, permutations are bijections, and renders are
// the same bit for bit at any thread count and pass split. Unbiasedness is tested on images:
// test_furnace.cpp (Furnace.EverySampler) and test_image_cornell.cpp (ImageCornell.EverySampler).
#include <gtest/gtest.h>
#include <cmath>
#include <functional>
#include <memory>
#include <set>
#include <vector>
#include "render/renderer.h"
#include "sampling/samplers.h"
#include "scene/cornell.h"

using namespace candela;

namespace {

SamplerSetup setup(SamplerType t, uint32_t n, uint64_t seed = 7, ivec2 res = ivec2(64)) {
    SamplerSetup s;
    s.desc.type = t;
    s.seed = seed;
    s.sample_count = n;
    s.resolution = res;
    return s;
}

// Points of one draw: `pattern` says which draws a sample makes (1 or 2 per draw), the points
// returned are those of draw `which`, for samples [first, first + count) of `pixel`.
template <class S>
std::vector<vec2> draws(S s, ivec2 pixel, uint32_t first, uint32_t count, const std::vector<int>& pattern, size_t which) {
    std::vector<vec2> out;
    for (uint32_t i = first; i < first + count; ++i) {
        s.start_pixel_sample(pixel, i);
        for (size_t k = 0; k < pattern.size(); ++k) {
            vec2 p = pattern[k] == 2 ? s.next_2d() : vec2(s.next_1d(), 0.f);
            if (k == which) out.push_back(p);
        }
    }
    return out;
}

// Exactly one point per cell of an nx x ny grid (the counts test: the claim is "one per stratum").
bool one_per_cell(const std::vector<vec2>& p, uint32_t nx, uint32_t ny) {
    if (p.size() != size_t(nx) * ny) return false;
    std::vector<int> c(p.size(), 0);
    for (vec2 q : p) {
        if (!(q.x >= 0.f && q.x < 1.f && q.y >= 0.f && q.y < 1.f)) return false;
        const uint32_t x = std::min(uint32_t(q.x * float(nx)), nx - 1), y = std::min(uint32_t(q.y * float(ny)), ny - 1);
        if (++c[size_t(y) * nx + x] > 1) return false;
    }
    return true;
}

// A (0, m, 2)-net in base 2: one point in every elementary interval of area 2^-m (all 2^k x 2^(m-k)
// grids).
bool is_02_net(const std::vector<vec2>& p, int m) {
    for (int k = 0; k <= m; ++k)
        if (!one_per_cell(p, 1u << k, 1u << (m - k))) return false;
    return true;
}

std::vector<vec2> xs(const std::vector<vec2>& p) {
    std::vector<vec2> o;
    for (vec2 q : p) o.push_back(vec2(q.x, 0.f));
    return o;
}
std::vector<vec2> ys(const std::vector<vec2>& p) {
    std::vector<vec2> o;
    for (vec2 q : p) o.push_back(vec2(q.y, 0.f));
    return o;
}

}  // namespace

// The generator matrices against the Sobol sequence as Joe and Kuo's generator lists it (Gray-code
// order: point n is C * gray(n)), and every tabulated dimension is a (0, 1)-sequence.
TEST(Samplers, SobolMatricesMatchTheSequence) {
    const double expected[8][3] = {{0, 0, 0},         {0.5, 0.5, 0.5},       {0.75, 0.25, 0.25},    {0.25, 0.75, 0.75},
                                   {0.375, 0.375, 0.625}, {0.875, 0.875, 0.125}, {0.625, 0.125, 0.875}, {0.125, 0.625, 0.375}};
    for (uint32_t n = 0; n < 8; ++n)
        for (int d = 0; d < 3; ++d)
            EXPECT_EQ(double(sobol_bits(n ^ (n >> 1), d)) * 0x1p-32, expected[n][d]) << "point " << n << " dim " << d;
    for (int d = 0; d < kSobolDimensions; ++d) {
        std::vector<vec2> p;
        for (uint32_t i = 0; i < 4096; ++i) p.push_back(vec2(bits_to_unit(sobol_bits(i, d)), 0.f));
        EXPECT_TRUE(one_per_cell(p, 4096, 1)) << "dimension " << d;
    }
}

// Owen-scrambled Sobol (dimensions 0 and 1, a pixel's first 2D draw) is a (0, 2)-sequence: every
// aligned block of 2^m points is a (0, m, 2)-net, m = 0..10, at any pixel and seed. Control:
// independent points are not (the first 16 already fail).
TEST(Samplers, OwenScrambledSobolIsAZeroTwoSequence) {
    for (uint64_t seed : {0u, 5u})
        for (ivec2 px : {ivec2(0, 0), ivec2(17, 3)}) {
            const SobolSampler s(setup(SamplerType::Sobol, 1, seed));
            const std::vector<vec2> p = draws(s, px, 0, 2048, {2}, 0);
            for (int m = 0; m <= 10; ++m)
                for (size_t b = 0; b < p.size(); b += size_t(1) << m)
                    EXPECT_TRUE(is_02_net(std::vector<vec2>(p.begin() + long(b), p.begin() + long(b + (size_t(1) << m))), m))
                        << "m " << m << " block " << b;
        }
    // Scrambled: another pixel gets other points, and not the unscrambled ones.
    const SobolSampler s(setup(SamplerType::Sobol, 1));
    EXPECT_NE(draws(s, ivec2(0), 1, 1, {2}, 0)[0], draws(s, ivec2(1, 0), 1, 1, {2}, 0)[0]);
    EXPECT_NE(draws(s, ivec2(0), 1, 1, {2}, 0)[0], vec2(0.5f));
    const std::vector<vec2> ind = draws(IndependentSampler(7), ivec2(0), 0, 16, {2}, 0);
    EXPECT_FALSE(is_02_net(ind, 4));
}

// Every Sobol dimension of the budget is stratified in 1D (each prefix of 2^m points one per
// stratum of 2^-m), whichever draw reaches it; past the budget the numbers are independent ones.
TEST(Samplers, SobolDimensionsWithinTheBudgetAreStratified) {
    const SobolSampler s(setup(SamplerType::Sobol, 1));
    const std::vector<int> pattern = {2, 1, 2, 1, 2, 1, 2, 1, 2, 1, 2, 1, 2, 1, 2, 1, 2, 1, 2, 1, 2, 1, 2};  // 34 dims
    int dim = 0;
    for (size_t k = 0; k < pattern.size(); ++k) {
        const std::vector<vec2> p = draws(s, ivec2(3, 9), 0, 64, pattern, k);
        const bool in_budget = dim + pattern[k] <= kSobolDimensions;
        EXPECT_EQ(one_per_cell(xs(p), 64, 1), in_budget) << "draw " << k << " (dimension " << dim << ")";
        if (pattern[k] == 2 && in_budget) {
            EXPECT_TRUE(one_per_cell(ys(p), 64, 1)) << "draw " << k;
        }
        dim += pattern[k];
    }
}

// Stratified (4 x 4 and 16 strata), multijitter (4 x 4 cells and 16 strata on both axes; 3 x 4
// for 12), ldsampler ((0, 4, 2)-nets): in every draw, and again in the second set of samples.
// Control: independent points fail each check.
TEST(Samplers, StratifiedSetsAreStratified) {
    const std::vector<int> pattern = {2, 1, 2, 1, 2};
    for (uint32_t set = 0; set < 2; ++set)
        for (size_t k = 0; k < pattern.size(); ++k) {
            for (bool jitter : {true, false}) {
                SamplerSetup st = setup(SamplerType::Stratified, 16);
                st.desc.jitter = jitter;
                const auto p = draws(StratifiedSampler(st), ivec2(5, 2), 16 * set, 16, pattern, k);
                EXPECT_TRUE(pattern[k] == 2 ? one_per_cell(p, 4, 4) : one_per_cell(p, 16, 1)) << "stratified draw " << k;
            }
            const auto m = draws(MultijitterSampler(setup(SamplerType::Multijitter, 16)), ivec2(5, 2), 16 * set, 16, pattern, k);
            EXPECT_TRUE(one_per_cell(xs(m), 16, 1)) << "multijitter draw " << k;
            if (pattern[k] == 2) {
                EXPECT_TRUE(one_per_cell(m, 4, 4)) << "multijitter draw " << k;
                EXPECT_TRUE(one_per_cell(ys(m), 16, 1)) << "multijitter draw " << k;
                const auto m12 = draws(MultijitterSampler(setup(SamplerType::Multijitter, 12)), ivec2(1), 12 * set, 12, pattern, k);
                EXPECT_TRUE(one_per_cell(m12, 3, 4) && one_per_cell(xs(m12), 12, 1) && one_per_cell(ys(m12), 12, 1));
            }
            const auto l = draws(LdSampler(setup(SamplerType::LdSampler, 16)), ivec2(5, 2), 16 * set, 16, pattern, k);
            EXPECT_TRUE(pattern[k] == 2 ? is_02_net(l, 4) : one_per_cell(l, 16, 1)) << "ldsampler draw " << k;
        }
    const auto ind = draws(IndependentSampler(7), ivec2(5, 2), 0, 16, {2}, 0);
    EXPECT_FALSE(one_per_cell(ind, 4, 4));
    EXPECT_FALSE(one_per_cell(xs(ind), 16, 1));
    // Sample counts the sets are made of (Mitsuba's roundings).
    EXPECT_EQ(sampler_sample_count(SamplerType::Stratified, 10), 16u);
    EXPECT_EQ(sampler_sample_count(SamplerType::Multijitter, 10), 12u);
    EXPECT_EQ(sampler_sample_count(SamplerType::LdSampler, 10), 16u);
    EXPECT_EQ(sampler_sample_count(SamplerType::Sobol, 10), 10u);
}

// orthogonal (strength 2, n = p^2): every dimension is a Latin hypercube (one point in each of the
// n 1D strata) and every pair of dimensions of one array (group of p + 1 dimensions, a 2D draw
// never straddling two) is stratified on the p x p grid, for p = 2, 3, 5, with and without jitter,
// in the first and second sets. Control: pairs from different groups (independent arrays) are not
// all stratified, and independent points fail (StratifiedSetsAreStratified).
TEST(Samplers, OrthogonalArraysAreStratified) {
    const std::vector<int> pattern = {2, 1, 2, 2, 1, 1, 2, 1, 2};  // 14 dimensions: several groups for every p
    for (uint32_t p : {2u, 3u, 5u}) {
        const uint32_t n = p * p;
        EXPECT_EQ(sampler_sample_count(SamplerType::Orthogonal, n), n);
        // Group of each dimension, by the rule of the sampler's comment.
        std::vector<int> group;
        int g = -1;
        uint32_t col = p + 1;
        for (int w : pattern) {
            if (col + uint32_t(w) > p + 1) ++g, col = 0;
            col += uint32_t(w);
            for (int k = 0; k < w; ++k) group.push_back(g);
        }
        for (bool jitter : {true, false})
            for (uint32_t set = 0; set < 2; ++set) {
                SamplerSetup st = setup(SamplerType::Orthogonal, n, 11);
                st.desc.jitter = jitter;
                OrthogonalSampler s(st);
                std::vector<std::vector<float>> dims(group.size());
                for (uint32_t i = set * n; i < (set + 1) * n; ++i) {
                    s.start_pixel_sample(ivec2(4, 7), i);
                    size_t d = 0;
                    for (int w : pattern) {
                        if (w == 2) {
                            const vec2 q = s.next_2d();
                            dims[d++].push_back(q.x);
                            dims[d++].push_back(q.y);
                        } else {
                            dims[d++].push_back(s.next_1d());
                        }
                    }
                }
                int cross_stratified = 0, cross = 0;
                for (size_t a = 0; a < dims.size(); ++a) {
                    std::vector<vec2> xa;
                    for (float v : dims[a]) xa.push_back(vec2(v, 0.f));
                    EXPECT_TRUE(one_per_cell(xa, n, 1)) << "p " << p << " dimension " << a;
                    for (size_t b = a + 1; b < dims.size(); ++b) {
                        std::vector<vec2> ab;
                        for (uint32_t i = 0; i < n; ++i) ab.push_back(vec2(dims[a][i], dims[b][i]));
                        const bool ok = one_per_cell(ab, p, p);
                        if (group[a] == group[b]) {
                            EXPECT_TRUE(ok) << "p " << p << " dimensions " << a << ", " << b;
                        } else {
                            ++cross;
                            cross_stratified += ok;
                        }
                    }
                }
                EXPECT_LT(cross_stratified, cross) << "p " << p << ": the groups' arrays are not independent";
            }
    }
    EXPECT_EQ(sampler_sample_count(SamplerType::Orthogonal, 1), 4u);
    EXPECT_EQ(sampler_sample_count(SamplerType::Orthogonal, 10), 25u);
    EXPECT_EQ(sampler_sample_count(SamplerType::Orthogonal, 26), 49u);
    EXPECT_EQ(sampler_sample_count(SamplerType::Orthogonal, 50), 121u);
}

// zsobol: the samples of an aligned quad of pixels are one block of the sequence, so the 4 spp of
// a 4 x 4-pixel quad together form a (0, 6, 2)-net (blue noise across pixels), in later draws too
// (the per-dimension digit permutations keep blocks), and each pixel's own 4 samples a (0, 2, 2)-
// net. Control: the per-pixel sobol sampler's 4 x 4 pixels are not a net together.
TEST(Samplers, ZSobolQuadsFormNets) {
    auto quad = [](const auto& s, ivec2 at, size_t which) {
        std::vector<vec2> p;
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 4; ++x) {
                auto q = draws(s, at + ivec2(x, y), 0, 4, {2, 1, 2}, which);
                p.insert(p.end(), q.begin(), q.end());
            }
        return p;
    };
    for (ivec2 at : {ivec2(0, 0), ivec2(8, 4), ivec2(60, 28)}) {
        const ZSobolSampler z(setup(SamplerType::ZSobol, 4, 3, ivec2(64, 32)));
        EXPECT_TRUE(is_02_net(quad(z, at, 0), 6)) << at.x << "," << at.y;
        EXPECT_TRUE(is_02_net(quad(z, at, 2), 6)) << at.x << "," << at.y;
        EXPECT_TRUE(one_per_cell(xs(quad(z, at, 1)), 64, 1));
        EXPECT_TRUE(is_02_net(draws(z, at, 0, 4, {2}, 0), 2));
        EXPECT_TRUE(is_02_net(draws(z, at, 4, 4, {2}, 0), 2)) << "second set";
    }
    const SobolSampler s(setup(SamplerType::Sobol, 4));
    EXPECT_FALSE(is_02_net(quad(s, ivec2(0), 0), 6));
    // Odd log2 of the sample count (8 spp) and a film that is not a power of two.
    const ZSobolSampler z8(setup(SamplerType::ZSobol, 8, 1, ivec2(37, 21)));
    for (ivec2 px : {ivec2(0), ivec2(36, 20)}) EXPECT_TRUE(is_02_net(draws(z8, px, 0, 8, {2}, 0), 3));
}

TEST(Samplers, PermutationsAreBijections) {
    for (uint32_t n : {1u, 2u, 3u, 5u, 16u, 17u, 100u, 1000u})
        for (uint32_t seed : {0u, 1u, 0xdeadbeefu}) {
            std::set<uint32_t> seen;
            for (uint32_t i = 0; i < n; ++i) seen.insert(sampler_detail::permute(i, n, seed));
            EXPECT_EQ(seen.size(), size_t(n));
            EXPECT_LT(*seen.rbegin(), n);
        }
}

// Same seed and sample count: the same image bit for bit at 1 and 2 threads and for 2 passes of 4
// spp or 1 pass of 8, with every sampler (box filter: the unweighted loop; gaussian: the weighted).
TEST(Samplers, RendersAreDeterministicAcrossThreadsAndPassSplits) {
    for (int t = 0; t < kSamplerTypeCount; ++t)
        for (bool gaussian : {false, true}) {
            SceneDescription d = make_cornell_box();
            d.settings.width = d.settings.height = 24;
            d.settings.spp = 8;
            d.settings.seed = 3;
            d.settings.sampler.type = SamplerType(t);
            if (gaussian) d.settings.filter = gaussian_filter();
            const std::shared_ptr<const Scene> sc = build_scene(std::move(d));
            Film a(24, 24), b(24, 24), c(24, 24);  // render_pass lays them out for the filter
            Renderer::render_pass(*sc, a, 0, 8, 1);
            Renderer::render_pass(*sc, b, 0, 4, 2);
            Renderer::render_pass(*sc, b, 4, 4, 2);
            Renderer::render_pass(*sc, c, 0, 8, 2);
            int diff_split = 0, diff_threads = 0;
            for (int y = 0; y < 24; ++y)
                for (int x = 0; x < 24; ++x) {
                    diff_split += a.pixel(x, y) != b.pixel(x, y);
                    diff_threads += a.pixel(x, y) != c.pixel(x, y);
                }
            EXPECT_EQ(diff_split, 0) << sampler_type_name(SamplerType(t)) << (gaussian ? " gaussian" : "");
            EXPECT_EQ(diff_threads, 0) << sampler_type_name(SamplerType(t)) << (gaussian ? " gaussian" : "");
        }
}
