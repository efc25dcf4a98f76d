// The integrators other than plain path tracing (issue 13): `direct` (Mitsuba 3's direct.cpp: sample
// counts in the MIS weights, delta lobes, hide_emitters), `path` with hide_emitters, `volpath`
// without media, and the `moment` and `aov` wrappers.
//
// * Direct_ExactIrradiance: a diffuse plane (albedo rho) under a parallel square emitter of
//   radiance L, side 2a at height h, seen straight down at the point below its centre. The
//   radiance leaving that point is rho L F, with F the form factor from the point to the square
//   (four corner rectangles: F = 4 F_corner(a/h, a/h), F_corner(X, Y) = 1/(2 pi) [X/sqrt(1+X^2)
//   atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))]). Every (emitter_samples,
//   bsdf_samples) pair must be unbiased: z-tests, Sidak-corrected; the standard error is below
//   0.5% of the value so that a bias cannot hide, and a 3% error is rejected (the control).
// * Direct_AgreesWithPathAtDepthOne: with one sample of each strategy the direct estimator is the
//   path tracer's at max depth 1 (same sample order, same weights: h(a/2, b/2) = h(a, b)).
// * Direct_MatchesMitsuba: emitter_samples 2, bsdf_samples 3, hide_emitters on the Cornell box,
//   against a committed Mitsuba 3.9.1 reference (tests/data/direct_es2_bs3_hide_*.exr, made by
//     $PY tests/data/make_reference.py tests/data/scenes/cbox_direct.xml --res 32 --batches 16
//         --spp 2048 --variant scalar_rgb --out tests/data/direct_es2_bs3_hide).
//   Controls: the same render with the emitters shown is rejected.
#include <gtest/gtest.h>
#include <cmath>
#include <cstring>
#include <memory>
#include "core/error.h"
#include "film/exr_layers.h"
#include "film/image_io.h"
#include "integrator/direct/direct.h"
#include "integrator/path.h"
#include "render/launch.h"
#include "render/renderer.h"
#include "scene/cornell.h"
#include "scene/loaders.h"
#include "support/run.h"
#include "support/render.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;

double corner_form_factor(double X, double Y) {
    const double sx = std::sqrt(1 + X * X), sy = std::sqrt(1 + Y * Y);
    return (X / sx * std::atan(Y / sx) + Y / sy * std::atan(X / sy)) / (2 * M_PI);
}

// A 20 x 20 plane at z = 0 facing +z, and a 2a x 2a emitter at height h facing -z.
std::shared_ptr<const Scene> plane_under_square(float rho, float L, float a, float h, int es, int bs) {
    SceneDescription d;
    d.source = "<plane under a square emitter>";
    d.materials.push_back({"plane", DiffuseBsdf{vec3(rho)}, false});
    d.materials.push_back({"lamp", DiffuseBsdf{vec3(0.f)}, false});
    d.emitters.push_back({vec3(L)});
    const float s = 10.f;
    d.add_shape("plane", {vec3(-s, -s, 0), vec3(s, -s, 0), vec3(s, s, 0), vec3(-s, s, 0)}, {},
                {uvec3(0, 1, 2), uvec3(0, 2, 3)}, 0, -1);
    d.add_shape("lamp", {vec3(-a, -a, h), vec3(a, -a, h), vec3(a, a, h), vec3(-a, a, h)}, {},
                {uvec3(0, 2, 1), uvec3(0, 3, 2)}, 1, 0);  // wound clockwise from above: faces -z
    d.settings.width = d.settings.height = 4;
    d.settings.integrator.type = IntegratorType::Direct;
    d.settings.integrator.emitter_samples = es;
    d.settings.integrator.bsdf_samples = bs;
    return build_scene(std::move(d));
}

}  // namespace

