// Reconstruction filters (issue 13): box, tent and gaussian with Mitsuba 3's weighting (a sample
// adds w L to every pixel within the radius; a pixel is sum(w L) / sum(w)), its discretised
// weights, and the guarantees of the film around them: bit-for-bit determinism across thread counts
// and pass splits with a wide filter, and checkpoint/resume.
//
// The image tests compare candela with committed Mitsuba 3.9.1 references of the Cornell box at
// 32 x 32 (path tracing, Mitsuba max_depth 3) with each filter, made by
//   $PY tests/data/make_reference.py tests/data/scenes/cbox_filter.xml --res 32 --batches 16
//       --spp 2048 --variant scalar_rgb -D filter=F --out tests/data/filter_F
//   (F = box, tent, gaussian, mitchell, catmullrom, lanczos)
// (scalar_rgb: Mitsuba's scalar image block uses the discretised filter, as candela does). The
// control: the box-filtered image must be rejected against the gaussian reference (the Cornell
// box's edges and light make the blur visible).
#include <gtest/gtest.h>
#include <cmath>
#include <cstring>
#include <memory>
#include "core/error.h"
#include "film/image_io.h"
#include "integrator/tiles.h"
#include "render/launch.h"
#include "render/renderer.h"
#include "scene/loaders.h"
#include "support/run.h"
#include "support/render.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;

ImageEstimate load_reference(const std::string& prefix) { return ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/" + prefix); }

std::string filter_scene() { return std::string(CANDELA_TEST_DATA) + "/scenes/cbox_filter.xml"; }

ImageEstimate render_batches(const std::string& filter, int batches, int spp) {
    const std::shared_ptr<const Scene> built = build_scene(load_scene(filter_scene(), {{"filter", filter}}));
    return candela::test::render_batch_estimate(*built, built->params(), batches, spp);
}

}  // namespace

TEST(Filters, MitsubaDefinitionsAndDiscretisation) {
    PixelFilter g(gaussian_filter());
    EXPECT_FLOAT_EQ(g.radius(), 2.f);
    EXPECT_FLOAT_EQ(g.eval(0.f), 1.f - std::exp(-8.f));
    EXPECT_FLOAT_EQ(g.eval(2.f), 0.f);
    EXPECT_FLOAT_EQ(g.eval(1.f), std::exp(-2.f) - std::exp(-8.f));
    // Tabulated at radius * i / 31, looked up by truncation of |x| * 31 / radius.
    EXPECT_EQ(g.eval_discretized(0.3f), g.eval(2.f * 4.f / 31.f));
    EXPECT_EQ(g.eval_discretized(-0.3f), g.eval_discretized(0.3f));
    EXPECT_EQ(g.eval_discretized(1.99f), g.eval(2.f * 30.f / 31.f));
    EXPECT_EQ(g.eval_discretized(2.5f), 0.f);
    PixelFilter t(tent_filter());
    EXPECT_FLOAT_EQ(t.radius(), 1.f);
    EXPECT_FLOAT_EQ(t.eval(0.25f), 0.75f);
    EXPECT_EQ(t.eval_discretized(0.5f), t.eval(15.f / 31.f));
    PixelFilter t2(tent_filter(2.5f));
    EXPECT_FLOAT_EQ(t2.eval(1.f), 0.6f);
    EXPECT_EQ(g.reach(), 2);
    EXPECT_EQ(t.reach(), 1);
    EXPECT_EQ(PixelFilter(gaussian_filter(1.f)).reach(), 4);
}

