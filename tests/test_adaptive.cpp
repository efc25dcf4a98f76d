// Adaptive sampling (film/adaptive.h, --target-error): the two halves of the film, the error
// estimate, the unbiasedness of the stopping rule (with the naive rule as the control it must
// reject), determinism and the CLI.
#include <gtest/gtest.h>
#include <cmath>
#include <cstring>
#include <deque>
#include <random>
#include "film/adaptive.h"
#include "film/exr_layers.h"
#include "film/image_io.h"
#include "film/pass_halves.h"
#include "render/renderer.h"
#include "scene/cornell.h"
#include "support/run.h"
#include "support/stats.h"

using namespace candela;

TEST(Adaptive, HalvesAndErrorEstimate) {
    Film f(2, 1);
    f.enable_adaptive();
    // Pixel 0: even indices get 1, 3 (decision half), odd ones 10, 20 (the image).
    const float v[4] = {1.f, 10.f, 3.f, 20.f};
    for (uint32_t s = 0; s < 4; ++s) f.add_adaptive_sample(ivec2(0, 0), vec3(v[s]), s);
    EXPECT_EQ(f.half_count(0, 0, 0), 2u);
    EXPECT_EQ(f.half_count(0, 0, 1), 2u);
    EXPECT_EQ(f.samples_taken(0, 0), 4u);
    EXPECT_EQ(f.total_samples(), 4u);
    EXPECT_FLOAT_EQ(f.pixel(0, 0).x, 15.f);  // the image is the odd half only
    // Decision half: mean 2, variance 2, e = sqrt(2 / 2) / 2.
    EXPECT_NEAR(adaptive_pixel_error(f, 0, 0), 0.5, 1e-12);
    EXPECT_NEAR(adaptive_pixel_error(f, 0, 0, 1), std::sqrt(50.0 / 2) / 15, 1e-12);
    // Pixel 1: one sample per half: no estimate yet; a black pixel is judged on the floor.
    f.add_adaptive_sample(ivec2(1, 0), vec3(0.f), 0);
    EXPECT_TRUE(std::isinf(adaptive_pixel_error(f, 1, 0)));
    f.add_adaptive_sample(ivec2(1, 0), vec3(0.f), 2);
    EXPECT_EQ(adaptive_pixel_error(f, 1, 0), 0.0);
    AdaptiveSettings s;
    s.target_error = 0.6;
    s.min_spp = 4;
    EXPECT_EQ(update_adaptive(f, s), 1u);  // pixel 1 has only 2 samples: below the minimum
    EXPECT_FALSE(f.active(0, 0));
    EXPECT_TRUE(f.active(1, 0));
}

namespace {

// A pixel whose samples are mostly dim and noisy, with rare bright paths: 50 with probability
// 1/100, else uniform in [0.4, 0.6]. Mean 0.99 * 0.5 + 0.5 = 0.995. Emulates the headless loop
// (passes of 2 spp, the rule between passes) on 64 x 64 independent pixels and returns the z-score
// of the image's mean against the true mean.
double rare_bright_z(bool naive) {
    const int W = 64, H = 64;
    Film f(W, H);
    f.enable_adaptive();
    AdaptiveSettings s;
    s.target_error = 0.05;
    s.min_spp = 16;
    s.decide_on_image = naive;
    std::vector<std::mt19937_64> rng;
    for (int i = 0; i < W * H; ++i) rng.emplace_back(0x5eed0000u + uint64_t(i));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (uint32_t first = 0; first < 256; first += 2) {
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                if (!f.active(x, y)) continue;
                for (uint32_t k = 0; k < 2; ++k) {
                    std::mt19937_64& r = rng[size_t(y * W + x)];
                    const double a = u(r), b = u(r);
                    const float L = a < 0.01 ? 50.f : float(0.4 + 0.2 * b);
                    f.add_adaptive_sample(ivec2(x, y), vec3(L), first + k);
                }
            }
        if (update_adaptive(f, s) == 0) break;
    }
    double sum = 0, sq = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const double p = f.pixel(x, y).x;
            sum += p;
            sq += p * p;
        }
    const double n = double(W * H), m = sum / n, var = (sq - n * m * m) / (n - 1);
    return (m - 0.995) / std::sqrt(var / n);
}

}  // namespace