TEST(Direct, ExactIrradianceForEverySampleSplit) {
    const float rho = 0.6f, L = 3.f, a = 1.f, h = 1.5f;
    const double exact = rho * L * 4.0 * corner_form_factor(a / h, a / h);
    const int splits[][2] = {{1, 1}, {1, 0}, {0, 1}, {2, 3}, {4, 1}, {0, 3}};
    const int n_tests = 6 + 1;
    const double level = sidak_level(kAlpha, n_tests);
    for (auto& sp : splits) {
        auto scene = plane_under_square(rho, L, a, h, sp[0], sp[1]);
        DirectIntegrator di(*scene);
        RunningStats st;
        PathStats ps;
        for (uint32_t i = 0; i < 200000; ++i) {
            IndependentSampler sampler(17);
            sampler.start_pixel_sample(ivec2(int(i % 512), int(i / 512)), i);
            Ray ray;
            ray.o = vec3(0.f, 0.f, 0.5f * h);
            ray.d = vec3(0.f, 0.f, -1.f);
            st.add(di.Li<IndependentSampler, true>(ray, sampler, ps).x);
        }
        MeanTest t = z_test(st, exact, 1e-6 * exact);
        std::printf("  emitter_samples %d, bsdf_samples %d: %s\n", sp[0], sp[1], t.describe().c_str());
        EXPECT_GE(t.p_value, level) << t.describe();
        EXPECT_LT(t.std_error, 0.005 * exact);
        if (sp[0] == 1 && sp[1] == 1) {
            MeanTest control = z_test(st, 0.97 * exact);
            std::printf("  control, 3%% low: %s\n", control.describe().c_str());
            EXPECT_LT(control.p_value, level);
        }
    }
}

TEST(Direct, AgreesWithPathAtDepthOne) {
    // The built-in box (diffuse) and the mirror-and-glass box (delta lobes: the BSDF sample's light
    // pdf is 0 and no light samples are taken at a purely specular vertex).
    std::vector<std::shared_ptr<const Scene>> scenes;
    {
        SceneOverrides ov;
        ov.width = ov.height = 16;
        scenes.push_back(prepare_scene("", ov));
        scenes.push_back(prepare_scene(std::string(CANDELA_SOURCE_DIR) + "/scenes/cornell-materials/mirror-glass.xml", ov));
    }
    for (const auto& base : scenes) {
        for (bool hide : {false, true}) {
            SceneParams p = base->params();
            p.settings.max_depth = 1;
            p.settings.integrator.hide_emitters = hide;
            auto path_scene = base->with_params(p);
            p.settings.integrator.type = IntegratorType::Direct;
            p.settings.integrator.emitter_samples = p.settings.integrator.bsdf_samples = 1;
            auto direct_scene = base->with_params(p);
            PathIntegrator pi(*path_scene);
            DirectIntegrator di(*direct_scene);
            Camera cam = path_scene->camera;
            cam.set_film_size(16, 16);
            PathStats s1, s2;
            double max_rel = 0, sum = 0;
            for (int y = 0; y < 16; ++y)
                for (int x = 0; x < 16; ++x)
                    for (uint32_t s = 0; s < 8; ++s) {
                        IndependentSampler a(5), b(5);
                        a.start_pixel_sample(ivec2(x, y), s);
                        b.start_pixel_sample(ivec2(x, y), s);
                        Ray ra = cam.generate_ray(vec2(float(x), float(y)) + a.next_2d());
                        Ray rb = cam.generate_ray(vec2(float(x), float(y)) + b.next_2d());
                        vec3 La = pi.Li<IndependentSampler, false>(ra, a, s1);
                        vec3 Lb = di.Li<IndependentSampler, false>(rb, b, s2);
                        for (int c = 0; c < 3; ++c) {
                            double d = std::abs(double(La[c]) - double(Lb[c]));
                            max_rel = std::max(max_rel, d / std::max(1e-3, double(std::abs(La[c]))));
                        }
                        sum += La.x;
                    }
            std::printf("  %s, hide_emitters %d: max relative difference %.3g (sum %.4g)\n", base->source.c_str(),
                        int(hide), max_rel, sum);
            EXPECT_LT(max_rel, 1e-4);
            EXPECT_GT(sum, 1.0);  // not a comparison of black images
        }
    }
}

