// BDPT and the light tracer against the path tracer on the repository's scenes (issue 15, docs/bdpt.md
// "Tests"): the Veach MIS scene, the caustics scene, the mirror/glass Cornell box, an envmap and a
// thin-lens camera. Reduced resolutions; 8 batches per integrator with independent seeds; block
// z-test (4 x 4 blocks) and whole-image z-test, Sidak-corrected over the depths of one test, with
// the 3% brighter control where the budget gives the power for it (otherwise the comment says
// which shared control covers the estimator). Past what the path tracer can referee: BDPT and the
// light tracer against committed Mitsuba 3 references (its path and ptracer integrators).
#include <gtest/gtest.h>
#include "render/renderer.h"
#include "scene/loaders.h"
#include "support/agreement.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;
using namespace candela::test;

namespace {

constexpr double kAlpha = 0.01;

std::shared_ptr<const Scene> load(const std::string& rel, Defines defines) {
    return build_scene(load_scene(std::string(CANDELA_SOURCE_DIR) + "/" + rel, defines));
}

// One comparison of `a` against `b` (integrator type, spp), both on `scene` at max depth `depth`.
// hide_emitters in both and the stratified sampler: the lamps seen directly cover a few pixels
// partly, which otherwise dominates the whole image's noise alike in every integrator.
void agree(const Scene& scene, int depth, IntegratorType a, int spp_a, IntegratorType b, int spp_b, uint64_t seed,
           const std::string& what, int tests, bool control) {
    SceneParams p = scene.params();
    p.settings.max_depth = depth;
    p.settings.integrator.hide_emitters = true;
    p.settings.sampler.type = SamplerType::Stratified;
    p.settings.integrator.type = a;
    ImageEstimate ea = render_batches(scene, p, 8, spp_a, seed);
    p.settings.integrator.type = b;
    ImageEstimate eb = render_batches(scene, p, 8, spp_b, seed + 100);
    expect_agreement(ea, eb, what, tests, control, kAlpha);
}

std::string depth_name(int d) { return d < 0 ? "unbounded" : "depth " + std::to_string(d); }

}  // namespace

// The Veach MIS scene (glossy plates of four roughnesses, four spherical lights), 32 x 22: at
// depth 1 what the path tracer's MIS is about; deeper, the plates' interreflections with the floor.
// The smallest lamp (radiance 800) is dimmed 50x here: its highlights on the plates are sub-pixel
// at this size, and their pixel coverage alone made the whole image's mean 5-15% noisy at this
// budget in both integrators alike (measured). Dimmed it is still 2-5%: no 3% control here; the
// Cornell box tests' controls (same comparison, same estimator) are rejected at every depth.
std::shared_ptr<const Scene> veach() {
    auto sc = load("scenes/veach-mis/scene.xml", {{"width", "32"}, {"height", "22"}});
    SceneParams p = sc->params();
    for (AreaEmitter& e : p.emitters)
        if (e.radiance.x > 100.f) e.radiance *= 0.02f;
    return sc->with_params(p);
}

TEST(Bdpt, AgreesWithPathOnTheVeachMisScene) {
    auto sc = veach();
    const std::vector<int> depths = {1, 2, 5, -1};
    for (int d : depths)
        agree(*sc, d, IntegratorType::Bdpt, 32, IntegratorType::Path, 64, 1000 + 10 * uint64_t(d + 1),
              "veach-mis " + depth_name(d), int(depths.size()), false);
}

// The caustics scene (a glass sphere and a diamond on a diffuse floor under a small lamp), 24 x 18,
// depth 1. Deeper, the caustics (lamp -> glass -> floor) are rare, bright events for the path
// tracer (its floor points must hit the small lamp through the glass by BSDF sampling): at depth
// 2, 5 and unbounded the blocks under the sphere differed from BDPT's by z = 4-5 (up to 20% of the
// blocks failing), the variance estimate of 8 batches being unreliable there; at 16k spp (path)
// against 2k spp (BDPT) those blocks still differ by up to 2x either way. The path tracer is no
// reference for them at a test's budget (docs/bdpt.md, "Tests").
// No 3% control: the lamp's sub-pixel reflections in the sphere and the diamond make the whole
// image's mean 1.5-5% noisy in both integrators alike; the comparison code and the estimator are
// the Cornell box tests', whose 3% controls are rejected at every depth (p <= 1.4e-10).
TEST(Bdpt, AgreesWithPathOnTheCausticsScene) {
    auto sc = load("scenes/caustics/scene.xml", {{"width", "24"}, {"height", "18"}});
    const std::vector<int> depths = {1};
    for (int d : depths)
        agree(*sc, d, IntegratorType::Bdpt, 32, IntegratorType::Path, 128, 1200 + 10 * uint64_t(d + 1),
              "caustics " + depth_name(d), int(depths.size()), false);
}

