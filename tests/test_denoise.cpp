// Denoising (docs/denoising.md): the denoiser's auxiliary layers (albedo and normal of the first
// non-specular surface), Open Image Denoise on the Cornell box against the Mitsuba 3 reference, the
// command line's outputs and the missing-library path, and the viewer session's background denoiser.
//
// With CANDELA_OIDN=ON (the default) the library must be there (scripts/setup.sh installs it): the
// tests that run it fail without it. Only a build with CANDELA_OIDN=OFF skips them.
#include <gtest/gtest.h>
#include <cmath>
#include "denoise/denoiser.h"
#include "film/exr_layers.h"
#include "integrator/integrator.h"
#include "render/launch.h"
#include "render/renderer.h"
#include "render/session.h"
#include "support/run.h"

using namespace candela;

namespace {

#if CANDELA_HAS_OIDN
#define REQUIRE_OIDN()
#else
#define REQUIRE_OIDN() GTEST_SKIP() << "built with CANDELA_OIDN=OFF: no denoiser"
#endif

std::unique_ptr<Film> render(const Scene& scene, int spp) {
    auto film = std::make_unique<Film>(scene.settings.width, scene.settings.height);
    configure_film(*film, scene.settings);
    Renderer::render_pass(scene, *film, 0, spp, 0);
    return film;
}

// Mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01): relMSE, as in docs/denoising.md.
double rel_mse(const std::vector<float>& x, const std::vector<float>& ref) {
    double s = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        const double d = double(x[i]) - double(ref[i]);
        s += d * d / (double(ref[i]) * double(ref[i]) + 0.01);
    }
    return s / double(x.size());
}

std::vector<float> cornell_reference(int* w, const char* file = "cornell64_mean.exr") {
    int h = 0;
    auto ch = read_exr_channels(std::string(CANDELA_TEST_DATA) + "/" + file, w, &h);
    std::vector<float> rgb(size_t(*w) * size_t(h) * 3);
    for (size_t i = 0; i < size_t(*w) * size_t(h); ++i) {
        rgb[3 * i] = ch["R"][i];
        rgb[3 * i + 1] = ch["G"][i];
        rgb[3 * i + 2] = ch["B"][i];
    }
    return rgb;
}

// relMSE against a stored reference of the built-in Cornell box at res x res (film of the scene's
// box filter, with the denoiser's guides): raw at `lo` and `hi` spp, and `lo` spp denoised (high).
struct CornellErrors {
    double raw_lo, raw_hi, denoised_lo;
};
CornellErrors cornell_errors(int res, const char* reference, int lo, int hi) {
    int w = 0;
    const std::vector<float> ref = cornell_reference(&w, reference);
    EXPECT_EQ(w, res);
    SceneOverrides ov;
    ov.width = ov.height = res;
    ov.denoise_aux = true;
    auto scene = prepare_scene("", ov);
    auto f_lo = render(*scene, lo);
    auto f_hi = render(*scene, hi);
    Denoiser dn(DenoiseQuality::High);
    std::vector<float> out;
    dn.denoise(denoise_inputs(*f_lo, scene->settings.integrator.aovs), out);
    const CornellErrors e{rel_mse(f_lo->resolve(), ref), rel_mse(f_hi->resolve(), ref), rel_mse(out, ref)};
    std::printf("  relMSE: raw %d spp %.6f, raw %d spp %.6f, denoised %d spp %.6f\n", lo, e.raw_lo, hi, e.raw_hi, lo,
                e.denoised_lo);
    return e;
}

}  // namespace

// The layers --denoise and --aov add: named albedo.R/G/B and normal.X/Y/Z, before a moment
// wrapper's channels, renamed when the scene's aov wrapper already uses the names.
TEST(DenoiseAov, LayerNames) {
    std::vector<AovSpec> aovs;
    add_denoise_aovs(aovs);
    EXPECT_EQ(aov_channel_names(aovs),
              (std::vector<std::string>{"albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z"}));
    add_denoise_aovs(aovs);  // idempotent
    EXPECT_EQ(aov_channel_count(aovs), 6);
    std::vector<AovSpec> taken{{"albedo", AovType::Albedo}, {"m", AovType::Moment}};
    add_denoise_aovs(taken);
    ASSERT_EQ(taken.size(), 4u);
    EXPECT_EQ(taken[1].name, "denoise_albedo");
    EXPECT_EQ(taken[2].name, "denoise_normal");
    EXPECT_EQ(taken[3].type, AovType::Moment);
}

