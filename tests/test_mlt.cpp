// Metropolis light transport: the primary-sample-space sampler (sampling/pss_sampler.h),
// PSSMLT over the path tracer and MMLT over BDPT (integrator/mlt/pssmlt.h, docs/mlt.md).
//
//  * Mlt_DetailedBalance: the real mutation code (PssSampler with Metropolis acceptance) on a toy
//    integrand of known shape over [0,1)^3 whose third coordinate is only drawn on half the domain
//    (lazy extension, catch-up after large steps). K independent chains each start exactly on the
//    target (rejection sampling of the sampler's own start states) and take T steps; a kernel that
//    keeps the target stationary leaves their final states target-distributed and independent,
//    so a chi-square on them is valid. Control: rejection without restoring the backup fails.
//  * Mlt_BootstrapMatchesPathTracer: b against the path tracer's mean image luminance (K seeds),
//    z-test; b 3% high is rejected.
//  * Mlt_AgreesWithPath*: PSSMLT on the Cornell box against the path tracer, and on the
//    mirror/glass box against BDPT (the path tracer's caustic estimate there is heavy-tailed: at a
//    test's budget its mean is typically low and its spread understated). MLT noise is correlated
//    between pixels, so each of K = 16 independent runs (seeds) gives one value per 16 x 16 block
//    and channel, and the test compares the across-run means (their spread gives the error) with
//    the reference's, Welch t-test Sidak-corrected over blocks x channels; a 3% brighter control is
//    rejected. Both scenes hide the emitters from the camera (cornell()). Many short chains: their
//    start states are independent, so the runs' spread falls faster than with few long chains.
//  * Mlt_Mmlt*: MMLT's bootstrap b and its image against the path tracer on the Cornell box at max
//    depth 5 (MMLT caps the depth), its image against BDPT on the mirror/glass box at depth 5, and
//    its determinism, the same ways.
//  * Mlt_Deterministic: 1 and 2 threads, one pass against several, and a pass that has to replay
//    the chains (after another render evicted them) give the same film bit for bit.
//  * Mlt_Xml: <integrator type="pssmlt"> and its parameters.
#include <gtest/gtest.h>
#include <cmath>
#include <cstring>
#include "core/error.h"
#include "film/filter.h"
#include "integrator/mlt/pssmlt.h"
#include "render/renderer.h"
#include "sampling/pss_sampler.h"
#include "scene/cornell.h"
#include "scene/loaders.h"
#include "support/run.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;

// ---- the toy chain ----------------------------------------------------------------------------

// f(u) = (0.1 + u0) (0.1 + 3 u1^2), times 2 u2 where u0 >= 0.5 (u2 drawn only there): its
// marginal on (u0, u1) is the separable product, and u2 given u0 >= 0.5 has density 2 u2.
struct ToyState {
    double u0 = 0, u1 = 0, u2 = -1;
    double f = 0;
};
ToyState toy_eval(PssSampler& s) {
    s.start_pixel_sample(ivec2(0), 0);
    ToyState x;
    const vec2 u = s.next_2d();
    x.u0 = u.x;
    x.u1 = u.y;
    x.f = (0.1 + x.u0) * (0.1 + 3 * x.u1 * x.u1);
    if (x.u0 >= 0.5) {
        x.u2 = s.next_1d();
        x.f *= 2 * x.u2;
    }
    return x;
}
constexpr double kToyMax = 1.1 * 3.1 * 2;

// Final states of K chains of T steps. restore: reject() on rejection (false: the broken control,
// which keeps the proposal's coordinates while the chain believes it stayed).
std::vector<ToyState> toy_chains(int K, int T, float sigma, float large, bool restore) {
    std::vector<ToyState> out;
    out.reserve(size_t(K));
    PCG32 pick(7, 11);
    uint64_t next = 0;
    for (int k = 0; k < K; ++k) {
        // A start state exactly on the target: the sampler's start states by rejection.
        PssSampler s;
        ToyState x;
        for (;;) {
            s = PssSampler(3, next++, sigma, large);
            x = toy_eval(s);
            if (double(pick.next_float()) * kToyMax < x.f) break;
        }
        s.reseed(3, uint64_t(k));
        PCG32 acc(uint64_t(k), 99);
        for (int t = 0; t < T; ++t) {
            s.start_iteration();
            const ToyState y = toy_eval(s);
            const double a = std::min(1.0, y.f / x.f);
            if (double(acc.next_float()) < a) {
                s.accept();
                x = y;
            } else if (restore) {
                s.reject();
            }
        }
        out.push_back(x);
    }
    return out;
}