// The caustics scene past depth 1, against committed Mitsuba 3 references: there the path tracer is
// no reference (its caustics through the glass come from rare BSDF-sampled paths that hit the small
// light; 16k-spp path renders still differed from BDPT by up to 2x in the blocks under the sphere).
// tests/data/caustics24_{d2,d5,inf}_{mean,var}.exr: 16 batches x 4096 spp of Mitsuba 3.9.1
// llvm_ad_rgb, 24 x 18, made by
//   $PY tests/data/make_reference.py scenes/caustics/scene.xml --res 0 --batches 16 --spp 4096
//       --out tests/data/caustics24_d2 -D width=24 -D height=18 -D max_depth=3   (6 and -1)
// Emitters visible and the independent sampler, as Mitsuba rendered them. 512 spp per batch: at 64
// the caustic's rare bright paths made the batch variance a poor estimate (a block at z = 11.6 with
// the image mean within 1%); at 512, seed bases 1700, 2700, 3700 gave max |z| 2.3-2.8 at depths 2
// and unbounded and 2.4-3.4 at depth 5 (Sidak p >= 0.06), and the 3% brighter control is rejected
// at every depth (p 1e-22 at depth 2, 3e-8 at depth 5, 1e-8 unbounded). BDPT renders about 36k
// samples per second per thread here, so each depth is 3.5M samples, 50-100 s on 2 threads: one
// test per depth lets ctest run them beside other tests. Each keeps the Sidak level of the family
// of the three depths.
namespace {

void caustics_vs_mitsuba(int depth, const std::string& name) {
    auto sc = load("scenes/caustics/scene.xml", {{"width", "24"}, {"height", "18"}});
    SceneParams p = sc->params();
    p.settings.max_depth = depth;
    p.settings.integrator.type = IntegratorType::Bdpt;
    const ImageEstimate ref = ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/caustics24_" + name);
    ASSERT_EQ(ref.width, 24);
    ImageEstimate e = render_batches(*sc, p, 16, 512, 1700 + 10 * uint64_t(depth + 1));
    expect_agreement(e, ref, "caustics vs Mitsuba, " + depth_name(depth), 3, true);
}

}  // namespace

TEST(Bdpt, AgreesWithMitsubaOnTheCausticsSceneAtDepth2) { caustics_vs_mitsuba(2, "d2"); }
TEST(Bdpt, AgreesWithMitsubaOnTheCausticsSceneAtDepth5) { caustics_vs_mitsuba(5, "d5"); }
TEST(Bdpt, AgreesWithMitsubaOnTheCausticsSceneUnbounded) { caustics_vs_mitsuba(-1, "inf"); }

// The mirror/glass Cornell box of scenes/ (Bdpt.AgreesWithPathOnTheSpecularBox has depth 1).
TEST(Bdpt, AgreesWithPathOnTheMirrorGlassBox) {
    auto sc = load("scenes/cornell-materials/mirror-glass.xml", {{"res", "16"}});
    const std::vector<int> depths = {2, -1};
    for (int d : depths)
        agree(*sc, d, IntegratorType::Bdpt, 64, IntegratorType::Path, 192, 1400 + 10 * uint64_t(d + 1),
              "mirror-glass " + depth_name(d), int(depths.size()), true);
}

// An envmap (an infinite light with a small bright sun): escaped camera paths (s = 0) and light
// paths leaving the scene's bounding disk.
TEST(Bdpt, AgreesWithPathUnderAnEnvmap) {
    auto sc = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/envmap.xml", {{"res", "16"}}));
    const std::vector<int> depths = {2, -1};
    for (int d : depths)
        agree(*sc, d, IntegratorType::Bdpt, 64, IntegratorType::Path, 128, 1500 + 10 * uint64_t(d + 1),
              "envmap " + depth_name(d), int(depths.size()), true);
}

