// The light tracer (integrator/ptracer/, Mitsuba 3's ptracer) and the film's splats.
//
//  * Ptracer_AgreesWithPath: the built-in Cornell box at max depth 0, 1, 2, 5 and unbounded, light
//    tracing against path tracing, independent seeds (batch means: 8 batches each), block z-test
//    (4 x 4 pixel blocks) and a whole-image z-test per channel, at alpha 0.01 Sidak-corrected over
//    the depths. The light tracer is noisy here (the whole-image mean has a relative standard error
//    of about 2-4% per depth at this budget), so this test has no 3% control of its own: the
//    controls that show the light tracer's bias would be caught are those of the diffuse wall
//    (3% brighter rejected, p = 7e-6) and of the furnace (3% off rejected, p < 1e-4).
//  * Ptracer_VisibleDiffuseWall: a diffuse wall lit by a square lamp outside the view, where
//    t = 1 alone is a whole estimator: the same tests against the path tracer.
//  * Ptracer_Furnace: the closed diffuse sphere lit by its own emission (tests/test_furnace.cpp):
//    every pixel's exact value is Le (1 - a^(d+1)) / (1 - a); z-test over the pixel means with a
//    3%-off control rejected at the same level.
//  * Ptracer_FilteredSplatsAgreeWithPathAtSharpEdges: the splats through the film's gaussian and
//    Mitchell filters against the path tracer's camera samples (support/agreement.h).
//  * Determinism: 1, 2 and 3 threads, and 4 passes of 1 spp against 1 pass of 4, give the same
//    film bit for bit (splats included), under the box and the gaussian filter; checkpoint and resume through the program (--integrator
//    ptracer) end bit for bit as the uninterrupted render.
//  * XML: <integrator type="ptracer"> with Mitsuba's max_depth, and a ptracer inside aov refused.
#include <gtest/gtest.h>
#include <cstring>
#include "core/error.h"
#include "film/image_io.h"
#include "render/renderer.h"
#include "scene/cornell.h"
#include "scene/loaders.h"
#include "support/agreement.h"
#include "support/run.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;
using namespace candela::test;

namespace {

constexpr double kAlpha = 0.01;

ImageEstimate batches(const Scene& scene, SceneParams p, IntegratorType type, int K, int spp, uint64_t base) {
    p.settings.integrator.type = type;
    return render_batches(scene, p, K, spp, base);
}

void compare(const ImageEstimate& lt, const ImageEstimate& pt, const std::string& what, int tests, bool control) {
    expect_agreement(lt, pt, what, tests, control, kAlpha);
}

std::shared_ptr<const Scene> cornell(int res) {
    SceneDescription d = make_cornell_box();
    d.settings.width = d.settings.height = res;
    return build_scene(std::move(d), "auto");
}

}  // namespace

TEST(Ptracer, AgreesWithPathOnTheCornellBox) {
    auto sc = cornell(16);
    const std::vector<int> depths = {0, 1, 2, 5, -1};
    for (int d : depths) {
        SceneParams p = sc->params();
        p.settings.max_depth = d;
        ImageEstimate lt = batches(*sc, p, IntegratorType::Ptracer, 8, d == 0 ? 16 : 64, 100 + 10 * uint64_t(d + 1));
        ImageEstimate pt = batches(*sc, p, IntegratorType::Path, 8, d == 0 ? 16 : 32, 200 + 10 * uint64_t(d + 1));
        compare(lt, pt, "cornell depth " + std::to_string(d), int(depths.size()), false);
    }
}

// The smooth-shaded ball light (support/agreement.h) against the path tracer with BSDF sampling
// alone, depth 1 (the walls lit by the ball) and 2. Until 2026-12-07 the light paths started with
// the shading normal's cosine (and the ball seen directly was weighted by it), where radiance is
// per unit of projected GEOMETRIC area, as the rays that hit the ball see it.
TEST(Ptracer, AgreesWithBsdfSamplingOnASmoothEmitter) {
    auto sc = build_scene(smooth_ball_description(16), "auto");
    const std::vector<int> depths = {1, 2};
    for (int d : depths) {
        SceneParams p = sc->params();
        p.settings.max_depth = d;
        p.settings.sampler.type = SamplerType::Stratified;
        ImageEstimate lt = batches(*sc, p, IntegratorType::Ptracer, 8, 64, 1300 + uint64_t(d));
        p.settings.sampling = SamplingMode::Bsdf;
        ImageEstimate pt = batches(*sc, p, IntegratorType::Path, 8, 128, 1400 + uint64_t(d));
        compare(lt, pt, "smooth ball depth " + std::to_string(d), int(depths.size()), true);
    }
}