// p-values of the (u0, u1) histogram (12 x 12) and of u2's (8 bins, states with u0 >= 0.5).
std::pair<double, double> toy_chi2(const std::vector<ToyState>& xs) {
    const int n = 12, m = 8;
    std::vector<double> obs(n * n, 0.0), exp(n * n, 0.0), obs2(m, 0.0), exp2(m, 0.0);
    double n_hi = 0;
    for (const ToyState& x : xs) {
        const int i = std::min(n - 1, int(x.u0 * n)), j = std::min(n - 1, int(x.u1 * n));
        obs[size_t(j * n + i)] += 1;
        if (x.u0 >= 0.5) {
            obs2[size_t(std::min(m - 1, int(x.u2 * m)))] += 1;
            n_hi += 1;
        }
    }
    auto Fx = [](double a, double b) { return 0.1 * (b - a) + 0.5 * (b * b - a * a); };
    auto Fy = [](double a, double b) { return 0.1 * (b - a) + (b * b * b - a * a * a); };
    const double total = Fx(0, 1) * Fy(0, 1);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            exp[size_t(j * n + i)] =
                double(xs.size()) * Fx(double(i) / n, double(i + 1) / n) * Fy(double(j) / n, double(j + 1) / n) / total;
    for (int k = 0; k < m; ++k) exp2[size_t(k)] = n_hi * (sqr(double(k + 1) / m) - sqr(double(k) / m));
    const ChiSquareResult r1 = chi_square_counts(obs, exp), r2 = chi_square_counts(obs2, exp2);
    std::printf("  (u0,u1): %s\n  u2: %s\n", r1.describe().c_str(), r2.describe().c_str());
    return {r1.p_value, r2.p_value};
}

// ---- images -----------------------------------------------------------------------------------

// hide_emitters: the lamp seen directly would hold most of the chains' time and of b's variance
// (its pixels are exact in both estimators anyway), and the test's budget is better spent on the
// light the walls carry.
std::shared_ptr<const Scene> cornell(int res, int max_depth = -1) {
    SceneDescription d = make_cornell_box();
    d.settings.width = d.settings.height = res;
    d.settings.max_depth = max_depth;
    d.settings.integrator.hide_emitters = true;
    return build_scene(std::move(d), "auto");
}

std::shared_ptr<const Scene> with(const Scene& scene, IntegratorType type, uint64_t seed, const MltParams* m = nullptr) {
    SceneParams p = scene.params();
    p.settings.integrator.type = type;
    p.settings.seed = seed;
    if (m) p.settings.integrator.mlt = *m;
    return scene.with_params(p);
}

// Per run, the mean of each block x block tile per channel; across the K runs their mean and the
// variance of that mean.
struct BlockRuns {
    std::vector<RunningStats> v;  // tile-major, 3 channels
    int tiles = 0;
};
void add_run(BlockRuns& br, const Film& f, int block) {
    const int tx = (f.width() + block - 1) / block, ty = (f.height() + block - 1) / block;
    br.tiles = tx * ty;
    if (br.v.empty()) br.v.resize(size_t(br.tiles) * 3);
    for (int t = 0; t < br.tiles; ++t) {
        dvec3 s(0.0);
        int n = 0;
        for (int y = (t / tx) * block; y < std::min(f.height(), (t / tx + 1) * block); ++y)
            for (int x = (t % tx) * block; x < std::min(f.width(), (t % tx + 1) * block); ++x, ++n) s += dvec3(f.pixel(x, y));
        s /= double(n);
        for (int c = 0; c < 3; ++c) br.v[size_t(t * 3 + c)].add(s[c]);
    }
}
BlockRuns runs(const Scene& scene, IntegratorType type, int K, int spp, int block, uint64_t base,
               const MltParams* m = nullptr) {
    BlockRuns br;
    for (int k = 0; k < K; ++k) {
        Film f(scene.settings.width, scene.settings.height);
        Renderer::render_pass(*with(scene, type, base + uint64_t(k) + 1, m), f, 0, spp, 2);
        add_run(br, f, block);
    }
    return br;
}
// Smallest Sidak-adjusted p of the per-tile Welch t-tests of a (scaled by `scale`) against b.
double compare_blocks(const BlockRuns& a, const BlockRuns& b, double scale, double* max_t = nullptr) {
    double p_min = 1, tmax = 0;
    int tests = 0;
    for (size_t i = 0; i < a.v.size(); ++i) {
        const double ma = a.v[i].mean() * scale, mb = b.v[i].mean();
        const double va = a.v[i].variance() * scale * scale / double(a.v[i].count()),
                     vb = b.v[i].variance() / double(b.v[i].count());
        if (va + vb <= 0) continue;
        const double t = (ma - mb) / std::sqrt(va + vb);
        // Welch-Satterthwaite degrees of freedom.
        const double na = double(a.v[i].count()), nb = double(b.v[i].count());
        const double dof = sqr(va + vb) / (sqr(va) / (na - 1) + sqr(vb) / (nb - 1));
        p_min = std::min(p_min, student_t_two_sided_p(t, dof));
        tmax = std::max(tmax, std::abs(t));
        ++tests;
    }
    if (max_t) *max_t = tmax;
    return sidak_adjust(p_min, tests);
}

