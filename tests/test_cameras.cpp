// Cameras and the film's crop window (issue 13): perspective (fov axes, focal length, principal
// point offset, clip planes), thin lens and orthographic sensors, hdrfilm crop and rgba.
//
//  * Geometry, exactly: the ray through pixel centres (and lens samples) against Mitsuba 3.9.1's
//    own sensor.sample_ray, committed as numbers in tests/data/cameras/rays.txt.
//  * Renders within Monte Carlo noise of Mitsuba references (tests/data/cameras/*_mean.exr,
//    *_var.exr) of the three scenes beside them, each with a control that must fail.
//  * Bit for bit: a thin lens with aperture 0 is the pinhole, a crop is the window of the full
//    film, whatever the thread count.
// tests/data/cameras/make_camera_data.py made the data (its header says how).
#include <gtest/gtest.h>
#include <tinyexr.h>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include "core/error.h"
#include "film/image_io.h"
#include "render/renderer.h"
#include "scene/loaders.h"
#include "support/run.h"
#include "viewer/camera_control.h"
#include "viewer/pick.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

const std::string kData = std::string(CANDELA_TEST_DATA) + "/cameras/";

std::string write_temp(const std::string& name, const std::string& text) {
    std::string d = ::testing::TempDir();
    if (!d.empty() && d.back() != '/') d += '/';
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string path = d + "candela_cam_" + info->name() + "_" + name;
    std::ofstream(path) << text;
    return path;
}

struct RayCase {
    std::string name, sensor_xml;
    struct Expected {
        ivec2 px;
        vec2 lens;
        vec3 o, d;
        float maxt;
    };
    std::vector<Expected> rays;
};

std::vector<RayCase> read_ray_cases() {
    std::ifstream f(kData + "rays.txt");
    std::vector<RayCase> cases;
    std::string line;
    while (std::getline(f, line)) {
        if (line.empty() || line[0] == '#') continue;
        if (line.rfind("case ", 0) == 0) {
            cases.push_back(RayCase{line.substr(5), "", {}});
            std::getline(f, cases.back().sensor_xml);
        } else if (line.rfind("ray ", 0) == 0 && !cases.empty()) {
            std::istringstream in(line.substr(4));
            RayCase::Expected e;
            in >> e.px.x >> e.px.y >> e.lens.x >> e.lens.y >> e.o.x >> e.o.y >> e.o.z >> e.d.x >> e.d.y >> e.d.z >> e.maxt;
            if (in) cases.back().rays.push_back(e);
        }
    }
    return cases;
}

SceneDescription load_text(const std::string& name, const std::string& xml) {
    return load_mitsuba_xml(write_temp(name, xml), {});
}

float max_abs(vec3 v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

}  // namespace

TEST(Cameras, RaysEqualMitsubaSampleRay) {
    std::vector<RayCase> cases = read_ray_cases();
    ASSERT_EQ(cases.size(), 15u) << "tests/data/cameras/rays.txt";
    float worst_d = 0, worst_o = 0, worst_t = 0;
    for (const RayCase& c : cases) {
        SCOPED_TRACE(c.name);
        SceneDescription s = load_text(c.name + ".xml", "<scene version=\"3.0.0\">" + c.sensor_xml + "</scene>");
        Camera cam = s.camera;
        cam.set_film_size(s.settings.width, s.settings.height);
        ASSERT_GE(c.rays.size(), 6u);
        for (const RayCase::Expected& e : c.rays) {
            Ray r = cam.generate_ray(e.px, vec2(0.5f), e.lens);
            // Float precision of two different evaluation orders: directions to a few ulps, the
            // origin relative to its distance from the world origin, the length relative to itself.
            float ed = max_abs(r.d - e.d), eo = max_abs(r.o - e.o) / (1.f + max_abs(e.o)),
                  et = std::abs(r.tmax - e.maxt) / e.maxt;
            worst_d = std::max(worst_d, ed);
            worst_o = std::max(worst_o, eo);
            worst_t = std::max(worst_t, et);
            EXPECT_LT(ed, 2e-6f) << "pixel " << e.px.x << "," << e.px.y;
            EXPECT_LT(eo, 2e-6f) << "pixel " << e.px.x << "," << e.px.y;
            EXPECT_LT(et, 2e-6f) << "pixel " << e.px.x << "," << e.px.y;
            EXPECT_EQ(r.tmin, 0.f);
        }
    }
    std::printf("  %zu sensors: max |d - d_mitsuba| %.2g, max origin error %.2g (relative), max length error %.2g\n",
                cases.size(), worst_d, worst_o, worst_t);
}