TEST(Adaptive, StoppingRuleUnbiasedOnRareBrightPaths) {
    // The two-half rule: the decision sees the even samples, the image averages the odd ones.
    const double z = rare_bright_z(false);
    const double p = stats::normal_two_sided_p(z);
    EXPECT_GT(p, 1e-3) << "z = " << z;
    // Control: the naive rule (the averaged samples decide) stops most pixels at 16 spp before
    // they saw a bright path, and their image is dark. Measured z = -41, p < 1e-300.
    const double zc = rare_bright_z(true);
    const double pc = stats::normal_two_sided_p(zc);
    EXPECT_LT(pc, 1e-6) << "z = " << zc;
    EXPECT_LT(zc, 0.0);
    std::printf("two-half rule z = %.3f p = %.3g; naive rule z = %.3f p = %.3g\n", z, p, zc, pc);
}

TEST(Adaptive, CliDeterministicSppChannelAndBounds) {
    std::string d = test::temp_dir("adaptive");
    // 64 spp at most, passes of 4; the Cornell box's dark and bright walls stop at different counts.
    const std::string common = "--width 32 --height 32 --frames 16 --spp-per-frame 4 --seed 3 --target-error 0.08 "
                               "--adaptive-min-spp 8";
    auto r1 = test::run_candela(common + " --threads 1 --out " + d + "/a1.exr");
    auto r2 = test::run_candela(common + " --threads 2 --out " + d + "/a2.exr");
    ASSERT_EQ(r1.exit_code, 0) << r1.output;
    ASSERT_EQ(r2.exit_code, 0) << r2.output;
    EXPECT_NE(r1.output.find("candela: adaptive: target error 0.08"), std::string::npos) << r1.output;
    Image a = read_linear_image(d + "/a1.exr"), b = read_linear_image(d + "/a2.exr");
    ASSERT_EQ(a.rgb.size(), size_t(32 * 32 * 3));
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    EXPECT_EQ(std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)), 0);
    auto ch1 = read_exr_channels(d + "/a1.exr"), ch2 = read_exr_channels(d + "/a2.exr");
    ASSERT_TRUE(ch1.count("spp"));
    EXPECT_EQ(ch1["spp"], ch2["spp"]);
    float lo = 1e9f, hi = 0.f;
    for (float c : ch1["spp"]) {
        lo = std::min(lo, c);
        hi = std::max(hi, c);
        EXPECT_EQ(std::fmod(c, 4.f), 0.f);  // decisions only between passes
    }
    EXPECT_GE(lo, 8.f);   // the minimum
    EXPECT_LE(hi, 64.f);  // the sample count bounds it
    EXPECT_LT(lo, hi);    // and the counts differ per pixel (else the rule did nothing)
    // A different seed changes the image (the equality above is not vacuous).
    auto r3 = test::run_candela("--width 32 --height 32 --frames 16 --spp-per-frame 4 --seed 4 --target-error 0.08 "
                                "--adaptive-min-spp 8 --threads 2 --out " + d + "/a3.exr");
    ASSERT_EQ(r3.exit_code, 0) << r3.output;
    Image c = read_linear_image(d + "/a3.exr");
    EXPECT_NE(std::memcmp(a.rgb.data(), c.rgb.data(), a.rgb.size() * sizeof(float)), 0);
    // A loose target stops the whole render early.
    auto r4 = test::run_candela("--width 16 --height 16 --frames 100 --spp-per-frame 4 --target-error 10 "
                                "--adaptive-min-spp 8 --out " + d + "/a4.exr");
    ASSERT_EQ(r4.exit_code, 0) << r4.output;
    EXPECT_NE(r4.output.find("10 reached"), std::string::npos) << r4.output;
    EXPECT_NE(r4.output.find(", 8 spp in"), std::string::npos) << r4.output;
}