namespace {

ImageEstimate load_reference(const std::string& prefix) { return ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/" + prefix); }

// K batches of `spp` samples with seeds 1..K of an XML test scene.
ImageEstimate render_batches(const std::string& scene_file, const Defines& defines, int batches, int spp) {
    const std::shared_ptr<const Scene> built = build_scene(load_scene(scene_file, defines));
    return candela::test::render_batch_estimate(*built, built->params(), batches, spp);
}

}  // namespace

TEST(Direct, MatchesMitsubaWithTwoEmitterAndThreeBsdfSamples) {
    const std::string scene = std::string(CANDELA_TEST_DATA) + "/scenes/cbox_direct.xml";
    ImageEstimate ref = load_reference("direct_es2_bs3_hide");
    ImageEstimate test = render_batches(scene, {{"res", "32"}}, 8, 64);
    BlockTestResult r = block_z_test(test, ref, 4, kAlpha);
    std::printf("  direct 2/3, hide_emitters: %s\n", r.describe().c_str());
    EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
    // Control: the emitters shown (hide_emitters false) must be rejected.
    ImageEstimate shown = render_batches(scene, {{"res", "32"}, {"hide", "false"}}, 8, 64);
    BlockTestResult c = block_z_test(shown, ref, 4, kAlpha);
    std::printf("  control, emitters shown: %s\n", c.describe().c_str());
    EXPECT_FALSE(c.passed(kAlpha));
}

// Mitsuba's differentiable integrators render their primal image with the path tracer's estimators:
// prb (and prbvolpath, prb_projective) as path, prb_basic with BSDF sampling only, direct_projective
// at one scattering event. A point light and a dim sky tell the three apart: prb_basic never finds
// the point light, direct_projective has no indirect light. References (Mitsuba 3.9.1 llvm_ad_rgb):
//   $PY tests/data/make_reference.py tests/data/scenes/emitter_point_env.xml --res 32 --batches 16
//       --spp 1024 -D integrator=prb --out tests/data/prb_path        (prb_basic: prb_basic,
//       direct_projective: prb_direct)
TEST(DifferentiableIntegrators, PrimalImagesMatchMitsuba) {
    const std::string scene = std::string(CANDELA_TEST_DATA) + "/scenes/emitter_point_env.xml";
    const char* types[3] = {"prb", "prb_basic", "direct_projective"};
    const char* refs[3] = {"prb_path", "prb_basic", "prb_direct"};
    const double alpha = sidak_level(kAlpha, 3);
    ImageEstimate images[3];
    for (int i = 0; i < 3; ++i) images[i] = render_batches(scene, {{"res", "32"}, {"integrator", types[i]}}, 8, 64);
    for (int i = 0; i < 3; ++i) {
        ImageEstimate ref = load_reference(refs[i]);
        // rel_floor 1e-5: where the sky is seen directly both images are noise-free, and Mitsuba's
        // RGB round trip moves it by a few 1e-7 (as in Emitters.MitsubaAgreement).
        BlockTestResult r = block_z_test(images[i], ref, 8, alpha, 1e-5);
        std::printf("  %-17s against Mitsuba's %s: %s\n", types[i], types[i], r.describe().c_str());
        EXPECT_TRUE(r.passed(alpha)) << types[i] << ": " << r.describe();
        // Control: each of the other two images must be rejected against this reference.
        for (int j = 0; j < 3; ++j) {
            if (j == i) continue;
            BlockTestResult c = block_z_test(images[j], ref, 8, kAlpha, 1e-5);
            EXPECT_FALSE(c.passed(kAlpha)) << types[j] << " passed against Mitsuba's " << types[i];
        }
    }
}

TEST(PathHideEmitters, CameraRaysPassThroughEmitters) {
    // Emitters only (Mitsuba's max depth 1): the light is the only non-black thing; hidden, nothing is left.
    SceneOverrides ov;
    ov.width = ov.height = 24;
    ov.max_depth = 1;
    auto shown = prepare_scene("", ov);
    SceneParams p = shown->params();
    p.settings.integrator.hide_emitters = true;
    auto hidden = shown->with_params(p);
    Film a(24, 24), b(24, 24);
    Renderer::render_pass(*shown, a, 0, 4, 2);
    Renderer::render_pass(*hidden, b, 0, 4, 2);
    double sa = 0, sb = 0;
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
            sa += a.pixel(x, y).x;
            sb += b.pixel(x, y).x;
        }
    EXPECT_GT(sa, 1.0);
    EXPECT_EQ(sb, 0.0);
}