// The control: the same comparison sees a principal point offset of 1/1000 of the film, and a
// fov_axis taken as another.
TEST(Cameras, RayComparisonSeesSmallErrors) {
    std::vector<RayCase> cases = read_ray_cases();
    for (const RayCase& c : cases) {
        if (c.name != "persp_ppo_clip" && c.name != "persp_smaller_portrait") continue;
        SceneDescription s = load_text(c.name + ".xml", "<scene version=\"3.0.0\">" + c.sensor_xml + "</scene>");
        Camera cam = s.camera;
        if (c.name == "persp_ppo_clip") cam.principal_point_offset.x += 1e-3f;
        else cam.fov_axis = FovAxis::Y;  // smaller on a portrait film is x
        cam.set_film_size(s.settings.width, s.settings.height);
        float worst = 0;
        for (const RayCase::Expected& e : c.rays) worst = std::max(worst, max_abs(cam.generate_ray(e.px, vec2(0.5f), e.lens).d - e.d));
        EXPECT_GT(worst, 1e-4f) << c.name;
    }
}

namespace {

// Renders `spp` samples per pixel with `threads` threads (0: all) and returns the film.
std::unique_ptr<Film> render(const SceneDescription& desc, int spp, int threads = 0, uint64_t seed = 0) {
    SceneDescription d = desc;
    d.settings.seed = seed;
    std::shared_ptr<const Scene> scene = build_scene(std::move(d));
    auto film = std::make_unique<Film>(scene->settings.width, scene->settings.height);
    Renderer::render_pass(*scene, *film, 0, spp, threads);
    return film;
}

SceneDescription load_file(const std::string& name) { return load_mitsuba_xml(kData + name, {}); }

}  // namespace

TEST(Cameras, ThinLensWithoutApertureIsThePinholeBitForBit) {
    SceneDescription lens = load_file("thinlens.xml");
    ASSERT_EQ(lens.camera.type, CameraType::ThinLens);
    ASSERT_GT(lens.camera.aperture_radius, 0.f);
    SceneDescription pinhole = lens;
    pinhole.camera.type = CameraType::Perspective;
    SceneDescription closed = lens;
    closed.camera.aperture_radius = 0.f;
    std::unique_ptr<Film> a = render(pinhole, 4), b = render(closed, 4), c = render(lens, 4);
    ASSERT_EQ(a->sums().size(), b->sums().size());
    size_t differ_open = 0;
    for (size_t i = 0; i < a->sums().size(); ++i) {
        EXPECT_EQ(a->sums()[i], b->sums()[i]) << "pixel " << i;
        differ_open += a->sums()[i] != c->sums()[i];
    }
    // The control: an open aperture changes (nearly) every pixel.
    EXPECT_GT(differ_open, a->sums().size() * 9 / 10);
}

TEST(Cameras, CropIsTheWindowOfTheFullFilmBitForBit) {
    for (const char* file : {"thinlens.xml", "perspective.xml"}) {
        SCOPED_TRACE(file);
        SceneDescription full = load_file(file);
        // thinlens.xml has its own window; perspective.xml gets one here, with its principal point.
        if (full.camera.film_size == ivec2(0)) {
            full.camera.film_size = ivec2(full.settings.width, full.settings.height);
            full.camera.crop_offset = ivec2(17, 5);
            full.camera.crop_size = ivec2(19, 23);
        }
        SceneDescription crop = full;
        crop.settings.width = crop.camera.crop_size.x;
        crop.settings.height = crop.camera.crop_size.y;
        const ivec2 off = full.camera.crop_offset, size = full.camera.crop_size;
        full.settings.width = full.camera.film_size.x;
        full.settings.height = full.camera.film_size.y;
        full.camera.film_size = full.camera.crop_offset = full.camera.crop_size = ivec2(0);
        std::unique_ptr<Film> f = render(full, 3, 2), c1 = render(crop, 3, 1), c2 = render(crop, 3, 2);
        ASSERT_EQ(c1->width(), size.x);
        ASSERT_EQ(c1->height(), size.y);
        int mismatches = 0;
        for (int y = 0; y < size.y; ++y)
            for (int x = 0; x < size.x; ++x) {
                mismatches += f->pixel_sum(x + off.x, y + off.y) != c1->pixel_sum(x, y);
                mismatches += c1->pixel_sum(x, y) != c2->pixel_sum(x, y);
            }
        EXPECT_EQ(mismatches, 0);
        // The control: the window one pixel to the right is another image.
        int shifted = 0;
        for (int y = 0; y < size.y; ++y)
            for (int x = 0; x < size.x; ++x) shifted += f->pixel_sum(x + off.x + 1, y + off.y) != c1->pixel_sum(x, y);
        EXPECT_GT(shifted, size.x * size.y / 2);
    }
}