TEST(Adaptive, CliRefusesWhatItDoesNotSupport) {
    std::string d = test::temp_dir("adaptive-refuse");
    const std::string base = "--width 8 --height 8 --frames 2 --target-error 0.1 --out " + d + "/x.exr ";
    auto r = test::run_candela(base + "--sampler sobol");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("needs the independent sampler"), std::string::npos) << r.output;
    r = test::run_candela(base + "--integrator ptracer");  // integrator/caps.h: a usage error
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--target-error: not available with the ptracer integrator"), std::string::npos) << r.output;
    r = test::run_candela(base + "--integrator bdpt");  // integrator/caps.h: a usage error
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--target-error: not available with the bdpt integrator"), std::string::npos) << r.output;
    r = test::run_candela(base + "--checkpoint " + d + "/c.ckpt");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("do not checkpoint"), std::string::npos) << r.output;
    r = test::run_candela(base + "--adaptive-min-spp 2");
    EXPECT_NE(r.exit_code, 0) << r.output;
    r = test::run_candela("--width 8 --height 8 --frames 2 --adaptive-min-spp 8 --out " + d + "/y.exr");
    EXPECT_NE(r.exit_code, 0) << r.output;  // needs --target-error
}

namespace {

// K films of the 32 x 32 Cornell box, seeds 10 + k: adaptive (target 0.1 after 8 spp, at most 64,
// passes of 4) or plain 64 spp.
std::deque<Film> cornell_batches(int K, bool adaptive, double scale = 1.0) {
    std::deque<Film> films;  // Film is not movable
    for (int k = 0; k < K; ++k) {
        SceneDescription d = make_cornell_box();
        d.settings.width = d.settings.height = 32;
        d.settings.seed = uint64_t(10 + k);
        // The light's edge pixels (radiance 0 or ~17 per sample) would dominate the whole-image
        // variance; hidden, the test sees the indirect light, where the rule acts.
        d.settings.integrator.hide_emitters = true;
        const std::shared_ptr<const Scene> sc = build_scene(std::move(d));
        films.emplace_back(32, 32);
        Film& f = films.back();
        AdaptiveSettings s;
        s.target_error = 0.1;
        s.min_spp = 8;
        if (adaptive) f.enable_adaptive();
        for (uint32_t first = 0; first < 64; first += 4) {
            Renderer::render_pass(*sc, f, first, 4, 2);
            if (adaptive && update_adaptive(f, s) == 0) break;
        }
        if (scale != 1.0) {  // the control: a brighter image
            std::vector<dvec3> sums = f.sums();
            for (dvec3& v : sums) v *= scale;
            f.restore(std::move(sums), f.counts(), 0);
        }
    }
    return films;
}

stats::ImageEstimate estimate(const std::deque<Film>& films) {
    std::vector<const Film*> ptrs;
    for (const Film& f : films) ptrs.push_back(&f);
    return stats::ImageEstimate::from_batches(ptrs);
}

}  // namespace

TEST(Adaptive, CornellImageAgreesWithAPlainRender) {
    // The adaptive image (fewer samples where the estimate says the pixel is converged) has the
    // plain render's mean: whole-image z-test per channel.
    const stats::ImageEstimate plain = estimate(cornell_batches(4, false));
    const std::deque<Film> adaptive = cornell_batches(4, true);
    uint64_t taken = 0;
    for (const Film& f : adaptive) taken += f.total_samples();
    EXPECT_LT(taken, uint64_t(4) * 32 * 32 * 64);  // the rule stopped some pixels early
    const double p = stats::whole_image_p(estimate(adaptive), plain);
    EXPECT_GT(p, 1e-3);
    // Control: the adaptive render 3% brighter is rejected.
    const double pc = stats::whole_image_p(estimate(cornell_batches(4, true, 1.03)), plain);
    EXPECT_LT(pc, 1e-4);
    std::printf("adaptive vs plain p = %.3g (%.1f spp on average); 3%% brighter p = %.3g\n", p,
                double(taken) / (4.0 * 32 * 32), pc);
}