namespace {

std::string cbox_with_integrator(const std::string& dir, const std::string& integrator) {
    std::string text = test::read_bytes(std::string(CANDELA_TEST_DATA) + "/scenes/cbox_filter.xml");
    size_t b = text.find("    <integrator"), e = text.find("</integrator>") + std::string("</integrator>").size();
    text = text.substr(0, b) + integrator + text.substr(e);
    // Meshes are named relative to tests/data/scenes: point them at the source tree.
    for (size_t at; (at = text.find("../../../scenes/")) != std::string::npos;)
        text.replace(at, 16, std::string(CANDELA_SOURCE_DIR) + "/scenes/");
    std::string path = dir + "/scene.xml";
    test::write_text(path, text);
    return path;
}

}  // namespace

TEST(IntegratorWrappers, VolpathAndMomentRenderThePathTracersImage) {
    std::string d = test::temp_dir("wrappers");
    const std::string common = " -D res=16 -D filter=box --frames 4 --seed 3 --quiet --threads 2 ";
    auto path = test::run_candela(cbox_with_integrator(d, "<integrator type=\"path\"><integer name=\"max_depth\" value=\"4\"/></integrator>") +
                                  common + "--out " + d + "/path.exr");
    ASSERT_EQ(path.exit_code, 0) << path.output;
    std::string vp = d + "/vp";
    std::system(("mkdir -p " + vp).c_str());
    auto volpath = test::run_candela(
        cbox_with_integrator(vp, "<integrator type=\"volpath\"><integer name=\"max_depth\" value=\"4\"/></integrator>") +
        common + "--out " + d + "/volpath.exr");
    ASSERT_EQ(volpath.exit_code, 0) << volpath.output;
    std::string mo = d + "/mo";
    std::system(("mkdir -p " + mo).c_str());
    auto moment = test::run_candela(
        cbox_with_integrator(mo, "<integrator type=\"moment\"><integrator type=\"path\"><integer name=\"max_depth\" "
                                 "value=\"4\"/></integrator></integrator>") +
        common + "--out " + d + "/moment.exr");
    ASSERT_EQ(moment.exit_code, 0) << moment.output;
    Image a = read_linear_image(d + "/path.exr"), b = read_linear_image(d + "/volpath.exr"),
          c = read_linear_image(d + "/moment.exr");
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    ASSERT_EQ(a.rgb.size(), c.rgb.size());
    EXPECT_EQ(std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * 4), 0);
    EXPECT_EQ(std::memcmp(a.rgb.data(), c.rgb.data(), a.rgb.size() * 4), 0);
}