namespace {

ImageEstimate load_reference(const std::string& name) { return ImageEstimate::from_reference_files(kData + name); }

ImageEstimate render_batches(const SceneDescription& desc) {
    const int batches = 8, spp = 256;
    std::vector<std::unique_ptr<Film>> films;
    std::vector<const Film*> ptrs;
    for (int b = 0; b < batches; ++b) {
        films.push_back(render(desc, spp, 0, uint64_t(b + 1)));
        ptrs.push_back(films.back().get());
    }
    return ImageEstimate::from_batches(ptrs);
}

constexpr double kAlpha = 0.01;

// Block z-test (4 x 4 blocks) of candela's render against the Mitsuba reference.
BlockTestResult compare(const std::string& name, const SceneDescription& desc) {
    ImageEstimate ref = load_reference(name);
    ImageEstimate test = render_batches(desc);
    EXPECT_EQ(test.width, ref.width);
    EXPECT_EQ(test.height, ref.height);
    return block_z_test(test, ref, 4, kAlpha);
}

void expect_match_and_control(const std::string& name, void (*spoil)(SceneDescription&)) {
    SceneDescription desc = load_file(name + ".xml");
    BlockTestResult r = compare(name, desc);
    std::printf("  %s: %s\n", name.c_str(), r.describe().c_str());
    EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
    spoil(desc);
    BlockTestResult bad = compare(name, desc);
    std::printf("  %s, control: %s\n", name.c_str(), bad.describe().c_str());
    EXPECT_FALSE(bad.passed(kAlpha)) << "the control should fail: " << bad.describe();
}

}  // namespace

TEST(Cameras, PerspectiveMatchesMitsubaReference) {
    // Control: the principal point 1% of the film's width (half a pixel) off.
    expect_match_and_control("perspective", [](SceneDescription& d) { d.camera.principal_point_offset.x += 0.01f; });
}

TEST(Cameras, ThinLensMatchesMitsubaReference) {
    // Control: half the aperture (less blur).
    expect_match_and_control("thinlens", [](SceneDescription& d) { d.camera.aperture_radius *= 0.5f; });
}

TEST(Cameras, OrthographicMatchesMitsubaReference) {
    // Control: an extent 2% too large.
    expect_match_and_control("orthographic", [](SceneDescription& d) {
        d.camera.to_world[0] *= 1.02f;
        d.camera.to_world[1] *= 1.02f;
    });
}

namespace {

std::string load_error(const std::string& body) {
    std::string path = write_temp("scene.xml", "<scene version=\"3.0.0\">\n" + body + "</scene>\n");
    try {
        load_mitsuba_xml(path, {});
    } catch (const Error& e) {
        return std::string(e.what()).substr(path.size());
    }
    return "<no error>";
}

std::string sensor(const std::string& type, const std::string& params, const std::string& film = "") {
    return "<sensor type=\"" + type + "\">\n" + params + "<film type=\"hdrfilm\">\n" + film + "</film>\n</sensor>\n";
}

}  // namespace