void agreement(const Scene& scene, const MltParams& m, int K, int mlt_spp, int ref_spp, int block,
               IntegratorType ref = IntegratorType::Path, IntegratorType type = IntegratorType::Pssmlt) {
    const BlockRuns mlt = runs(scene, type, K, mlt_spp, block, 100, &m);
    const BlockRuns pt = runs(scene, ref, K, ref_spp, block, 200);
    double t = 0, t_ctl = 0;
    const double p = compare_blocks(mlt, pt, 1.0, &t);
    const double p_ctl = compare_blocks(mlt, pt, 1.03, &t_ctl);
    const MltStats s = pssmlt_stats();
    std::printf("  mlt vs reference: %d tiles x 3, family p = %.3g (max |t| %.2f); 3%% brighter: p = %.3g (max |t| %.2f)\n"
                "  acceptance: small %.3f, large %.3f; b = %.5g +- %.2g\n",
                mlt.tiles, p, t, p_ctl, t_ctl, double(s.small_accepted) / double(std::max<uint64_t>(1, s.small_proposed)),
                double(s.large_accepted) / double(std::max<uint64_t>(1, s.large_proposed)), s.b, s.b_std_error);
    EXPECT_GE(p, kAlpha);
    EXPECT_LT(p_ctl, kAlpha) << "the 3% brighter control is not rejected";
}

bool films_equal(const Film& a, const Film& b) {
    if (a.splat_sums().size() != b.splat_sums().size() || a.splat_paths() != b.splat_paths()) return false;
    if (!a.splat_sums().empty() &&
        std::memcmp(a.splat_sums().data(), b.splat_sums().data(), a.splat_sums().size() * sizeof(dvec3)) != 0)
        return false;
    return a.counts() == b.counts();
}

}  // namespace

TEST(Mlt, DetailedBalance) {
    const int K = 40000, T = 24;
    const auto [p1, p2] = toy_chi2(toy_chains(K, T, 0.05f, 0.3f, true));
    const double level = sidak_level(kAlpha, 2);
    EXPECT_GE(p1, level);
    EXPECT_GE(p2, level);
    // Small steps only: the chain still keeps the target (a different kernel, the same balance).
    const auto [q1, q2] = toy_chi2(toy_chains(K, T, 0.05f, 0.f, true));
    EXPECT_GE(q1, level);
    EXPECT_GE(q2, level);
    // Control: rejected proposals not restored.
    const auto [c1, c2] = toy_chi2(toy_chains(K, T, 0.05f, 0.3f, false));
    EXPECT_LT(std::min(c1, c2), level) << "a chain that keeps rejected proposals passed";
}