// The lamp with tilted vertex normals (support/agreement.h), depth 1: the light tracer's light
// paths and the lamp seen directly, against BSDF sampling alone. With the shading normal's cosine
// (before 2026-12-07) the lamp's power went where its normals point: the image was 10-20% off.
TEST(Ptracer, AgreesWithBsdfSamplingOnATiltedNormalLamp) {
    auto sc = build_scene(tilted_lamp_description(16), "auto");
    SceneParams p = sc->params();
    p.settings.max_depth = 1;
    p.settings.sampler.type = SamplerType::Stratified;
    ImageEstimate lt = batches(*sc, p, IntegratorType::Ptracer, 8, 64, 1500);
    p.settings.sampling = SamplingMode::Bsdf;
    ImageEstimate pt = batches(*sc, p, IntegratorType::Path, 8, 128, 1600);
    compare(lt, pt, "tilted-normal lamp depth 1", 1, true);
}

// A 4 x 4 diffuse wall at z = 0 facing +z, lit by a 1 x 1 lamp facing it from z = 2 (off to the
// side, out of view), seen by a camera at z = 4 looking at the wall's centre.
TEST(Ptracer, VisibleDiffuseWall) {
    SceneDescription d;
    d.source = "<diffuse wall>";
    d.materials.push_back({"wall", DiffuseBsdf{vec3(0.7f, 0.5f, 0.3f)}, false});
    d.materials.push_back({"lamp", DiffuseBsdf{vec3(0.f)}, false});
    d.emitters.push_back({vec3(8.f)});
    d.add_shape("wall", {vec3(-2, -2, 0), vec3(2, -2, 0), vec3(2, 2, 0), vec3(-2, 2, 0)}, {}, {uvec3(0, 1, 2), uvec3(0, 2, 3)},
                0, -1);
    // Centred at (2.5, 0, 2), tilted to face the wall's centre.
    const vec3 c(2.5f, 0.f, 2.f), n = glm::normalize(-c), t = glm::normalize(glm::cross(n, vec3(0, 1, 0))),
               b = glm::cross(t, n);
    const vec3 q[4] = {c - 0.5f * t - 0.5f * b, c + 0.5f * t - 0.5f * b, c + 0.5f * t + 0.5f * b, c - 0.5f * t + 0.5f * b};
    const bool faces = glm::dot(glm::cross(q[1] - q[0], q[2] - q[0]), n) > 0.f;
    d.add_shape("lamp", {q[0], q[1], q[2], q[3]}, {}, faces ? std::vector<uvec3>{uvec3(0, 1, 2), uvec3(0, 2, 3)}
                                                           : std::vector<uvec3>{uvec3(0, 2, 1), uvec3(0, 3, 2)}, 1, 0);
    d.camera.to_world = look_at(vec3(0.f, 0.f, 4.f), vec3(0.f), vec3(0.f, 1.f, 0.f));
    d.camera.fov_deg = 40.f;
    d.settings.width = d.settings.height = 24;
    auto sc = build_scene(std::move(d), "auto");
    ImageEstimate lt = batches(*sc, sc->params(), IntegratorType::Ptracer, 8, 32, 300);
    ImageEstimate pt = batches(*sc, sc->params(), IntegratorType::Path, 8, 32, 400);
    compare(lt, pt, "diffuse wall", 1, true);
}

// The light tracer's splats go through the film's filter (issue 41): a lit wall's edge, which the
// gaussian and the Mitchell filter spread over the pixels around, against the path tracer's camera
// samples under the same filter. Before, every splat landed in its pixel (a box) and the blocks
// along the edge were rejected (the control).
TEST(Ptracer, FilteredSplatsAgreeWithPathAtSharpEdges) { expect_filtered_splats_agree(IntegratorType::Ptracer, 32, 1700); }