// Albedo in [0, 1] and normals of length at most 1 (an average of unit vectors), unit where a
// pixel sees one flat surface, on the built-in Cornell box; the beauty is the same bit for bit
// as without the layers (they draw no random numbers).
TEST(DenoiseAov, RangesOnCornellBox) {
    SceneOverrides ov;
    ov.width = ov.height = 32;
    auto plain = prepare_scene("", ov);
    ov.denoise_aux = true;
    auto scene = prepare_scene("", ov);
    ASSERT_EQ(aov_channel_count(scene->settings.integrator.aovs), 6);
    auto film = render(*scene, 4);
    auto raw = render(*plain, 4);
    EXPECT_EQ(film->resolve(), raw->resolve());
    DenoiseImages in = denoise_inputs(*film, scene->settings.integrator.aovs);
    ASSERT_EQ(in.albedo.size(), in.color.size());
    ASSERT_EQ(in.normal.size(), in.color.size());
    int unit = 0, pixels = 32 * 32;
    float max_albedo = 0.f;
    for (int i = 0; i < pixels; ++i) {
        for (int k = 0; k < 3; ++k) {
            EXPECT_GE(in.albedo[size_t(3 * i + k)], 0.f);
            EXPECT_LE(in.albedo[size_t(3 * i + k)], 1.f);
            max_albedo = std::max(max_albedo, in.albedo[size_t(3 * i + k)]);
        }
        const float len = std::sqrt(in.normal[size_t(3 * i)] * in.normal[size_t(3 * i)] +
                                    in.normal[size_t(3 * i + 1)] * in.normal[size_t(3 * i + 1)] +
                                    in.normal[size_t(3 * i + 2)] * in.normal[size_t(3 * i + 2)]);
        EXPECT_LE(len, 1.0001f);
        unit += len > 0.999f;
    }
    EXPECT_GT(max_albedo, 0.6f);      // the white walls' 0.725 (not all zero)
    EXPECT_GT(unit, pixels * 7 / 10);  // most pixels see one wall (797 of 1024 measured)
}

// Seen in a perfect mirror, the denoiser's albedo and normal are the reflected wall's: (0.2, 0.5,
// 0.8) and the wall's normal (0, 0, -1). Control: Mitsuba's albedo AOV, which stops at the mirror,
// gives the mirror's (0 for a delta lobe) there, so the test tells the two apart.
TEST(DenoiseAov, MirrorShowsReflectedSurface) {
    SceneOverrides ov;
    ov.denoise_aux = true;
    auto scene = prepare_scene(std::string(CANDELA_TEST_DATA) + "/scenes/denoise_mirror.xml", ov);
    auto film = render(*scene, 4);
    DenoiseImages in = denoise_inputs(*film, scene->settings.integrator.aovs);
    const vec3 wall(0.2f, 0.5f, 0.8f);
    for (size_t i = 0; i < in.albedo.size() / 3; ++i) {
        for (int k = 0; k < 3; ++k) ASSERT_NEAR(in.albedo[3 * i + size_t(k)], wall[k], 1e-6f) << "pixel " << i;
        ASSERT_NEAR(in.normal[3 * i], 0.f, 1e-5f);
        ASSERT_NEAR(in.normal[3 * i + 1], 0.f, 1e-5f);
        ASSERT_NEAR(in.normal[3 * i + 2], -1.f, 1e-5f);
    }
    // Control: the first-hit albedo (Mitsuba's aov "albedo") sees the mirror, not the wall.
    auto desc = load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/denoise_mirror.xml", {});
    desc.settings.integrator.aovs = {{"a", AovType::Albedo}};
    auto first_hit = build_scene(std::move(desc), "auto");
    auto f2 = render(*first_hit, 4);
    EXPECT_GT(std::fabs(f2->aov(8, 8, 2) - wall.z), 0.5f);
}

// The trade, at its smallest: the Cornell box at 16 spp denoised against the Mitsuba 3 reference
// (tests/data/cornell64_mean.exr) is closer than the raw render at twice the samples (measured:
// denoised 16 spp 0.0031, raw 32 spp 0.0070, raw 256 spp 0.00084: at 64 x 64 raw 256 spp stays
// ahead; CornellDenoised16BeatsRaw256 checks the issue's bar at 256 x 256). Control: the raw render
// at 16 spp is not closer than raw 32 spp (the comparison can fail).
TEST(Denoise, CornellDenoised16BeatsRaw32) {
    REQUIRE_OIDN();
    const CornellErrors e = cornell_errors(64, "cornell64_mean.exr", 16, 32);
    EXPECT_LT(e.denoised_lo, e.raw_hi);
    EXPECT_GT(e.raw_lo, e.raw_hi);  // control
}