TEST(IntegratorWrappers, AovLayersInTheExr) {
    std::string d = test::temp_dir("aov");
    const std::string common = " -D res=16 -D filter=gaussian --frames 16 --seed 3 --quiet --threads 2 ";
    auto plain = test::run_candela(cbox_with_integrator(d, "<integrator type=\"path\"/>") + common + "--out " + d +
                                   "/plain.exr");
    ASSERT_EQ(plain.exit_code, 0) << plain.output;
    std::string ad = d + "/aov";
    std::system(("mkdir -p " + ad).c_str());
    const std::string scene = cbox_with_integrator(
        ad, "<integrator type=\"aov\"><string name=\"aovs\" value=\"dd:depth, pp:position,nn:sh_normal,gg:geo_normal,"
            "aa:albedo\"/><integrator type=\"path\" name=\"my_image\"/></integrator>");
    auto aov = test::run_candela(scene + common + "--out " + d + "/aov.exr");
    ASSERT_EQ(aov.exit_code, 0) << aov.output;
    int w = 0, h = 0;
    auto ch = read_exr_channels(d + "/aov.exr", &w, &h);
    ASSERT_EQ(w, 16);
    for (const char* n : {"R", "G", "B", "dd.T", "pp.X", "pp.Y", "pp.Z", "nn.X", "nn.Y", "nn.Z", "gg.X", "gg.Y", "gg.Z",
                          "aa.R", "aa.G", "aa.B"})
        ASSERT_TRUE(ch.count(n)) << "channel " << n;
    EXPECT_EQ(ch.size(), 16u);
    // The wrapper draws no random numbers: the image is the nested integrator's, bit for bit.
    Image p = read_linear_image(d + "/plain.exr");
    for (size_t i = 0; i < size_t(w * h); ++i) {
        ASSERT_EQ(p.rgb[3 * i], ch["R"][i]) << i;
        ASSERT_EQ(p.rgb[3 * i + 2], ch["B"][i]) << i;
    }
    // The values, box-filtered (so that no neighbour blurs in): pixels (6..9, 4..5) look at the
    // back wall (z = 559.2, normal -z, white albedo) from (278, 273, -800), 1359 to 1400 away.
    std::string bd = d + "/box";
    std::system(("mkdir -p " + bd).c_str());
    auto boxed = test::run_candela(scene + " -D res=16 -D filter=box --frames 4 --quiet --out " + bd + "/aov.exr");
    ASSERT_EQ(boxed.exit_code, 0) << boxed.output;
    ch = read_exr_channels(bd + "/aov.exr", &w, &h);
    for (int y = 4; y <= 5; ++y)
        for (int x = 6; x <= 9; ++x) {
            size_t i = size_t(y * w + x);
            EXPECT_NEAR(ch["pp.Z"][i], 559.2f, 0.5f);
            // Depth is the distance from the pinhole to the position (up to the pixel's averaging).
            const float dist = glm::length(vec3(ch["pp.X"][i], ch["pp.Y"][i], ch["pp.Z"][i]) - vec3(278.f, 273.f, -800.f));
            EXPECT_NEAR(ch["dd.T"][i], dist, 0.5f);
            EXPECT_GT(ch["dd.T"][i], 1359.f);
            EXPECT_LT(ch["dd.T"][i], 1400.f);
            EXPECT_NEAR(ch["nn.Z"][i], -1.f, 1e-4f);
            EXPECT_NEAR(ch["gg.Z"][i], -1.f, 1e-4f);
            EXPECT_NEAR(ch["aa.R"][i], 0.725f, 1e-4f);
            EXPECT_NEAR(ch["aa.B"][i], 0.68f, 1e-4f);
        }
    // AOVs with checkpoints are refused in one line.
    auto ck = test::run_candela(scene + common + "--out " + d + "/x.exr --checkpoint " + d + "/x.ckpt");
    EXPECT_EQ(ck.exit_code, 1) << ck.output;
    EXPECT_NE(ck.output.find("checkpoints do not hold the aov integrator's layers"), std::string::npos) << ck.output;
}

// The moment wrapper's channels (Mitsuba's moment.cpp: the nested integrator's radiance as XYZ and
// its per-sample square) and the uv / prim_index AOVs.
TEST(IntegratorWrappers, MomentAndUvChannels) {
    std::string d = test::temp_dir("moment-uv");
    const std::string scene = cbox_with_integrator(
        d, "<integrator type=\"moment\"><integrator type=\"aov\"><string name=\"aovs\" value=\"uu:uv,ii:prim_index,"
           "du:dp_du\"/><integrator type=\"path\" name=\"img\"/></integrator></integrator>");
    auto r = test::run_candela(scene + " -D res=16 -D filter=box --frames 64 --seed 5 --quiet --threads 2 --out " + d +
                               "/m.exr");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    int w = 0, h = 0;
    auto ch = read_exr_channels(d + "/m.exr", &w, &h);
    ASSERT_EQ(w, 16);
    for (const char* n : {"R", "G", "B", "uu.U", "uu.V", "ii.I", "du.X", "du.Y", "du.Z", "_arg_0.X", "_arg_0.Y",
                          "_arg_0.Z", "m2__arg_0.X", "m2__arg_0.Y", "m2__arg_0.Z"})
        ASSERT_TRUE(ch.count(n)) << "channel " << n;
    EXPECT_EQ(ch.size(), 15u);
    size_t spread = 0;
    for (size_t i = 0; i < size_t(w * h); ++i) {
        const float R = ch["R"][i], G = ch["G"][i], B = ch["B"][i];
        // The first moment is the image itself in XYZ (a linear map commutes with the mean).
        const float Y = 0.212671f * R + 0.715160f * G + 0.072169f * B;
        ASSERT_NEAR(ch["_arg_0.Y"][i], Y, 1e-5f * std::max(1.f, Y)) << i;
        ASSERT_NEAR(ch["_arg_0.X"][i], 0.412453f * R + 0.357580f * G + 0.180423f * B, 1e-5f * std::max(1.f, Y)) << i;
        // The mean of the squares is at least the square of the mean, and strictly more where the
        // samples differ (the path-traced walls, not the black outside).
        const float m2 = ch["m2__arg_0.Y"][i];
        ASSERT_GE(m2, Y * Y * (1.f - 1e-5f)) << i;
        if (m2 > Y * Y * 1.01f) ++spread;
        // The Cornell box's OBJ meshes have no uvs: uv is the barycentric (b1, b2) of the triangle,
        // averaged over the pixel, and prim_index a triangle number within the shape.
        EXPECT_GE(ch["uu.U"][i], 0.f);
        EXPECT_LE(ch["uu.U"][i] + ch["uu.V"][i], 1.f + 1e-5f);
        EXPECT_GE(ch["ii.I"][i], 0.f);
        EXPECT_LT(ch["ii.I"][i], 64.f);
    }
    EXPECT_GT(spread, size_t(w * h / 2));
}