TEST(Cameras, BadParametersAreOneLineErrors) {
    struct Case {
        std::string body, expect;
    } cases[] = {
        {sensor("perspective", "<float name=\"fov\" value=\"40\"/>\n<string name=\"focal_length\" value=\"30mm\"/>\n"),
         ":4: give either"},
        {sensor("perspective", "<string name=\"focal_length\" value=\"wide\"/>\n"), ":3: focal_length must be of the form"},
        {sensor("perspective", "<string name=\"focal_length\" value=\"-5mm\"/>\n"), "must be positive"},
        {sensor("perspective", "<float name=\"fov\" value=\"40\"/>\n<string name=\"fov_axis\" value=\"z\"/>\n"),
         ":4: unknown fov_axis"},
        {sensor("thinlens", "<float name=\"fov\" value=\"40\"/>\n"), "needs an 'aperture_radius'"},
        {sensor("thinlens", "<float name=\"aperture_radius\" value=\"-1\"/>\n"), ":3: aperture_radius must not be negative"},
        {sensor("thinlens", "<float name=\"aperture_radius\" value=\"1\"/>\n<float name=\"focus_distance\" value=\"0\"/>\n"),
         ":4: focus_distance must be positive"},
        {sensor("thinlens", "<float name=\"aperture_radius\" value=\"1\"/>\n<float name=\"principal_point_offset_x\" value=\"0.1\"/>\n"),
         "unused parameter 'principal_point_offset_x'"},
        {sensor("orthographic", "<float name=\"fov\" value=\"40\"/>\n"), "unused parameter 'fov'"},
        {sensor("perspective", "<float name=\"near_clip\" value=\"nan\"/>\n"), ":3: "},
        {sensor("perspective", "<transform name=\"to_world\"><scale value=\"2\"/></transform>\n"), "must not scale"},
        {sensor("orthographic", "<transform name=\"to_world\"><scale x=\"0\"/></transform>\n"), "singular"},
        {sensor("perspective", "", "<integer name=\"width\" value=\"10\"/>\n<integer name=\"crop_width\" value=\"11\"/>\n"),
         ":5: the crop window"},
        {sensor("perspective", "", "<integer name=\"crop_offset_y\" value=\"600\"/>\n"), "does not fit"},
        {sensor("perspective", "", "<integer name=\"crop_offset_x\" value=\"-1\"/>\n"), "must not be negative"},
        {sensor("perspective", "", "<integer name=\"crop_height\" value=\"0\"/>\n"), "must be positive"},
        // Values Mitsuba 3.9's hdrfilm refuses too (the ones it takes are notes: FilmFormatsAsMitsuba).
        {sensor("perspective", "", "<string name=\"pixel_format\" value=\"spectrum\"/>\n"), "unknown pixel_format"},
        {sensor("perspective", "", "<string name=\"component_format\" value=\"uint8\"/>\n"), "unknown component_format"},
        {sensor("perspective", "", "<string name=\"file_format\" value=\"png\"/>\n"), "unknown file_format"},
        {sensor("perspective", "", "<boolean name=\"banner\" value=\"maybe\"/>\n"), ":4: "},
        {sensor("radiancemeter", ""), "unsupported sensor type 'radiancemeter'"},
    };
    for (const Case& c : cases) {
        std::string msg = load_error(c.body);
        EXPECT_EQ(msg.rfind(":", 0), 0u) << c.body << " -> " << msg;
        EXPECT_NE(msg.find(c.expect), std::string::npos) << c.body << " -> " << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
}

TEST(Cameras, ParametersAsMitsubaReadsThem) {
    // Mitsuba's defaults: 50 mm, a 46.79 degree diagonal, clip planes 0.01 and 1e4, focus at far_clip.
    SceneDescription d = load_text("d.xml", "<scene version=\"3.0.0\">" + sensor("perspective", "") + "</scene>");
    EXPECT_EQ(d.camera.type, CameraType::Perspective);
    EXPECT_NEAR(d.camera.fov_deg, 46.7930f, 1e-3f);
    EXPECT_EQ(d.camera.fov_axis, FovAxis::Diagonal);
    EXPECT_EQ(d.camera.near_clip, 1e-2f);
    EXPECT_EQ(d.camera.far_clip, 1e4f);
    EXPECT_EQ(d.settings.width, 768);
    EXPECT_EQ(d.settings.height, 576);
    EXPECT_FALSE(d.settings.alpha);
    // focus_distance is read by every projective camera (public scenes give it to perspective);
    // the shutter does not change a static scene.
    SceneDescription p = load_text("p.xml", "<scene version=\"3.0.0\">" +
                                                 sensor("perspective",
                                                        "<float name=\"focus_distance\" value=\"1000\"/>"
                                                        "<float name=\"shutter_open\" value=\"0\"/>"
                                                        "<float name=\"shutter_close\" value=\"0.5\"/>"
                                                        "<string name=\"focal_length\" value=\"35\"/>",
                                                        "<string name=\"pixel_format\" value=\"rgba\"/>"
                                                        "<integer name=\"crop_offset_x\" value=\"10\"/>"
                                                        "<integer name=\"crop_width\" value=\"100\"/>") +
                                                 "</scene>");
    EXPECT_NEAR(p.camera.fov_deg, 63.4400f, 1e-3f);  // 35 mm (no unit) as Mitsuba
    EXPECT_TRUE(p.settings.alpha);
    EXPECT_EQ(p.settings.width, 100);
    EXPECT_EQ(p.settings.height, 576);
    EXPECT_EQ(p.camera.film_size, ivec2(768, 576));
    EXPECT_EQ(p.camera.crop_offset, ivec2(10, 0));
    SceneDescription t = load_text("t.xml", "<scene version=\"3.0.0\">" +
                                                 sensor("thinlens", "<float name=\"aperture_radius\" value=\"0\"/>") +
                                                 "</scene>");
    EXPECT_EQ(t.camera.type, CameraType::ThinLens);
    EXPECT_EQ(t.camera.focus_distance, 1e4f);
    EXPECT_FALSE(t.camera.needs_lens_sample());
}

// Issue 43: Bitterli's scenes as published are Mitsuba 0.5 files whose film carries parameters of
// Mitsuba 0.x's output. Mitsuba 3.9.1 loads this very file (checked with its Python module): hdrfilm
// marks `banner` queried, and lower-cases and accepts every file_format, component_format and
// pixel_format on its lists. candela accepts the same, each with one note; what Mitsuba 3 refuses
// (high_quality_edges, attach_log, gamma: "unreferenced property") stays an error.
TEST(Cameras, LegacyFilmParametersAsMitsuba3) {
    const std::string film =
        "<integer name=\"width\" value=\"32\"/>\n<integer name=\"height\" value=\"16\"/>\n"
        "<boolean name=\"banner\" value=\"false\"/>\n<string name=\"fileFormat\" value=\"rgbe\"/>\n"
        "<string name=\"componentFormat\" value=\"uint32\"/>\n<string name=\"pixelFormat\" value=\"Luminance_Alpha\"/>\n"
        "<rfilter type=\"box\"/>\n";
    auto v05 = [&](const std::string& extra) {
        return "<scene version=\"0.5.0\">\n<sensor type=\"perspective\">\n<film type=\"hdrfilm\">\n" + film + extra +
               "</film>\n</sensor>\n<shape type=\"sphere\"/>\n</scene>\n";
    };
    SceneDescription s = load_text("v05.xml", v05(""));
    EXPECT_EQ(s.settings.width, 32);
    EXPECT_EQ(s.settings.height, 16);
    EXPECT_TRUE(s.settings.alpha);  // luminance_alpha: candela writes RGBA
    ASSERT_EQ(s.warnings.size(), 4u);
    const char* expect[4] = {".xml:9: hdrfilm: pixel_format 'luminance_alpha'", ".xml:8: hdrfilm: component_format 'uint32'",
                             ".xml:7: hdrfilm: file_format 'rgbe'", ".xml:6: hdrfilm: banner ignored"};
    for (int i = 0; i < 4; ++i) {
        EXPECT_NE(s.warnings[size_t(i)].find(expect[i]), std::string::npos) << s.warnings[size_t(i)];
        EXPECT_EQ(s.warnings[size_t(i)].find('\n'), std::string::npos);
    }
    // The control: parameters Mitsuba 3.9.1 reports as unreferenced are still refused.
    for (const char* p : {"<boolean name=\"highQualityEdges\" value=\"true\"/>\n", "<boolean name=\"attachLog\" value=\"false\"/>\n",
                          "<float name=\"gamma\" value=\"2.2\"/>\n"}) {
        try {
            load_text("v05bad.xml", v05(p));
            ADD_FAILURE() << p << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(".xml:11: unused parameter"), std::string::npos) << e.what();
        }
    }
}