// The issue's bar: the denoised Cornell box at 16 spp is closer to the reference than the raw one at
// 256 spp. At 256 x 256 (at 128 x 128 it is not: 0.00119 against 0.00081, docs/denoising.md; OIDN
// sees too few pixels per feature there). The reference (cornell256_ref.exr, 1024 spp, another
// seed, made by `candela --width 256 --height 256 --frames 1024 --seed 777 --out tests/data/cornell256_ref.exr`) adds its own variance to both errors alike, so
// it does not favour either side.
TEST(Denoise, CornellDenoised16BeatsRaw256) {
    REQUIRE_OIDN();
    const CornellErrors e = cornell_errors(256, "cornell256_ref.exr", 16, 256);
    EXPECT_LT(e.denoised_lo, e.raw_hi);
    EXPECT_GT(e.raw_lo, 8 * e.raw_hi);  // control: the raw error falls as 1/spp (16x the samples)
}

// --denoise on the command line: R, G, B denoised, the raw beauty as "noisy" (bit for bit the
// render without --denoise) and the auxiliaries as layers; beside a .pfm, OUT.layers.exr.
TEST(Denoise, CommandLineLayers) {
    REQUIRE_OIDN();
    const std::string d = test::temp_dir("denoise-cli");
    const std::string common = "--width 24 --height 24 --frames 4 --quiet ";
    auto raw = test::run_candela(common + "--out " + d + "/raw.exr");
    ASSERT_EQ(raw.exit_code, 0) << raw.output;
    auto dn = test::run_candela(common + "--denoise --denoise-quality fast --out " + d + "/dn.exr");
    ASSERT_EQ(dn.exit_code, 0) << dn.output;
    auto r = read_exr_channels(d + "/raw.exr");
    auto c = read_exr_channels(d + "/dn.exr");
    for (const char* n : {"R", "G", "B", "noisy.R", "noisy.G", "noisy.B", "albedo.R", "albedo.G", "albedo.B", "normal.X",
                          "normal.Y", "normal.Z"})
        EXPECT_TRUE(c.count(n)) << n;
    EXPECT_EQ(c["noisy.R"], r["R"]);
    EXPECT_EQ(c["noisy.B"], r["B"]);
    EXPECT_NE(c["R"], r["R"]);  // denoised
    auto pfm = test::run_candela(common + "--denoise --out " + d + "/dn.pfm");
    ASSERT_EQ(pfm.exit_code, 0) << pfm.output;
    auto beside = read_exr_channels(d + "/dn.layers.exr");
    EXPECT_TRUE(beside.count("noisy.G") && beside.count("normal.Z"));
    // --aov alone: the auxiliaries as layers, the image raw.
    auto aov = test::run_candela(common + "--aov --out " + d + "/aov.exr");
    ASSERT_EQ(aov.exit_code, 0) << aov.output;
    auto a = read_exr_channels(d + "/aov.exr");
    EXPECT_TRUE(a.count("albedo.R") && a.count("normal.X") && !a.count("noisy.R"));
    EXPECT_EQ(a["R"], r["R"]);
}

// Without the library (CANDELA_OIDN_LIBRARY names a file that is not there): one line says so,
// the raw image is written in place of the denoised one (the auxiliaries as its layers), exit 1.
TEST(Denoise, MissingLibraryWritesRawImage) {
    const std::string d = test::temp_dir("denoise-missing");
    const std::string common = "--width 16 --height 16 --frames 2 --quiet ";
    auto raw = test::run_candela(common + "--out " + d + "/raw.exr");
    ASSERT_EQ(raw.exit_code, 0) << raw.output;
    auto r = test::run_candela(common + "--denoise --out " + d + "/x.exr",
                               "CANDELA_OIDN_LIBRARY=/nonexistent/libOpenImageDenoise.so.2");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
#if CANDELA_HAS_OIDN
    EXPECT_NE(r.output.find("Open Image Denoise is not installed"), std::string::npos) << r.output;
#else
    EXPECT_NE(r.output.find("CANDELA_OIDN=OFF"), std::string::npos) << r.output;
#endif
    EXPECT_NE(r.output.find("the raw image is written instead"), std::string::npos) << r.output;
    auto x = read_exr_channels(d + "/x.exr");
    auto ref = read_exr_channels(d + "/raw.exr");
    EXPECT_EQ(x["R"], ref["R"]);
    EXPECT_EQ(x["G"], ref["G"]);
    EXPECT_TRUE(x.count("albedo.R") && !x.count("noisy.R"));
}