// The viewer's estimate (film/pass_halves.h) on synthetic passes whose error is known: 256 x 256
// pixels of means mu in [0.5, 2], each pass one sample mu (1 + u), u uniform on [-1/2, 1/2], so the
// relative error of a pixel after K passes is 1 / sqrt(12 K). K = 31 (halves of 16 and 15 passes).
// e^2 is a mean over the N pixels of f (a - b)^2 / m^2, each term about true^2 chi^2_1, so its
// standard error is true^2 sqrt(2 / N); m in the denominator adds 3 / (12 K) to first order, which
// the expectation includes. z-test; control: an estimate 3% too high (in e) is rejected. Also a
// weighted film (exact values) and reset. Measured (fixed seed): z = -1.34, control z = -12.5.
TEST(Adaptive, PassHalvesEstimateTheImageError) {
    constexpr int kRes = 256, kPasses = 31;
    std::mt19937 rng(12345);
    std::uniform_real_distribution<double> u(-0.5, 0.5), mu_d(0.5, 2.0);
    std::vector<double> mu(size_t(kRes * kRes));
    for (double& m : mu) m = mu_d(rng);
    Film film(kRes, kRes);
    PassHalvesError est;
    EXPECT_LT(est.relative_rms(film), 0.0);
    for (int k = 0; k < kPasses; ++k) {
        for (int y = 0; y < kRes; ++y)
            for (int x = 0; x < kRes; ++x) film.add_sample(ivec2(x, y), vec3(float(mu[size_t(y * kRes + x)] * (1.0 + u(rng)))));
        est.add_pass(film, k);
        if (k == 0) {
            EXPECT_LT(est.relative_rms(film), 0.0);  // one half only
        }
    }
    EXPECT_EQ(est.passes(0), 16);
    EXPECT_EQ(est.passes(1), 15);
    const double truth2 = 1.0 / (12.0 * kPasses), expected2 = truth2 * (1.0 + 3.0 / (12.0 * kPasses));
    const double se2 = truth2 * std::sqrt(2.0 / double(kRes * kRes));
    const double e = est.relative_rms(film);
    const double z = (e * e - expected2) / se2, zc = (e * e - expected2 * 1.03 * 1.03) / se2;
    std::printf("  estimate %.5f, true %.5f: z = %.2f; 3%% high: z = %.2f\n", e, std::sqrt(truth2), z, zc);
    EXPECT_LT(std::abs(z), 4.0);
    EXPECT_GT(std::abs(zc), 4.0);
    // A weighted film (the tile-merge path): one sample per pixel centre per pass, so the same
    // numbers; the normaliser is the weight sum.
    Film w(16, 16);
    w.set_layout(true, 0);
    PassHalvesError ew;
    for (int k = 0; k < 2; ++k) {
        FilmTile t;
        t.reset(w, 0, 0, 16, 16, 0);
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) {
                t.sum_weight[size_t(y * 16 + x)] = dvec4(dvec3(k == 0 ? 2.0 : 4.0), 2.0);  // weight 2: values 1 and 2
                w.count_sample(ivec2(x, y));
            }
        w.merge(t);
        ew.add_pass(w, k);
    }
    // a = 1, b = 2, m = 1.5, f = 1/4: e = 0.5 / 1.5 everywhere.
    EXPECT_NEAR(ew.relative_rms(w), 0.5 / 1.5, 1e-12);
    // reset: no estimate until both halves have a pass again.
    ew.reset();
    EXPECT_LT(ew.relative_rms(w), 0.0);
}