namespace {

// An orthographic camera (extent x in [-2, 2], y in [-1, 1] on a 40 x 20 film) facing a rectangle
// of half-width `half_w` and half-height 0.5 at z = 5. Film column of x: 20 (1 - x / 2), row of y:
// 10 (1 - y): the rectangle's rows 5..14 are whole pixels, its columns end inside pixels 10 and 29.
std::string coverage_scene(float half_w, const std::string& pixel_format = "rgba") {
    return "<scene version=\"3.0.0\">\n"
           "<sensor type=\"orthographic\"><transform name=\"to_world\"><scale x=\"2\" y=\"2\"/></transform>\n"
           "<film type=\"hdrfilm\"><integer name=\"width\" value=\"40\"/><integer name=\"height\" value=\"20\"/>\n"
           "<string name=\"pixel_format\" value=\"" + pixel_format + "\"/><rfilter type=\"box\"/></film></sensor>\n"
           "<shape type=\"rectangle\"><transform name=\"to_world\"><scale x=\"" + std::to_string(half_w) +
           "\" y=\"0.5\"/><translate z=\"5\"/></transform></shape>\n</scene>\n";
}

// z of the mean alpha of the partly covered columns 10 and 29 (rows 6..13) against `expected`.
double edge_alpha_z(const Film& f, int spp, double expected) {
    double sum = 0;
    int n = 0;
    for (int y = 6; y <= 13; ++y)
        for (int x : {10, 29}) {
            sum += f.alpha(x, y);
            ++n;
        }
    double samples = double(n) * spp;
    return (sum / n - expected) / std::sqrt(expected * (1 - expected) / samples);
}

}  // namespace