// A failure inside the library (support/fake_oidn.cpp: every call succeeds until a filter runs,
// which fails with out of memory, as OIDN reports it): one line naming the library's own message,
// the raw image written in place of the denoised one with the auxiliaries as its layers, exit 1.
TEST(Denoise, FailureInsideTheLibraryWritesRawImage) {
    REQUIRE_OIDN();
    const std::string d = test::temp_dir("denoise-fails");
    const std::string common = "--width 16 --height 16 --frames 2 --quiet ";
    auto raw = test::run_candela(common + "--out " + d + "/raw.exr");
    ASSERT_EQ(raw.exit_code, 0) << raw.output;
    for (const char* out : {"x.exr", "x.png"}) {
        auto r = test::run_candela(common + "--denoise --out " + d + "/" + out,
                                   std::string("CANDELA_OIDN_LIBRARY=") + test_paths::fake_oidn());
        EXPECT_EQ(r.exit_code, 1) << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
        EXPECT_NE(r.output.find("Open Image Denoise failed to denoise: out of memory (fake library for tests)"),
                  std::string::npos)
            << r.output;
        EXPECT_NE(r.output.find("the raw image is written instead"), std::string::npos) << r.output;
    }
    auto x = read_exr_channels(d + "/x.exr");
    auto ref = read_exr_channels(d + "/raw.exr");
    EXPECT_EQ(x["R"], ref["R"]);
    EXPECT_EQ(x["B"], ref["B"]);
    EXPECT_TRUE(x.count("albedo.R") && x.count("normal.X") && !x.count("noisy.R"));
    // Beside the PNG: the raw beauty's layers file, as when the denoise succeeds.
    auto layers = read_exr_channels(d + "/x.layers.exr");
    EXPECT_TRUE(layers.count("albedo.R")) << "no layers beside the PNG";
}

// The viewer's session: turned on, the denoised image follows the full passes on its own thread,
// with the film's generation; the raw images go on being published as before.
TEST(Denoise, SessionDenoisesInBackground) {
    REQUIRE_OIDN();
    SceneOverrides ov;
    ov.width = ov.height = 32;
    ov.denoise_aux = true;
    SessionOptions so;
    so.threads = 1;
    so.max_passes = 3;
    RenderSession session(prepare_scene("", ov), so);
    session.set_denoise(true, DenoiseQuality::Fast);
    ASSERT_TRUE(session.wait_for(0, 3, 60.0));
    ASSERT_TRUE(session.wait_for_denoised(0, 3, 60.0)) << session.denoise_error();
    SessionImage dn;
    ASSERT_TRUE(session.take_denoised(dn));
    EXPECT_EQ(dn.width, 32);
    EXPECT_EQ(dn.passes, 3);
    EXPECT_EQ(dn.rgb.size(), size_t(32 * 32 * 3));
    SessionImage raw = session.latest_full_image();
    EXPECT_NE(raw.rgb, dn.rgb);
    EXPECT_FALSE(session.take_denoised(dn));  // nothing newer
}

// --denoise renders with the box filter (a wider one correlates the noise between pixels, which
// OIDN keeps) and says so; --aov alone keeps the scene's filter.
TEST(DenoiseAov, DenoiseRendersWithTheBoxFilter) {
    const std::string scene = std::string(CANDELA_TEST_DATA) + "/scenes/cbox_filter.xml";
    SceneOverrides ov;
    ov.denoise_aux = true;
    auto aov_only = prepare_scene(scene, ov);
    EXPECT_EQ(aov_only->settings.filter.type, FilterType::Gaussian);
    ov.denoise_box_filter = true;
    auto denoised = prepare_scene(scene, ov);
    EXPECT_TRUE(denoised->settings.filter.is_box());
    ASSERT_FALSE(denoised->warnings.empty());
    EXPECT_NE(denoised->warnings.back().find("box filter, not gaussian"), std::string::npos) << denoised->warnings.back();
}