namespace {
std::shared_ptr<const Scene> mirror_glass(int res, int max_depth = -1) {
    SceneDescription d = load_scene(std::string(CANDELA_SOURCE_DIR) + "/scenes/cornell-materials/mirror-glass.xml");
    d.settings.width = d.settings.height = res;
    d.settings.max_depth = max_depth;
    d.settings.filter = box_filter();
    d.settings.integrator.hide_emitters = true;  // as cornell()
    return build_scene(std::move(d), "auto");
}

void bootstrap_agreement(const Scene& scene, int B, IntegratorType ref, int K, int spp,
                         IntegratorType type = IntegratorType::Pssmlt) {
    MltParams m;
    m.bootstrap_samples = B;
    const int w = scene.settings.width, h = scene.settings.height;
    const MltStats bs = pssmlt_bootstrap(*with(scene, type, 5, &m), w, h, 2);
    RunningStats pt;
    for (int k = 0; k < K; ++k) {
        Film f(w, h);
        Renderer::render_pass(*with(scene, ref, uint64_t(k) + 1), f, 0, spp, 2);
        double s = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) s += double(luminance(f.pixel(x, y)));
        pt.add(s / double(w * h));
    }
    const MeanTest z = z_test(bs.b, std::sqrt(sqr(bs.b_std_error) + sqr(pt.std_error())), pt.mean());
    const MeanTest c = z_test(bs.b * 1.03, std::sqrt(sqr(bs.b_std_error * 1.03) + sqr(pt.std_error())), pt.mean());
    std::printf("  b = %.5f +- %.5f, reference %.5f +- %.5f: %s\n  control (b 3%% high): %s\n", bs.b, bs.b_std_error,
                pt.mean(), pt.std_error(), z.describe().c_str(), c.describe().c_str());
    EXPECT_GE(z.p_value, kAlpha);
    EXPECT_LT(c.p_value, kAlpha);
}
}  // namespace

TEST(Mlt, BootstrapMatchesPathTracer) {
    bootstrap_agreement(*cornell(32), 200000, IntegratorType::Path, 12, 16);
}

TEST(Mlt, MmltBootstrapMatchesPathTracer) {
    bootstrap_agreement(*cornell(32, 5), 200000, IntegratorType::Path, 12, 16, IntegratorType::Mmlt);
}

TEST(Mlt, MmltAgreesWithPathOnTheCornellBox) {
    auto scene = cornell(32, 5);
    MltParams m;
    m.bootstrap_samples = 100000;  // b's spread per path is larger than pssmlt's (one strategy x their count)
    m.chains = 2048;
    agreement(*scene, m, 16, 48, 32, 16, IntegratorType::Path, IntegratorType::Mmlt);
}

TEST(Mlt, AgreesWithPathOnTheCornellBox) {
    auto scene = cornell(32);
    MltParams m;
    m.bootstrap_samples = 30000;
    m.chains = 2048;
    agreement(*scene, m, 16, 32, 32, 16);
}

TEST(Mlt, AgreesWithPathOnTheMirrorGlassBox) {
    auto scene = mirror_glass(32);
    MltParams m;
    m.bootstrap_samples = 60000;
    m.chains = 4096;
    agreement(*scene, m, 16, 48, 16, 16, IntegratorType::Bdpt);
}

// MMLT on a specular scene: its chains move between BDPT's strategies for each path length, and
// paths through the mirror and the glass have delta vertices where no strategy connects. Max
// depth 5, against BDPT at the same depth: MMLT caps unbounded depths at 12, and past 12 scattering
// events this box (albedos up to 0.7) still has light of the order of 0.7^12 = 1% (an estimate). 160 mutations per pixel over 16384
// chains (10 per chain): the top blocks' spread across runs falls with the mutations (1.2% of the
// block at 48 per pixel over 4096 chains, where the 3% control was not rejected, p = 0.25), the
// bottom blocks' (the glass block's caustics, 3-5%) with the bootstrap's size. Measured over three
// seed bases (runs +0, +1000, +2000): family p 0.62, 0.91, 0.07 (max |t| 1.8, 1.4, 3.1), the 3%
// brighter control rejected at p = 2.6e-4, 3.0e-4, 2.5e-5. About 20 s of CPU.
TEST(Mlt, MmltAgreesWithBdptOnTheMirrorGlassBox) {
    auto scene = mirror_glass(32, 5);
    MltParams m;
    m.bootstrap_samples = 100000;
    m.chains = 16384;
    agreement(*scene, m, 16, 160, 16, 16, IntegratorType::Bdpt, IntegratorType::Mmlt);
}

