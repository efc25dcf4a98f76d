// Film accumulation (double sums, non-finite samples, counts) and the image block z-test of
// tests/support/stats.h that image regression tests use against a committed reference; and the
// splats through the film's filter (SplatFilter.*: the box's bytes, any thread count, and the
// splat image's expectation against the camera samples', film/splat_filter.h).
#include <gtest/gtest.h>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include "film/film.h"
#include "integrator/tiles.h"
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
    std::vector<SplatTile> st(1);
    st[0].add(film.width(), film.height(), vec2(0.5f, 0.5f), vec3(nan));
    st[0].add(film.width(), film.height(), vec2(-1.f, 0.5f), vec3(1.f));
    st[0].add(film.width(), film.height(), vec2(3.5f, 0.5f), vec3(1.f));
    EXPECT_EQ(st[0].size(), 0u);
    film.add_splats(st, SplatFilter(box_filter(), film.width(), film.height()));
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

// ---- Splats through the film's filter (film/splat_filter.h) ----------------------------------

namespace {

// Splats at random positions, with random values (some outside the image, one not finite).
std::vector<SplatTile> random_splats(int w, int h, int tiles, int per_tile, uint32_t seed) {
    std::vector<SplatTile> out(static_cast<size_t>(tiles));
    uint32_t s = seed;
    auto next = [&] {
        s = s * 1664525u + 1013904223u;
        return float(s >> 8) / float(1u << 24);
    };
    for (SplatTile& t : out) {
        for (int k = 0; k < per_tile; ++k) {
            const vec2 p(next() * float(w + 2) - 1.f, next() * float(h + 2) - 1.f);
            t.add(w, h, p, vec3(next(), 10.f * next(), next() * next()));
        }
        t.add(w, h, vec2(1.f), vec3(std::numeric_limits<float>::quiet_NaN()));
        t.paths = uint64_t(per_tile);
    }
    return out;
}

// The image function of the expectation test: a ramp, and a step along a slanted line.
double image_fn(double x, double y) { return 0.5 + 0.1 * x + (x + 0.37 * y > 3.3 ? 2.0 : 0.0); }

// Per pixel, the limit of the camera samples' sum(w L) / sum(w) (samples uniform over the image)
// and the splat image (every splat one light path of the whole image: L N / paths), both by a
// midpoint rule of k x k points per pixel of image_fn. `splat_f`: the splats' filter.
void filtered_images(const FilterDesc& f, const FilterDesc& splat_f, int w, int h, int k, std::vector<dvec3>& camera,
                     std::vector<dvec3>& splat) {
    const PixelFilter pf(f);
    Film film(w, h);
    film.set_layout(true, 0);
    FilmTile tile;
    tile.reset(film, 0, 0, w, h, pf.reach());
    std::vector<SplatTile> st(1);
    for (int y = 0; y < h * k; ++y)
        for (int x = 0; x < w * k; ++x) {
            const vec2 p((float(x) + 0.5f) / float(k), (float(y) + 0.5f) / float(k));
            const vec3 L(float(image_fn(double(p.x), double(p.y))));
            detail::splat(tile, pf, w, h, p, L, nullptr);
            st[0].add(w, h, p, L);
        }
    st[0].paths = uint64_t(w) * uint64_t(h) * uint64_t(k) * uint64_t(k);
    film.merge(tile);
    film.add_splats(st, SplatFilter(splat_f, w, h));
    camera.assign(size_t(w) * size_t(h), dvec3(0.0));
    splat = camera;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            camera[i] = film.pixel_sum(x, y) / film.weights()[i];
            splat[i] = film.splat_value(i);
        }
}

double max_rel_diff(const std::vector<dvec3>& a, const std::vector<dvec3>& b) {
    double m = 0;
    for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i].x - b[i].x) / std::abs(b[i].x));
    return m;
}

}  // namespace