TEST(Cameras, AlphaIsTheFractionOfCameraRaysThatHit) {
    const int spp = 256;
    SceneDescription d = load_text("cov.xml", coverage_scene(0.93f));
    ASSERT_TRUE(d.settings.alpha);
    std::shared_ptr<const Scene> scene = build_scene(d);
    Film film(40, 20);
    film.enable_alpha();
    Renderer::render_pass(*scene, film, 0, spp, 0);
    // Whole pixels inside are 1, outside 0, exactly; the edge columns are 30% covered.
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 40; ++x) {
            bool inside = y >= 5 && y <= 14 && x >= 11 && x <= 28, outside = y <= 3 || y >= 16 || x <= 9 || x >= 30;
            if (inside) {
                EXPECT_EQ(film.alpha(x, y), 1.f) << x << "," << y;
            } else if (outside) {
                EXPECT_EQ(film.alpha(x, y), 0.f) << x << "," << y;
            }
        }
    double z = edge_alpha_z(film, spp, 0.3);
    EXPECT_LT(std::abs(z), 3.3) << "p < 0.001";  // two-sided
    // The control: a rectangle reaching pixel 10.5 (x = 0.95) covers 50%, which the test sees.
    SceneDescription wide = load_text("cov_wide.xml", coverage_scene(0.95f));
    Film film2(40, 20);
    film2.enable_alpha();
    Renderer::render_pass(*build_scene(wide), film2, 0, spp, 0);
    double z_control = edge_alpha_z(film2, spp, 0.3);
    std::printf("  edge coverage 0.3: z = %.2f; control (0.5 covered) z = %.1f\n", z, z_control);
    EXPECT_GT(std::abs(z_control), 3.3);
}

namespace {

// RGBA of an EXR through tinyexr (A is 1 where the file has no alpha channel).
std::vector<float> load_rgba(const std::string& path, int& w, int& h) {
    float* rgba = nullptr;
    const char* err = nullptr;
    std::vector<float> out;
    if (LoadEXR(&rgba, &w, &h, path.c_str(), &err) != TINYEXR_SUCCESS) {
        if (err) FreeEXRErrorMessage(err);
        return out;
    }
    out.assign(rgba, rgba + size_t(w) * size_t(h) * 4);
    std::free(rgba);
    return out;
}

}  // namespace