// The thin-lens camera (a crop window of its film, focused on the red cube): the lens is sampled by
// the camera subpath and by the t = 1 connections.
TEST(Bdpt, AgreesWithPathThroughAThinLens) {
    auto sc = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/cameras/thinlens.xml", {}));
    const std::vector<int> depths = {2};
    for (int d : depths)
        agree(*sc, d, IntegratorType::Bdpt, 16, IntegratorType::Path, 32, 1600, "thin lens " + depth_name(d), 1, true);
}

TEST(Ptracer, AgreesWithPathThroughAThinLens) {
    auto sc = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/cameras/thinlens.xml", {}));
    agree(*sc, 2, IntegratorType::Ptracer, 64, IntegratorType::Path, 32, 1700, "thin lens depth 2", 1, true);
}

// ---- the light tracer against Mitsuba 3's ptracer ----------------------------------------------
// A pure light tracer cannot see what the camera sees through a delta surface (camera -> glass or
// mirror -> lamp has no vertex it can connect to the camera), so on the caustics and mirror/glass
// scenes its expected image is not the path tracer's: the reference is Mitsuba 3's `ptracer` on
// the same XML, which has the same blind spot. tests/data/ptracer_<scene>_{d2,inf}_{mean,var}.exr:
// 16 batches x 4096 spp of Mitsuba 3.9.1 llvm_ad_rgb, made by
//   $PY tests/data/make_reference.py SCENE --integrator ptracer --batches 16 --spp 4096
//       --out tests/data/ptracer_<scene>_d2 -D max_depth=3   (and max_depth=-1 for _inf)
// with --res 0 -D width=24 -D height=18 (caustics) and --res 16 (mirror-glass). candela's depth 2 is
// Mitsuba's max_depth 3. Both as the XML says: the independent sampler, emitters visible (Mitsuba's
// ptracer splats them by sampling a point on an emitter and connecting it to the camera, as
// candela's does), Russian roulette from rr_depth (5). The emitter choice differs (Mitsuba picks
// emitters uniformly, candela by power): the same expectation, other noise. 16 batches x 128 spp,
// depth 2 and unbounded, Sidak over the two; max |z| over three seed bases (+0, +1000, +2000),
// depth 2 / unbounded: caustics 2.0 / 2.7, 2.3 / 2.1, 1.9 / 2.3, control (3% brighter) p <= 1e-22;
// mirror/glass 2.9 / 2.1, 2.5 / 1.5, 1.9 / 1.8, control p <= 1e-148. At 64 spp per batch
// (mirror/glass 24 x 24) one seed base gave a block at z = 4.0 (family p 0.006, at the level's
// edge): the rare bright caustic paths again, too few per batch for the spread of the batch means.
// The Veach MIS scene is not tested (docs/bdpt.md, "Tests": at 16 x 512 spp its whole-image mean
// is still 1.5% noisy, the 3% control not rejected).
namespace {

void ptracer_vs_mitsuba(const std::string& rel, Defines defines, const std::string& ref, int width, uint64_t base) {
    auto sc = load(rel, defines);
    const std::vector<std::pair<int, std::string>> depths = {{2, "d2"}, {-1, "inf"}};
    for (const auto& [d, name] : depths) {
        SceneParams p = sc->params();
        p.settings.max_depth = d;
        p.settings.integrator.type = IntegratorType::Ptracer;
        const ImageEstimate mi = ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/" + ref + "_" + name);
        ASSERT_EQ(mi.width, width);
        ImageEstimate e = render_batches(*sc, p, 16, 128, base + 10 * uint64_t(d + 1));
        expect_agreement(e, mi, ref + " " + depth_name(d), int(depths.size()), true);
    }
}

}  // namespace

TEST(Ptracer, AgreesWithMitsubaPtracerOnTheCausticsScene) {
    ptracer_vs_mitsuba("scenes/caustics/scene.xml", {{"width", "24"}, {"height", "18"}}, "ptracer_caustics24", 24, 1800);
}

TEST(Ptracer, AgreesWithMitsubaPtracerOnTheMirrorGlassBox) {
    ptracer_vs_mitsuba("scenes/cornell-materials/mirror-glass.xml", {{"res", "16"}}, "ptracer_mirrorglass16", 16, 2000);
}