// The box filter: each splat added as it is to the pixel it lands in, as before splats were
// filtered (the same bytes), whatever the threads.
TEST(SplatFilter, BoxIsThePixelItLandsIn) {
    const int w = 13, h = 7;
    const std::vector<SplatTile> tiles = random_splats(w, h, 5, 200, 7u);
    std::vector<dvec3> expect(size_t(w) * size_t(h), dvec3(0.0));
    uint64_t kept = 0;
    for (const SplatTile& t : tiles)
        for (size_t k = 0; k < t.size(); ++k) {
            const int x = std::min(int(t.pos[k].x), w - 1), y = std::min(int(t.pos[k].y), h - 1);
            expect[size_t(y) * size_t(w) + size_t(x)] += dvec3(t.value[k]);
            ++kept;
        }
    EXPECT_GT(kept, 600u);
    EXPECT_LT(kept, 800u);  // about a third fell outside
    for (int threads : {1, 3}) {
        Film film(w, h);
        film.add_splats(tiles, SplatFilter(box_filter(), w, h), threads);
        ASSERT_EQ(film.splat_sums().size(), expect.size());
        EXPECT_EQ(std::memcmp(film.splat_sums().data(), expect.data(), expect.size() * sizeof(dvec3)), 0);
        EXPECT_EQ(film.splat_paths(), 1000u);
        EXPECT_EQ(film.nonfinite_count(), 5u);
    }
}

// Wider filters: bands of rows shared out to threads give the one-thread sums bit for bit, and a
// splat's weights sum to about one away from the borders (W is the filter's integral there).
TEST(SplatFilter, SameSumsAtAnyThreadCount) {
    const int w = 21, h = 17;
    const std::vector<SplatTile> tiles = random_splats(w, h, 4, 300, 11u);
    for (const FilterDesc& f : {gaussian_filter(), mitchell_filter(), lanczos_filter(), tent_filter(1.5f)}) {
        SCOPED_TRACE(filter_name(f.type));
        const SplatFilter sf(f, w, h);
        Film a(w, h), b(w, h);
        a.add_splats(tiles, sf, 1);
        b.add_splats(tiles, sf, 3);
        EXPECT_EQ(std::memcmp(a.splat_sums().data(), b.splat_sums().data(), a.splat_sums().size() * sizeof(dvec3)), 0);
        std::vector<SplatTile> one(1);
        one[0].add(w, h, vec2(10.3f, 8.8f), vec3(1.f));
        Film c(w, h);
        c.add_splats(one, sf);
        double sum = 0;
        for (const dvec3& v : c.splat_sums()) sum += v.x;
        std::printf("  %-10s one interior splat's weights sum to %.4f\n", filter_name(f.type), sum);
        // The discretised weights' ripple; Lanczos's (31 steps over 3 lobes) is 11% here.
        if (f.type != FilterType::Lanczos) {
            EXPECT_NEAR(sum, 1.0, 0.05);
        }
    }
}

// The expectation of a splat image is the camera samples' image under the same filter, every pixel
// (the borders too), for filters with and without negative lobes; the splats in one pixel (the
// box), or normalised by the filter's integral alone at the borders (pbrt-v4's), are not.
TEST(SplatFilter, ExpectationIsTheCameraImage) {
    const int w = 7, h = 5, k = 64;
    for (const FilterDesc& f : {gaussian_filter(), mitchell_filter(), lanczos_filter(2), tent_filter(1.f), gaussian_filter(1.f)}) {
        SCOPED_TRACE(filter_name(f.type));
        std::vector<dvec3> camera, splat;
        filtered_images(f, f, w, h, k, camera, splat);
        const double d = max_rel_diff(splat, camera);
        std::printf("  %-10s radius %.1f: splat image against camera image, max relative difference %.2e\n",
                    filter_name(f.type), double(PixelFilter(f).radius()), d);
        EXPECT_LT(d, 5e-3);  // the midpoint rule on the discretised filter's steps: O(1 / k)
        // Control: the box splats against the filtered camera image.
        std::vector<dvec3> camera2, boxed;
        filtered_images(f, box_filter(), w, h, k, camera2, boxed);
        EXPECT_GT(max_rel_diff(boxed, camera), 0.05);
        // Control: W the filter's integral everywhere (no border term) is off at the borders.
        const SplatFilter sf(f, w, h);
        std::vector<dvec3> interior_norm = splat;
        const double full = sf.norm_x(w / 2) * sf.norm_y(h / 2);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) interior_norm[size_t(y * w + x)] *= sf.norm_x(x) * sf.norm_y(y) / full;
        EXPECT_GT(max_rel_diff(interior_norm, camera), 0.05);
    }
}