TEST(Cameras, RgbaFilmWritesAlphaAndResumesBitForBit) {
    const std::string d = test::temp_dir("cam_rgba");
    test::write_text(d + "/rgba.xml", coverage_scene(0.93f));
    test::write_text(d + "/rgb.xml", coverage_scene(0.93f, "rgb"));
    const std::string q = " --quiet --frames 6 --out ";
    ASSERT_EQ(test::run_candela(d + "/rgba.xml" + q + d + "/full.exr").exit_code, 0);
    ASSERT_EQ(test::run_candela(d + "/rgb.xml" + q + d + "/rgb.exr").exit_code, 0);
    // 2 passes, checkpointed, then resumed to 6 on another thread count.
    ASSERT_EQ(test::run_candela(d + "/rgba.xml --quiet --frames 2 --threads 1 --out " + d + "/part.exr --checkpoint " +
                                d + "/part.ck").exit_code, 0);
    test::RunResult r = test::run_candela(d + "/rgba.xml" + q + d + "/resumed.exr --threads 2 --checkpoint " + d +
                                          "/part.ck --resume " + d + "/part.ck");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    int w = 0, h = 0;
    std::vector<float> full = load_rgba(d + "/full.exr", w, h), resumed = load_rgba(d + "/resumed.exr", w, h);
    ASSERT_EQ(w, 40);
    ASSERT_EQ(h, 20);
    ASSERT_EQ(full.size(), resumed.size());
    EXPECT_TRUE(full == resumed);
    auto alpha = [&](const std::vector<float>& img, int x, int y) { return img[(size_t(y) * 40 + size_t(x)) * 4 + 3]; };
    EXPECT_EQ(alpha(full, 20, 10), 1.f);
    EXPECT_EQ(alpha(full, 2, 2), 0.f);
    std::vector<float> rgb = load_rgba(d + "/rgb.exr", w, h);
    EXPECT_EQ(alpha(rgb, 2, 2), 1.f);  // no A channel: tinyexr's default
    // A checkpoint without alpha does not resume an rgba render.
    ASSERT_EQ(test::run_candela(d + "/rgb.xml --quiet --frames 2 --out " + d + "/p2.exr --checkpoint " + d + "/rgb.ck")
                  .exit_code, 0);
    test::RunResult bad = test::run_candela(d + "/rgba.xml" + q + d + "/x.exr --resume " + d + "/rgb.ck");
    EXPECT_EQ(bad.exit_code, 1) << bad.output;
}

TEST(Cameras, ViewerControlsKeepTheOrthographicExtent) {
    SceneDescription d = load_file("orthographic.xml");
    std::shared_ptr<const Scene> scene = build_scene(d);
    const Camera start = scene->camera;
    auto lengths = [](const Camera& c) {
        return vec3(glm::length(vec3(c.to_world[0])), glm::length(vec3(c.to_world[1])), glm::length(vec3(c.to_world[2])));
    };
    CameraController ctl(start, scene->geometry->bounds);
    Camera c = start;
    ctl.orbit(0.3f, 0.1f);
    ctl.apply(c);
    EXPECT_NEAR(glm::length(lengths(c) - lengths(start)), 0.f, 1e-5f);
    EXPECT_GT(glm::length(c.forward() - start.forward()), 0.1f);
    // Pan follows the drag: after pan(0.1, 0) the image centre shows what was 10% of the width to
    // its right.
    ctl.reset(start, scene->geometry->bounds);
    ctl.pan(0.1f, 0.f);
    ctl.apply(c);
    c.set_film_size(scene->settings.width, scene->settings.height);
    const float w = float(scene->settings.width), h = float(scene->settings.height);
    Ray moved = c.generate_ray(vec2(0.5f * w, 0.5f * h)), before = start.generate_ray(vec2(0.6f * w, 0.5f * h));
    EXPECT_LT(glm::length(moved.o - before.o), 1e-4f);
    EXPECT_LT(glm::length(moved.d - before.d), 1e-6f);
    // The wheel zooms: the extent shrinks by 0.85 per step, the position stays.
    ctl.reset(start, scene->geometry->bounds);
    ctl.dolly(1.f);
    ctl.apply(c);
    EXPECT_NEAR(lengths(c).x, 0.85f * lengths(start).x, 1e-5f);
    EXPECT_NEAR(lengths(c).y, 0.85f * lengths(start).y, 1e-5f);
    EXPECT_LT(glm::length(vec3(c.to_world[3]) - start.origin()), 1e-5f);
}