// The filters with negative lobes against Mitsuba 3.9.1's own eval and eval_discretized (printed by
// mi.load_dict({'type': 'mitchell', ...}).eval(x) in scalar_rgb).
TEST(Filters, NegativeLobedFiltersMatchMitsubasValues) {
    struct Row {
        FilterDesc desc;
        float radius;
        float at[6];  // eval at 0, 0.3, 0.9, 1.4, 1.99, 2.5
        float disc[2];  // eval_discretized at 0.3, 1.4
    };
    const Row rows[] = {
        {mitchell_filter(), 2.f, {0.88888896f, 0.74038899f, 0.11938893f, -0.035999898f, -3.2797383e-05f, 0.f},
         {0.77574509f, -0.034312934f}},
        {mitchell_filter(0.2f, 0.4f), 2.f, {0.93333334f, 0.77043331f, 0.099033192f, -0.050400402f, -3.995611e-05f, 0.f},
         {0.8091616f, -0.050127298f}},
        {catmullrom_filter(), 2.f, {1.f, 0.81550002f, 0.068499967f, -0.072000027f, -4.9273174e-05f, 0.f},
         {0.85928643f, -0.073847935f}},
        {lanczos_filter(), 3.f, {1.f, 0.84434313f, 0.09381593f, -0.14668514f, -0.0021004691f, 0.024317075f},
         {0.8537122f, -0.1469572f}},
        {lanczos_filter(2), 2.f, {1.f, 0.82697457f, 0.076356769f, -0.079549633f, -2.5246434e-05f, 0.f},
         {0.86971271f, -0.084112875f}},
    };
    const float xs[6] = {0.f, 0.3f, 0.9f, 1.4f, 1.99f, 2.5f};
    for (const Row& r : rows) {
        const PixelFilter f(r.desc);
        EXPECT_EQ(f.radius(), r.radius) << filter_name(r.desc.type);
        for (int i = 0; i < 6; ++i) EXPECT_NEAR(f.eval(xs[i]), r.at[i], 2e-6f) << filter_name(r.desc.type) << " at " << xs[i];
        EXPECT_NEAR(f.eval_discretized(0.3f), r.disc[0], 2e-6f) << filter_name(r.desc.type);
        EXPECT_NEAR(f.eval_discretized(1.4f), r.disc[1], 2e-6f) << filter_name(r.desc.type);
    }
}

TEST(Filters, OneSampleSplatsMitsubasWeights) {
    Film film(8, 8);
    film.set_layout(true, 0);
    PixelFilter f(gaussian_filter());
    FilmTile t;
    t.reset(film, 0, 0, 8, 8, f.reach());
    const vec2 pos(3.7f, 4.2f);
    detail::splat(t, f, 8, 8, pos, vec3(2.f), nullptr);
    film.merge(t);
    int touched = 0;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            const float dx = float(x) + 0.5f - pos.x, dy = float(y) + 0.5f - pos.y;
            const bool inside = std::abs(dx) <= f.radius() && std::abs(dy) <= f.radius();
            const double w = inside ? double(f.eval_discretized(dx) * f.eval_discretized(dy)) : 0.0;
            EXPECT_NEAR(film.weights()[size_t(y * 8 + x)], w, 1e-7) << x << "," << y;
            touched += w > 0;
            if (w > 0) {
                EXPECT_NEAR(film.pixel(x, y).x, 2.f, 1e-6f);
            }
        }
    EXPECT_EQ(touched, 16);  // pixel centres within 2 of (3.7, 4.2): x in 2..5, y in 3..6
}

TEST(Filters, EachFilterMatchesMitsuba) {
    for (const char* f : {"box", "tent", "gaussian", "mitchell", "catmullrom", "lanczos"}) {
        ImageEstimate ref = load_reference(std::string("filter_") + f);
        ImageEstimate test = render_batches(f, 8, 128);
        BlockTestResult r = block_z_test(test, ref, 4, kAlpha);
        std::printf("  %s: %s\n", f, r.describe().c_str());
        EXPECT_TRUE(r.passed(kAlpha)) << f << ": " << r.describe();
    }
}

TEST(Filters, BoxImageIsRejectedAgainstTheGaussianReference) {
    ImageEstimate ref = load_reference("filter_gaussian");
    ImageEstimate box = render_batches("box", 8, 128);
    BlockTestResult r = block_z_test(box, ref, 4, kAlpha);
    std::printf("  box against gaussian: %s\n", r.describe().c_str());
    EXPECT_FALSE(r.passed(kAlpha));
}