TEST(Ptracer, Furnace) {
    const std::vector<int> depths = {1, -1};
    const double level = sidak_level(kAlpha, int(depths.size()) * 3);
    for (int depth : depths) {
        FurnaceConfig c;
        c.integrator = IntegratorType::Ptracer;
        c.max_depth = depth;
        c.seed = uint64_t(7 + depth);
        c.spp = 384;
        expect_furnace_exact(c, level);
    }
}

// The box filter (the built-in Cornell box's) and the gaussian, whose splats the merge spreads
// over bands of rows shared out to the threads (Film::add_splats): 1, 2 and 3 threads.
TEST(Ptracer, SameFilmAtAnyThreadCountAndPassSplit) {
    auto base = cornell(20);
    expect_splat_film_deterministic(*base, 20, IntegratorType::Ptracer, base->settings.max_depth);
}

TEST(Ptracer, CheckpointAndResumeKeepTheSplats) {
    using namespace candela::test;
    const std::string d = temp_dir("ptracer-ckpt"), o = "--width 20 --height 16 --quiet --integrator ptracer";
    ASSERT_EQ(run_candela(o + " --frames 5 --out " + d + "/full.exr --checkpoint " + d + "/full.ck").exit_code, 0);
    RunResult a = run_candela(o + " --frames 2 --threads 1 --out " + d + "/part.exr --checkpoint " + d + "/part.ck");
    ASSERT_EQ(a.exit_code, 0) << a.output;
    RunResult b = run_candela(o + " --frames 5 --threads 2 --out " + d + "/part.exr --checkpoint " + d + "/part.ck --resume " +
                              d + "/part.ck");
    ASSERT_EQ(b.exit_code, 0) << b.output;
    EXPECT_TRUE(read_bytes(d + "/full.ck") == read_bytes(d + "/part.ck")) << "the checkpoints differ";
    Image ia = read_linear_image(d + "/full.exr"), ib = read_linear_image(d + "/part.exr");
    ASSERT_EQ(ia.rgb.size(), ib.rgb.size());
    EXPECT_EQ(std::memcmp(ia.rgb.data(), ib.rgb.data(), ia.rgb.size() * sizeof(float)), 0);
    double sum = 0;
    for (float v : ia.rgb) sum += v;
    EXPECT_GT(sum, 0.0);  // the image is the splats: not black
    // A path-traced render refuses the light tracer's checkpoint (another integrator).
    RunResult c = run_candela("--width 20 --height 16 --quiet --frames 6 --out " + d + "/x.exr --resume " + d + "/full.ck");
    EXPECT_EQ(c.exit_code, 1) << c.output;
    EXPECT_NE(c.output.find("another scene or other settings"), std::string::npos) << c.output;
    // An unknown integrator is a one-line usage error.
    RunResult e = run_candela("--integrator nope --out " + d + "/y.exr");
    EXPECT_NE(e.exit_code, 0);
    EXPECT_NE(e.output.find("--integrator"), std::string::npos) << e.output;
}

TEST(Ptracer, XmlIntegrator) {
    using namespace candela::test;
    const std::string d = temp_dir("ptracer-xml");
    auto scene_with = [&](const std::string& integrator) {
        return "<scene version=\"3.0.0\">" + integrator +
               "<sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/>"
               "<integer name=\"height\" value=\"8\"/></film></sensor>"
               "<shape type=\"sphere\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape></scene>";
    };
    write_text(d + "/a.xml", scene_with("<integrator type=\"ptracer\"><integer name=\"max_depth\" value=\"3\"/>"
                                        "<integer name=\"rr_depth\" value=\"2\"/><boolean name=\"hide_emitters\" value=\"true\"/>"
                                        "</integrator>"));
    SceneDescription s = load_scene(d + "/a.xml");
    EXPECT_EQ(s.settings.integrator.type, IntegratorType::Ptracer);
    EXPECT_EQ(s.settings.max_depth, 2);  // Mitsuba's segments: 3 = two scattering events
    EXPECT_EQ(s.settings.rr_depth, 2);
    EXPECT_TRUE(s.settings.integrator.hide_emitters);
    write_text(d + "/b.xml", scene_with("<integrator type=\"aov\"><string name=\"aovs\" value=\"dd:depth\"/>"
                                        "<integrator type=\"ptracer\"/></integrator>"));
    try {
        load_scene(d + "/b.xml");
        ADD_FAILURE() << "ptracer inside aov accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("ptracer cannot be nested"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("b.xml"), std::string::npos) << e.what();
    }
}