TEST(Cameras, PickFollowsTheCameraTypeAndTheCrop) {
    // Orthographic: the centre pixel sees the rectangle at z = 5, from the near plane (z = 0.01).
    SceneDescription cov = load_text("cov.xml", coverage_scene(0.93f));
    std::shared_ptr<const Scene> s = build_scene(cov);
    PickResult p = pick(*s, s->camera, vec2(20.f, 10.f));
    ASSERT_TRUE(p.hit);
    EXPECT_NEAR(p.position.z, 5.f, 1e-5f);
    EXPECT_NEAR(p.distance, 4.99f, 1e-4f);
    EXPECT_FALSE(pick(*s, s->camera, vec2(2.f, 2.f)).hit);
    // A crop: image pixel (x, y) is film pixel (x, y) + crop offset.
    SceneDescription crop = load_file("thinlens.xml");
    crop.camera.aperture_radius = 0.f;  // pick traces the lens centre: compare pinholes
    SceneDescription full = crop;
    full.settings.width = crop.camera.film_size.x;
    full.settings.height = crop.camera.film_size.y;
    const ivec2 off = crop.camera.crop_offset;
    full.camera.film_size = full.camera.crop_offset = full.camera.crop_size = ivec2(0);
    std::shared_ptr<const Scene> sc = build_scene(crop), sf = build_scene(full);
    for (ivec2 px : {ivec2(3, 4), ivec2(20, 10), ivec2(31, 19)}) {
        PickResult a = pick(*sc, sc->camera, vec2(px) + 0.5f), b = pick(*sf, sf->camera, vec2(px + off) + 0.5f);
        ASSERT_EQ(a.hit, b.hit);
        EXPECT_EQ(a.position, b.position);
        EXPECT_EQ(a.shape, b.shape);
    }
}

namespace {

std::string read_text(const std::string& path) {
    std::ifstream f(path);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
    size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) s.replace(at, from.size(), to);
    return s;
}

}  // namespace

// The checkpoint's fingerprint probes the camera by its rays: resuming with another aperture,
// focus distance, fov axis, principal point, crop offset or orthographic extent is refused.
TEST(Cameras, CheckpointRefusesAnotherCamera) {
    const std::string d = test::temp_dir("cam_ck");
    struct Edit {
        const char *file, *from, *to;
    } edits[] = {
        {"thinlens.xml", "name=\"aperture_radius\" value=\"0.25\"", "name=\"aperture_radius\" value=\"0.26\""},
        {"thinlens.xml", "name=\"focus_distance\" value=\"6\"", "name=\"focus_distance\" value=\"6.1\""},
        {"thinlens.xml", "value=\"smaller\"", "value=\"x\""},
        {"thinlens.xml", "name=\"crop_offset_x\" value=\"8\"", "name=\"crop_offset_x\" value=\"9\""},
        {"perspective.xml", "name=\"principal_point_offset_y\" value=\"-0.06\"",
         "name=\"principal_point_offset_y\" value=\"-0.05\""},
        {"orthographic.xml", "<scale x=\"3\" y=\"3\"/>", "<scale x=\"3\" y=\"3.05\"/>"},
    };
    int i = 0;
    for (const Edit& e : edits) {
        SCOPED_TRACE(e.to);
        const std::string base = read_text(kData + e.file), tag = d + "/" + std::to_string(i++);
        test::write_text(tag + "a.xml", base);
        test::write_text(tag + "b.xml", replaced(base, e.from, e.to));
        const std::string opts = " --quiet --frames 1 --out " + tag + ".exr";
        ASSERT_EQ(test::run_candela(tag + "a.xml" + opts + " --checkpoint " + tag + ".ck").exit_code, 0);
        EXPECT_EQ(test::run_candela(tag + "a.xml" + opts + " --resume " + tag + ".ck").exit_code, 0);
        test::RunResult r = test::run_candela(tag + "b.xml" + opts + " --resume " + tag + ".ck");
        EXPECT_EQ(r.exit_code, 1) << r.output;
        EXPECT_NE(r.output.find("another scene or other settings"), std::string::npos) << r.output;
    }
}