TEST(Filters, WideFilterIsDeterministicAcrossThreadsAndPassSplits) {
    // Gaussian of stddev 1: radius 4, every sample reaches 4 pixels into its neighbours' tiles.
    SceneOverrides ov;
    ov.width = 40;
    ov.height = 36;
    auto box = prepare_scene("", ov);
    SceneParams p = box->params();
    p.settings.filter = gaussian_filter(1.f);
    auto scene = box->with_params(p);
    Film one(40, 36), two(40, 36), split(40, 36);
    for (int k = 0; k < 3; ++k) Renderer::render_pass(*scene, one, uint32_t(2 * k), 2, 1);
    for (int k = 0; k < 3; ++k) Renderer::render_pass(*scene, two, uint32_t(2 * k), 2, 2);
    for (int k = 0; k < 6; ++k) Renderer::render_pass(*scene, split, uint32_t(k), 1, 2);
    ASSERT_TRUE(one.weighted());
    for (int y = 0; y < 36; ++y)
        for (int x = 0; x < 40; ++x) {
            ASSERT_EQ(one.sample_count(x, y), 6u);
            dvec3 a = one.pixel_sum(x, y), b = two.pixel_sum(x, y), c = split.pixel_sum(x, y);
            ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << x << "," << y;
            ASSERT_EQ(std::memcmp(&a, &c, sizeof a), 0) << x << "," << y;
            ASSERT_EQ(one.weights()[size_t(y * 40 + x)], two.weights()[size_t(y * 40 + x)]);
        }
    // Not vacuous: the filtered image differs from the box-filtered one.
    Film b(40, 36);
    for (int k = 0; k < 3; ++k) Renderer::render_pass(*box, b, uint32_t(2 * k), 2, 2);
    EXPECT_FALSE(b.weighted());
    EXPECT_NE(b.pixel(20, 3).x, one.pixel(20, 3).x);
}

TEST(Filters, ConstantRadianceStaysExactUpToTheEdges) {
    // The camera inside a closed box that emits Le everywhere and reflects nothing: every sample is
    // Le, so every pixel, edges included (fewer neighbours, smaller weight sum), is Le.
    SceneDescription d;
    d.source = "<emissive box>";
    d.materials.push_back({"black", DiffuseBsdf{vec3(0.f)}, false});
    d.emitters.push_back({vec3(1.5f, 0.5f, 2.f)});
    std::vector<vec3> v;
    std::vector<uvec3> tris;
    for (int axis = 0; axis < 3; ++axis)
        for (int s = -1; s <= 1; s += 2) {
            vec3 n(0.f), u(0.f), w(0.f);
            n[axis] = float(s);
            u[(axis + 1) % 3] = 1.f;
            w[(axis + 2) % 3] = 1.f;
            uint32_t b = uint32_t(v.size());
            for (vec3 c : {n - u - w, n + u - w, n + u + w, n - u + w}) v.push_back(5.f * c);
            // Wound so that the normal points inwards (-n), the side the camera is on.
            if (glm::dot(glm::cross(u, w), n) > 0.f) tris.insert(tris.end(), {uvec3(b, b + 2, b + 1), uvec3(b, b + 3, b + 2)});
            else tris.insert(tris.end(), {uvec3(b, b + 1, b + 2), uvec3(b, b + 2, b + 3)});
        }
    d.add_shape("box", v, {}, tris, 0, 0);
    d.settings.width = 20;
    d.settings.height = 12;
    d.settings.filter = gaussian_filter();
    d.camera.to_world = look_at(vec3(0.f), vec3(0.3f, 0.1f, 1.f), vec3(0.f, 1.f, 0.f));
    auto scene = build_scene(std::move(d));
    Film film(20, 12);
    Renderer::render_pass(*scene, film, 0, 3, 2);
    for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 20; ++x) {
            vec3 p = film.pixel(x, y);
            EXPECT_NEAR(p.x, 1.5f, 1e-6f) << x << "," << y;
            EXPECT_NEAR(p.z, 2.f, 1e-6f) << x << "," << y;
        }
}

TEST(Filters, CheckpointResumeWithAWideFilter) {
    std::string d = test::temp_dir("filter-checkpoint");
    const std::string common = filter_scene() + " -D res=20 -D filter=gaussian --seed 4 --quiet --threads 2 ";
    auto full = test::run_candela(common + "--frames 6 --out " + d + "/full.exr");
    ASSERT_EQ(full.exit_code, 0) << full.output;
    auto first = test::run_candela(common + "--frames 3 --checkpoint " + d + "/c.ckpt --out " + d + "/half.exr");
    ASSERT_EQ(first.exit_code, 0) << first.output;
    auto rest = test::run_candela(common + "--frames 6 --resume " + d + "/c.ckpt --out " + d + "/resumed.exr");
    ASSERT_EQ(rest.exit_code, 0) << rest.output;
    Image a = read_linear_image(d + "/full.exr"), b = read_linear_image(d + "/resumed.exr");
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    EXPECT_EQ(std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * 4), 0);
    // The same checkpoint under the box filter is another render: refused in one line.
    auto other = test::run_candela(filter_scene() + " -D res=20 -D filter=box --seed 4 --quiet --frames 6 --resume " + d +
                                   "/c.ckpt --out " + d + "/x.exr");
    EXPECT_EQ(other.exit_code, 1) << other.output;
    EXPECT_NE(other.output.find("refusing to resume"), std::string::npos) << other.output;
}