TEST(IntegratorXml, ParametersAndErrors) {
    std::string d = test::temp_dir("integrator-xml");
    auto load = [&](const std::string& integrator) {
        return load_scene(cbox_with_integrator(d, integrator), {{"res", "8"}});
    };
    SceneDescription s = load("<integrator type=\"direct\"><integer name=\"shading_samples\" value=\"3\"/></integrator>");
    EXPECT_EQ(s.settings.integrator.type, IntegratorType::Direct);
    EXPECT_EQ(s.settings.integrator.emitter_samples, 3);
    EXPECT_EQ(s.settings.integrator.bsdf_samples, 3);
    s = load("<integrator type=\"direct\"><integer name=\"bsdf_samples\" value=\"0\"/></integrator>");
    EXPECT_EQ(s.settings.integrator.emitter_samples, 1);
    EXPECT_EQ(s.settings.integrator.bsdf_samples, 0);
    s = load("<integrator type=\"path\"><boolean name=\"hide_emitters\" value=\"true\"/><integer name=\"max_depth\" value=\"3\"/></integrator>");
    EXPECT_TRUE(s.settings.integrator.hide_emitters);
    EXPECT_EQ(s.settings.max_depth, 2);
    s = load("<integrator type=\"moment\"><integrator type=\"aov\"><string name=\"aovs\" value=\"d:depth\"/>"
             "<integrator type=\"volpath\"><integer name=\"max_depth\" value=\"2\"/></integrator></integrator></integrator>");
    EXPECT_EQ(s.settings.integrator.type, IntegratorType::Volpath);
    EXPECT_EQ(s.settings.max_depth, 1);
    // The moment channels come last, named after the (unnamed: "_arg_0") integrator it holds.
    ASSERT_EQ(s.settings.integrator.aovs.size(), 2u);
    EXPECT_EQ(aov_channel_names(s.settings.integrator.aovs),
              (std::vector<std::string>{"d.T", "_arg_0.X", "_arg_0.Y", "_arg_0.Z", "m2__arg_0.X", "m2__arg_0.Y",
                                        "m2__arg_0.Z"}));

    s = load("<integrator type=\"volpathmis\"><integer name=\"max_depth\" value=\"4\"/></integrator>");
    EXPECT_EQ(s.settings.integrator.type, IntegratorType::Volpath);
    EXPECT_EQ(s.settings.max_depth, 3);
    EXPECT_TRUE(s.settings.integrator.spectral_mis);
    s = load("<integrator type=\"volpath\"/>");
    EXPECT_FALSE(s.settings.integrator.spectral_mis);
    // The differentiable integrators: Mitsuba's default depth for them is 6 segments, not unbounded.
    s = load("<integrator type=\"prb\"/>");
    EXPECT_EQ(s.settings.integrator.type, IntegratorType::Path);
    EXPECT_EQ(s.settings.max_depth, 5);
    EXPECT_EQ(s.settings.sampling, SamplingMode::Mis);
    s = load("<integrator type=\"prb_basic\"><integer name=\"max_depth\" value=\"-1\"/>"
             "<boolean name=\"hide_emitters\" value=\"true\"/></integrator>");
    EXPECT_EQ(s.settings.max_depth, -1);
    EXPECT_EQ(s.settings.sampling, SamplingMode::Bsdf);
    EXPECT_TRUE(s.settings.integrator.hide_emitters);
    s = load("<integrator type=\"prbvolpath\"><integer name=\"max_depth\" value=\"3\"/>"
             "<integer name=\"rr_depth\" value=\"2\"/></integrator>");
    EXPECT_EQ(s.settings.max_depth, 2);
    EXPECT_EQ(s.settings.rr_depth, 2);
    s = load("<integrator type=\"prb_projective\"><integer name=\"sppi\" value=\"0\"/>"
             "<string name=\"guiding\" value=\"grid\"/><boolean name=\"guiding_proj\" value=\"false\"/></integrator>");
    EXPECT_EQ(s.settings.max_depth, 5);
    // direct_projective reads max_depth and then renders direct light only, as in Mitsuba.
    s = load("<integrator type=\"direct_projective\"><integer name=\"max_depth\" value=\"12\"/>"
             "<string name=\"project_seed\" value=\"bsdf\"/></integrator>");
    EXPECT_EQ(s.settings.integrator.type, IntegratorType::Path);
    EXPECT_EQ(s.settings.max_depth, 1);

    auto expect_error = [&](const std::string& integrator, const std::string& needle) {
        try {
            load(integrator);
            ADD_FAILURE() << "no error for " << integrator;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("scene.xml:"), std::string::npos) << e.what();
        }
    };
    expect_error("<integrator type=\"sppm\"/>", "unsupported integrator type 'sppm'");
    expect_error("<integrator type=\"direct\"><integer name=\"shading_samples\" value=\"2\"/><integer name=\"bsdf_samples\" value=\"1\"/></integrator>",
                 "cannot give both");
    expect_error("<integrator type=\"direct\"><integer name=\"emitter_samples\" value=\"0\"/><integer name=\"bsdf_samples\" value=\"0\"/></integrator>",
                 "at least one");
    expect_error("<integrator type=\"direct\"><integer name=\"max_depth\" value=\"2\"/></integrator>", "max_depth");
    expect_error("<integrator type=\"prb_projective\"><string name=\"guiding\" value=\"kd\"/></integrator>",
                 "guiding must be none, grid or octree");
    expect_error("<integrator type=\"direct_projective\"><string name=\"project_seed\" value=\"x\"/></integrator>",
                 "project_seed must be");
    expect_error("<integrator type=\"prb\"><integer name=\"sppc\" value=\"4\"/></integrator>", "sppc");
    expect_error("<integrator type=\"prb\"><integer name=\"max_depth\" value=\"0\"/></integrator>", "max_depth 0");
    expect_error("<integrator type=\"moment\"/>", "needs a nested <integrator>");
    expect_error("<integrator type=\"aov\"><string name=\"aovs\" value=\"b:boundary_test\"/><integrator type=\"path\"/></integrator>",
                 "AOV type 'boundary_test' is not supported");
    expect_error("<integrator type=\"moment\"><integrator type=\"moment\"><integrator type=\"path\"/></integrator></integrator>",
                 "inside another moment");
    expect_error("<integrator type=\"aov\"><string name=\"aovs\" value=\"depth\"/><integrator type=\"path\"/></integrator>",
                 "expected <name>:<type>");
    expect_error("<integrator type=\"aov\"><integrator type=\"path\"/></integrator>", "needs an 'aovs' string");
    expect_error("<integrator type=\"aov\"><string name=\"aovs\" value=\"d:depth\"/><integrator type=\"path\"/>"
                 "<integrator type=\"direct\"/></integrator>",
                 "more than one nested integrator");
}