namespace {
void determinism(IntegratorType type) {
    auto scene = cornell(24, type == IntegratorType::Mmlt ? 4 : -1);
    MltParams m;
    m.bootstrap_samples = 4000;
    m.chains = 37;  // not a divisor of the pixel count: uneven shares
    auto sc = with(*scene, type, 9, &m);
    Film one(24, 24), two(24, 24), split(24, 24), replayed(24, 24);
    Renderer::render_pass(*sc, one, 0, 4, 1);
    Renderer::render_pass(*sc, two, 0, 4, 2);
    EXPECT_TRUE(films_equal(one, two)) << "1 and 2 threads differ";
    Renderer::render_pass(*sc, split, 0, 1, 2);
    Renderer::render_pass(*sc, split, 1, 3, 2);
    EXPECT_TRUE(films_equal(one, split)) << "1 + 3 samples differ from 4";
    // Another render in between evicts the chains: the next pass rebuilds and replays them.
    Renderer::render_pass(*sc, replayed, 0, 2, 2);
    Film other(24, 24);
    Renderer::render_pass(*with(*scene, type, 10, &m), other, 0, 1, 2);
    Renderer::render_pass(*sc, replayed, 2, 2, 2);
    EXPECT_TRUE(films_equal(one, replayed)) << "a replayed pass differs";
    EXPECT_FALSE(films_equal(one, other));
    EXPECT_EQ(one.splat_paths(), uint64_t(4 * 24 * 24));
    EXPECT_EQ(one.nonfinite_count(), 0u);
}
}  // namespace

TEST(Mlt, Deterministic) { determinism(IntegratorType::Pssmlt); }
TEST(Mlt, MmltDeterministic) { determinism(IntegratorType::Mmlt); }

TEST(Mlt, Xml) {
    using namespace candela::test;
    const std::string d = temp_dir("mlt-xml");
    auto scene_with = [&](const std::string& integrator) {
        return "<scene version=\"3.0.0\">" + integrator +
               "<sensor type=\"perspective\"><sampler type=\"independent\"><integer name=\"sample_count\" value=\"8\"/>"
               "</sampler><film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/>"
               "<integer name=\"height\" value=\"8\"/></film></sensor>"
               "<shape type=\"sphere\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape></scene>";
    };
    write_text(d + "/a.xml", scene_with("<integrator type=\"pssmlt\"><integer name=\"max_depth\" value=\"4\"/>"
                                        "<integer name=\"bootstrap_samples\" value=\"500\"/><integer name=\"chains\" value=\"7\"/>"
                                        "<integer name=\"mutations_per_pixel\" value=\"33\"/><float name=\"sigma\" value=\"0.02\"/>"
                                        "<float name=\"large_step_probability\" value=\"0.5\"/></integrator>"));
    SceneDescription s = load_scene(d + "/a.xml");
    EXPECT_EQ(s.settings.integrator.type, IntegratorType::Pssmlt);
    EXPECT_EQ(s.settings.max_depth, 3);
    EXPECT_EQ(s.settings.integrator.mlt.bootstrap_samples, 500);
    EXPECT_EQ(s.settings.integrator.mlt.chains, 7);
    EXPECT_EQ(s.settings.spp, 33);  // mutations_per_pixel is the sample count, the sensor's notwithstanding
    EXPECT_FLOAT_EQ(s.settings.integrator.mlt.sigma, 0.02f);
    EXPECT_FLOAT_EQ(s.settings.integrator.mlt.large_step_probability, 0.5f);
    write_text(d + "/b.xml", scene_with("<integrator type=\"pssmlt\"><float name=\"sigma\" value=\"0\"/></integrator>"));
    EXPECT_THROW(load_scene(d + "/b.xml"), Error);
    write_text(d + "/c.xml", scene_with("<integrator type=\"pssmlt\"/>"));
    SceneDescription c = load_scene(d + "/c.xml");
    EXPECT_EQ(c.settings.spp, 8);
    EXPECT_EQ(c.settings.integrator.mlt.chains, 1000);
    write_text(d + "/m.xml", scene_with("<integrator type=\"mmlt\"><integer name=\"max_depth\" value=\"6\"/>"
                                        "<integer name=\"chains\" value=\"9\"/></integrator>"));
    SceneDescription mm = load_scene(d + "/m.xml");
    EXPECT_EQ(mm.settings.integrator.type, IntegratorType::Mmlt);
    EXPECT_EQ(mm.settings.max_depth, 5);
    EXPECT_EQ(mm.settings.integrator.mlt.chains, 9);
}