TEST(Filters, XmlParametersDefaultsAndErrors) {
    std::string d = test::temp_dir("filter-xml");
    std::string text = test::read_bytes(filter_scene());
    for (size_t at; (at = text.find("../../../scenes/")) != std::string::npos;)
        text.replace(at, 16, std::string(CANDELA_SOURCE_DIR) + "/scenes/");
    auto load = [&](const std::string& rfilter) {
        std::string t = text;
        size_t at = t.find("            <rfilter type=\"$filter\"/>\n");
        t.replace(at, std::string("            <rfilter type=\"$filter\"/>\n").size(), rfilter);
        test::write_text(d + "/scene.xml", t);
        return load_scene(d + "/scene.xml", {});
    };
    EXPECT_EQ(load("").settings.filter, gaussian_filter());  // Mitsuba's default
    EXPECT_EQ(load("<rfilter type=\"box\"/>").settings.filter, box_filter());
    EXPECT_EQ(load("<rfilter type=\"tent\"/>").settings.filter, tent_filter(1.f));
    EXPECT_EQ(load("<rfilter type=\"tent\"><float name=\"radius\" value=\"1.5\"/></rfilter>").settings.filter, tent_filter(1.5f));
    EXPECT_EQ(load("<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"0.25\"/></rfilter>").settings.filter,
              gaussian_filter(0.25f));
    EXPECT_FLOAT_EQ(gaussian_filter(0.25f).radius, 1.f);
    // Mitsuba's image block takes any filter of radius 0.5 for the box.
    EXPECT_EQ(load("<rfilter type=\"tent\"><float name=\"radius\" value=\"0.5\"/></rfilter>").settings.filter, box_filter());
    // The built-in box and OBJ scenes keep the box.
    EXPECT_EQ(RenderSettings().filter, box_filter());
    auto expect_error = [&](const std::string& rfilter, const std::string& needle) {
        try {
            load(rfilter);
            ADD_FAILURE() << "no error for " << rfilter;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("scene.xml:"), std::string::npos) << e.what();
        }
    };
    EXPECT_EQ(load("<rfilter type=\"mitchell\"/>").settings.filter, mitchell_filter());
    EXPECT_EQ(load("<rfilter type=\"mitchell\"><float name=\"B\" value=\"0.5\"/><float name=\"C\" value=\"0.25\"/></rfilter>")
                  .settings.filter,
              mitchell_filter(0.5f, 0.25f));
    EXPECT_EQ(load("<rfilter type=\"catmullrom\"/>").settings.filter, catmullrom_filter());
    EXPECT_EQ(load("<rfilter type=\"lanczos\"><integer name=\"lobes\" value=\"2\"/></rfilter>").settings.filter,
              lanczos_filter(2));
    expect_error("<rfilter type=\"lanczos\"><integer name=\"lobes\" value=\"0\"/></rfilter>", "lobes");
    expect_error("<rfilter type=\"mitchell\"><float name=\"B\" value=\"1e30\"/></rfilter>", "B must be finite");
    expect_error("<rfilter type=\"catmullrom\"><float name=\"C\" value=\"0.5\"/></rfilter>", "C");
    expect_error("<rfilter type=\"blackman\"/>", "unsupported rfilter type 'blackman'");
    expect_error("<rfilter type=\"box\"><float name=\"radius\" value=\"1\"/></rfilter>", "radius");
    expect_error("<rfilter type=\"tent\"><float name=\"radius\" value=\"-1\"/></rfilter>", "radius");
    expect_error("<rfilter type=\"tent\"><float name=\"radius\" value=\"nan\"/></rfilter>", "radius");
    expect_error("<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"1e9\"/></rfilter>", "stddev");
    expect_error("<rfilter type=\"gaussian\"><float name=\"radius\" value=\"2\"/></rfilter>", "radius");
}
