// Mitsuba 3's `envmap` (light/envmap.h, EnvmapLight in light/emitter.h) and Distribution2D:
// * Distribution2D: chi-square of sample() against pdf(); sample's pdf equals pdf().
// * the envmap's sample_li directions: chi-square against pdf_li, on a grid in the map's own
//   (u, v) (its cells align with the map's, so the expected counts are exact); sample_li's pdf
//   and Le equal pdf_li and eval_infinite at the direction it returns; pdf_li integrates to 1 and
//   L / pdf to the map's integral (both estimated with uniform directions, independent of the
//   lat-long mapping); sample_le's directions match pdf_le; no NaN or inf at the poles.
// * eval against Mitsuba: tests/data/envmap_eval_mitsuba.txt (make_envmap_reference.py: Mitsuba
//   3.9.1 scalar_rgb eval for 90 directions and four cases: an EXR, the EXR turned and scaled,
//   an sRGB PNG, an RGBE .hdr), each within 1e-3 relative.
// * an image against Mitsuba: tests/data/scenes/envmap.xml (a diffuse and a rough-conductor sphere
//   on a floor under the turned, scaled map, which is also seen directly), reference
//   tests/data/envmap_scene_{mean,var}.exr, block z-test; controls: 3% dimmer and the map turned
//   by 180 degrees are rejected.
// * the white furnace: a white diffuse sphere inside a uniform white envmap is 1 everywhere
//   (path: light, BSDF, MIS sampling; direct); hide_emitters hides the map from camera rays.
// * XML: defaults, errors with file:line, one environment emitter per scene (as Mitsuba).
#include <gtest/gtest.h>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <glm/gtc/matrix_transform.hpp>
#include "core/error.h"
#include "light/area.h"
#include "light/envmap.h"
#include "render/renderer.h"
#include "sampling/distribution.h"
#include "sampling/pcg32.h"
#include "sampling/warp.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "support/load_error.h"
#include "support/render.h"
#include "support/run.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;

std::string data(const std::string& f) { return std::string(CANDELA_TEST_DATA) + "/" + f; }

DomainSample smooth(vec3 p) {
    DomainSample s;
    s.kind = DomainSample::Smooth;
    s.p = dvec3(p);
    return s;
}

// The quadrant map of make_envmap_reference.py, turned and scaled as its case "rot".
EnvmapLight rotated_light() {
    EnvmapLight l;
    l.map = EnvironmentMap::load(data("textures/envmap_quadrants.exr"));
    l.scale = vec3(2.5f);
    l.to_world = glm::mat3(glm::rotate(mat4(1.f), glm::radians(70.f), vec3(0, 1, 0)) *
                           glm::rotate(mat4(1.f), glm::radians(30.f), vec3(1, 0, 0)));
    l.update();
    return l;
}

// Directions through the light's own lat-long coordinates: g = (u - half texel, v), so that a
// grid of k W x k (H - 1) cells has the map's cells as unions of its cells.
Domain latlong_domain(const EnvmapLight& l) {
    const float half = 0.5f / float(l.map->width());
    Domain d;
    d.name = "latlong";
    d.to_point = [=](dvec2 g) {
        float s;
        return dvec3(l.from_local(EnvironmentMap::uv_to_direction(vec2(float(g.x) + half, float(g.y)), s)));
    };
    d.to_grid = [=](const dvec3& p, dvec2& g) {
        vec2 uv = EnvironmentMap::direction_to_uv(l.to_local(vec3(p)));
        double s = double(uv.x) - half;
        s -= std::floor(s);
        g = dvec2(std::min(s, 1.0 - 1e-12), std::min(double(uv.y), 1.0 - 1e-12));
        return true;
    };
    d.jacobian = [](dvec2 g) { return 2.0 * M_PI * M_PI * std::sin(M_PI * g.y); };
    return d;
}

}  // namespace

// ---- Distribution2D -----------------------------------------------------------------------------

TEST(Envmap, Distribution2DMatchesItsPdf) {
    const int nu = 7, nv = 5;
    std::vector<float> w(nu * nv);
    PCG32 r(3, 1);
    for (float& x : w) x = r.next_float() < 0.2f ? 0.f : r.next_float() * 4.f;
    w[2 * nu + 3] = 30.f;                                   // a peak
    for (int i = 0; i < nu; ++i) w[size_t(4 * nu + i)] = 0.f;  // an empty row
    Distribution2D d(w, nu, nv);
    ChiSquareSetup s;
    s.domain = square_domain();
    s.res_x = 2 * nu;
    s.res_y = 2 * nv;
    s.samples = 400000;
    s.sample = [&](PCG32& g) {
        vec2 uv;
        float pdf;
        if (!d.sample(vec2(g.next_float(), g.next_float()), uv, pdf)) return DomainSample{};
        return smooth(vec3(uv, 0.f));
    };
    s.pdf = [&](const dvec3& p) { return double(d.pdf(vec2(p))); };
    ChiSquareResult res = chi_square_2d(s);
    std::printf("  distribution2d %s\n", res.describe().c_str());
    EXPECT_GE(res.p_value, kAlpha) << res.describe();
    EXPECT_NEAR(res.pdf_integral, 1.0, 1e-5);
    // The pdf sample() returns is pdf() at the point; empty cells are never returned.
    for (int k = 0; k < 20000; ++k) {
        vec2 uv;
        float pdf;
        ASSERT_TRUE(d.sample(vec2(r.next_float(), r.next_float()), uv, pdf));
        ASSERT_GT(pdf, 0.f);
        ASSERT_NEAR(pdf, d.pdf(uv), 1e-5f * pdf);
        ASSERT_LT(uv.y, 0.8f);  // not the empty row
    }
    // Control: a pdf that ignores the peak is rejected.
    s.pdf = [&](const dvec3& p) {
        vec2 q(p);
        return int(q.x * nu) == 3 && int(q.y * nv) == 2 ? 0.5 * d.pdf(q) : double(d.pdf(q));
    };
    EXPECT_LT(chi_square_2d(s).p_value, kAlpha);
}

// ---- sampling -----------------------------------------------------------------------------------

TEST(Envmap, SampleLiMatchesPdfLi) {
    const EnvmapLight l = rotated_light();
    const SceneSphere sphere{vec3(0.5f, -1.f, 2.f), 3.f};
    const LightModel m = l;
    ChiSquareSetup s;
    s.domain = latlong_domain(l);
    s.res_x = 2 * l.map->width();
    s.res_y = 4 * (l.map->height() - 1);
    s.samples = 1000000;
    s.sample = [&](PCG32& g) {
        LightSample ls;
        if (!sample_li(m, sphere, vec3(0.3f), vec2(g.next_float(), g.next_float()), ls)) return DomainSample{};
        return smooth(ls.wi);
    };
    s.pdf = [&](const dvec3& w) { return double(pdf_li(m, vec3(w))); };
    ChiSquareResult r = chi_square_2d(s);
    std::printf("  sample_li   %s\n", r.describe().c_str());
    EXPECT_GE(r.p_value, kAlpha) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);

    // sample_le's directions (travelling away from the light) against pdf_le.
    s.sample = [&](PCG32& g) {
        auto es = sample_le(m, sphere, vec2(g.next_float(), g.next_float()), vec2(g.next_float(), g.next_float()));
        return es ? smooth(-es->ray.d) : DomainSample{};
    };
    s.pdf = [&](const dvec3& w) {
        float pp, pd;
        pdf_le(m, sphere, -vec3(w), pp, pd);
        return double(pd);
    };
    r = chi_square_2d(s);
    std::printf("  sample_le   %s\n", r.describe().c_str());
    EXPECT_GE(r.p_value, kAlpha) << r.describe();

    // Control: the same test against a uniform pdf fails.
    s.pdf = [](const dvec3&) { return double(kInv4Pi); };
    EXPECT_LT(chi_square_2d(s).p_value, kAlpha);
}

TEST(Envmap, SampleLiReturnsPdfLiAndEval) {
    const LightModel m = rotated_light();
    const SceneSphere sphere{vec3(0.f), 1.f};
    PCG32 r(11, 1);
    int n = 0, pdf_off = 0, le_off = 0;
    for (int k = 0; k < 200000; ++k) {
        LightSample s;
        if (!sample_li(m, sphere, vec3(0.f), vec2(r.next_float(), r.next_float()), s)) continue;
        ++n;
        ASSERT_TRUE(std::isfinite(s.pdf) && s.pdf > 0.f);
        ASSERT_TRUE(s.infinite && !s.delta);
        const float p = pdf_li(m, s.wi);
        const vec3 e = eval_infinite(m, s.wi);
        if (std::abs(p - s.pdf) > 1e-3f * s.pdf) ++pdf_off;
        if (glm::length(e - s.Le) > 1e-3f * glm::length(s.Le) + 1e-6f) ++le_off;
    }
    EXPECT_GT(n, 199000);
    // A direction rounded across a cell border can see its neighbour's density: rare.
    EXPECT_LE(pdf_off, n / 10000) << pdf_off << " of " << n;
    EXPECT_LE(le_off, n / 10000) << le_off << " of " << n;
}

TEST(Envmap, PdfIntegratesToOneAndEvalToTheMapsIntegral) {
    const EnvmapLight l = rotated_light();
    const LightModel m = l;
    const dvec3 exact = dvec3(l.map->integral()) * dvec3(l.scale);
    // The map's integral from its pixels: sin-weighted rows, 4 pi times the weighted mean.
    EXPECT_GT(exact.x, 0.0);
    PCG32 r(5, 1);
    RunningStats pdf_u, lum_u, lum_is;
    const int n = 400000;
    for (int k = 0; k < n; ++k) {
        // Uniform directions: independent of the lat-long mapping.
        vec3 w = square_to_uniform_sphere(vec2(r.next_float(), r.next_float()));
        pdf_u.add(double(pdf_li(m, w)) * 4.0 * M_PI);
        lum_u.add(double(luminance(eval_infinite(m, w))) * 4.0 * M_PI);
        LightSample s;
        if (sample_li(m, SceneSphere{}, vec3(0.f), vec2(r.next_float(), r.next_float()), s))
            lum_is.add(double(luminance(s.Le)) / double(s.pdf));
        else
            lum_is.add(0.0);
    }
    const double lum_exact = double(luminance(vec3(exact)));
    MeanTest t1 = z_test(pdf_u, 1.0), t2 = z_test(lum_u, lum_exact), t3 = z_test(lum_is, lum_exact);
    std::printf("  int pdf      %s\n  int L (unif) %s\n  int L (is)   %s\n", t1.describe().c_str(),
                t2.describe().c_str(), t3.describe().c_str());
    EXPECT_GE(t1.p_value, sidak_level(kAlpha, 3)) << t1.describe();
    EXPECT_GE(t2.p_value, sidak_level(kAlpha, 3)) << t2.describe();
    EXPECT_GE(t3.p_value, sidak_level(kAlpha, 3)) << t3.describe();
    // Importance sampling pays: its spread is well below uniform sampling's.
    EXPECT_LT(t3.std_error, 0.5 * t2.std_error);
}

TEST(Envmap, NoNanAtThePoles) {
    for (const EnvmapLight& l : {rotated_light(), [] {
             EnvmapLight x = rotated_light();
             x.to_world = glm::mat3(1.f);
             x.update();
             return x;
         }()}) {
        const LightModel m = l;
        for (vec3 d : {vec3(0, 1, 0), vec3(0, -1, 0), vec3(-0.f, 1, -0.f), vec3(1e-20f, -1, 0), vec3(0, 0, -1)}) {
            for (vec3 w : {d, l.from_local(d)}) {
                EXPECT_TRUE(all_finite(eval_infinite(m, w))) << w.x << " " << w.y << " " << w.z;
                const float p = pdf_li(m, w);
                EXPECT_TRUE(std::isfinite(p) && p >= 0.f);
            }
        }
        for (vec2 u : {vec2(0.f), vec2(0x1.fffffep-1f), vec2(0.f, 0x1.fffffep-1f), vec2(0x1.fffffep-1f, 0.f), vec2(0.5f, 0.f)}) {
            LightSample s;
            if (sample_li(m, SceneSphere{}, vec3(0.f), u, s)) {
                EXPECT_TRUE(std::isfinite(s.pdf) && s.pdf > 0.f);
                EXPECT_TRUE(all_finite(s.Le) && all_finite(s.wi));
            }
        }
    }
}

// ---- against Mitsuba ----------------------------------------------------------------------------

TEST(Envmap, EvalMatchesMitsuba) {
    std::ifstream f(data("envmap_eval_mitsuba.txt"));
    ASSERT_TRUE(f) << "tests/data/envmap_eval_mitsuba.txt";
    std::map<std::string, EnvmapLight> cases;
    cases["rot"] = rotated_light();
    cases["exr"].map = EnvironmentMap::load(data("textures/envmap_quadrants.exr"));
    cases["png"].map = EnvironmentMap::load(data("textures/envmap_small.png"));
    cases["hdr"].map = EnvironmentMap::load(data("textures/envmap_quadrants.hdr"));
    for (auto& c : cases) c.second.update();
    std::string line;
    int n = 0, bad = 0;
    while (std::getline(f, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream in(line);
        std::string name;
        vec3 d, ref;
        in >> name >> d.x >> d.y >> d.z >> ref.x >> ref.y >> ref.z;
        ASSERT_TRUE(in && cases.count(name)) << line;
        const vec3 v = eval_infinite(LightModel(cases[name]), d);
        ++n;
        for (int k = 0; k < 3; ++k)
            if (!(std::abs(v[k] - ref[k]) <= 1e-3f * std::abs(ref[k]) + 1e-6f)) {
                ++bad;
                ADD_FAILURE() << name << " d = (" << d.x << ", " << d.y << ", " << d.z << "): candela (" << v.x << ", "
                              << v.y << ", " << v.z << "), Mitsuba (" << ref.x << ", " << ref.y << ", " << ref.z << ")";
                break;
            }
    }
    EXPECT_EQ(n, 360);
    EXPECT_EQ(bad, 0);
}

namespace {

ImageEstimate render_envmap_scene(float scale, float rotation) {
    auto built = build_scene(load_scene(data("scenes/envmap.xml"), {{"res", "32"}}));
    SceneParams p = built->params();
    for (Light& l : p.lights) {
        light_strength(l.model) *= scale;
        if (EnvmapLight* e = std::get_if<EnvmapLight>(&l.model)) {
            e->rotation = rotation;
            e->update();
        }
    }
    return candela::test::render_batch_estimate(*built, p, 8, 64);
}

}  // namespace

TEST(Envmap, ImageMatchesMitsuba) {
    ImageEstimate ref = ImageEstimate::from_reference_files(data("envmap_scene"));
    ASSERT_EQ(ref.width, 32);
    ImageEstimate test = render_envmap_scene(1.f, 0.f);
    BlockTestResult r = block_z_test(test, ref, 8, kAlpha, 1e-5);
    dvec3 rel;
    const double p = whole_image_p(test, ref, &rel);
    std::printf("  blocks: %s\n  whole image: p = %.3g, relative (%.4f, %.4f, %.4f)\n", r.describe().c_str(), p, rel.x,
                rel.y, rel.z);
    EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
    EXPECT_GE(p, kAlpha);
    // Controls: 3% dimmer, and the map turned half-way round, are rejected.
    ImageEstimate dim = render_envmap_scene(0.97f, 0.f);
    EXPECT_TRUE(!block_z_test(dim, ref, 8, kAlpha, 1e-5).passed(kAlpha) || whole_image_p(dim, ref, nullptr) < kAlpha);
    ImageEstimate turned = render_envmap_scene(1.f, 180.f);
    EXPECT_FALSE(block_z_test(turned, ref, 8, kAlpha, 1e-5).passed(kAlpha));
}

// ---- furnace ------------------------------------------------------------------------------------

namespace {

std::shared_ptr<const Scene> envmap_furnace(IntegratorType type, SamplingMode mode) {
    TexelGrid g;
    g.width = 16;
    g.height = 8;
    g.data.assign(size_t(16 * 8 * 3), 1.f);
    EnvmapLight sky;
    sky.map = std::make_shared<const EnvironmentMap>(g);
    sky.to_world = glm::mat3(glm::rotate(mat4(1.f), 0.4f, glm::normalize(vec3(1, 2, 3))));
    sky.update();
    SceneDescription d;
    d.source = "<envmap furnace>";
    d.materials.push_back({"white", DiffuseBsdf{vec3(1.f)}, false});
    d.add_analytic_shape("ball", make_sphere(mat4(1.f), vec3(0.f), 1.f, false), 0, -1);
    d.lights.push_back({"sky", sky});
    d.camera.to_world = look_at(vec3(0, 0, 4), vec3(0.f), vec3(0, 1, 0));
    d.camera.fov_deg = 40.f;
    d.settings.width = d.settings.height = 16;
    d.settings.sampling = mode;
    d.settings.integrator.type = type;
    return build_scene(std::move(d));
}

}  // namespace

TEST(Envmap, WhiteFurnaceIsOneEverywhere) {
    struct Case {
        const char* name;
        IntegratorType type;
        SamplingMode mode;
    };
    const std::vector<Case> cases = {{"path light", IntegratorType::Path, SamplingMode::Light},
                                     {"path bsdf", IntegratorType::Path, SamplingMode::Bsdf},
                                     {"path mis", IntegratorType::Path, SamplingMode::Mis},
                                     {"direct mis", IntegratorType::Direct, SamplingMode::Mis}};
    const int tests = int(cases.size()) * 3;
    for (const Case& c : cases) {
        auto sc = envmap_furnace(c.type, c.mode);
        ImageEstimate est = candela::test::render_batch_estimate(*sc, sc->params(), 4, 16);
        for (int ch = 0; ch < 3; ++ch) {
            double sum = 0, var = 0;
            for (size_t i = 0; i < est.mean.size(); ++i) {
                sum += est.mean[i][ch];
                var += est.var_of_mean[i][ch];
                ASSERT_TRUE(std::isfinite(est.mean[i][ch]));
            }
            const double n = double(est.mean.size());
            MeanTest t = z_test(sum / n, std::sqrt(var) / n, 1.0, 1e-6);
            EXPECT_GE(t.p_value, sidak_level(kAlpha, tests)) << c.name << ": " << t.describe();
            EXPECT_LT(t.std_error, 0.01) << c.name;
            if (ch == 0) std::printf("  %-12s %s\n", c.name, t.describe().c_str());
        }
    }
}

TEST(Envmap, HideEmittersHidesTheMapFromCameraRays) {
    auto sc = envmap_furnace(IntegratorType::Path, SamplingMode::Mis);
    SceneParams p = sc->params();
    p.settings.integrator.hide_emitters = true;
    ImageEstimate est = candela::test::render_batch_estimate(*sc, p, 2, 4);
    EXPECT_EQ(est.mean[0].x, 0.0);  // the corner sees only the sky
    EXPECT_NEAR(est.mean[size_t(8 * 16 + 8)].x, 1.0, 0.1);
}

// ---- XML ----------------------------------------------------------------------------------------

TEST(Envmap, XmlDefaultsAndParameters) {
    const std::string dir = test::temp_dir("envmap-xml");
    const std::string exr = data("textures/envmap_quadrants.exr");
    test::write_text(dir + "/a.xml", "<scene version=\"3.0.0\">\n<emitter type=\"envmap\"><string name=\"filename\" value=\"" +
                                         exr + "\"/></emitter>\n</scene>\n");
    SceneDescription d = load_scene(dir + "/a.xml");
    ASSERT_EQ(d.lights.size(), 1u);
    const EnvmapLight* e = std::get_if<EnvmapLight>(&d.lights[0].model);
    ASSERT_TRUE(e);
    EXPECT_EQ(e->scale, vec3(1.f));
    EXPECT_EQ(e->frame, glm::mat3(1.f));
    EXPECT_EQ(e->map->width(), 24);
    EXPECT_EQ(e->map->height(), 12);
    EXPECT_STREQ(light_type_name(d.lights[0].model), "envmap");
    EXPECT_STREQ(light_strength_name(d.lights[0].model), "scale");
    EXPECT_EQ(light_flags(d.lights[0].model), uint32_t(kLightInfinite));
    // The viewer's edits (scale, rotation) make a different light; the map is shared, not copied.
    Light turned = d.lights[0];
    EXPECT_TRUE(same_light(turned, d.lights[0]));
    std::get<EnvmapLight>(turned.model).rotation = 30.f;
    std::get<EnvmapLight>(turned.model).update();
    EXPECT_FALSE(same_light(turned, d.lights[0]));
    EXPECT_NE(std::get<EnvmapLight>(turned.model).frame, e->frame);
    EXPECT_EQ(std::get<EnvmapLight>(turned.model).map, e->map);
    Light brighter = d.lights[0];
    light_strength(brighter.model) *= 2.f;
    EXPECT_FALSE(same_light(brighter, d.lights[0]));
}

TEST(Envmap, BadInputIsOneLineWithFileAndLine) {
    const std::string dir = test::temp_dir("envmap-bad");
    test::write_text(dir + "/not_an_image.exr", "this is not an EXR file\n");
    const std::string exr = data("textures/envmap_quadrants.exr");
    auto envmap = [&](const std::string& file, const std::string& extra = "") {
        return "<emitter type=\"envmap\"><string name=\"filename\" value=\"" + file + "\"/>" + extra + "</emitter>";
    };
    auto expect_error = [&](const std::string& body, const std::string& needle) {
        test::expect_load_error(dir, body, needle, "scene.xml:2:");
    };
    expect_error(envmap("missing_sky.exr"), "not found");
    expect_error(envmap(dir + "/not_an_image.exr"), "envmap");
    expect_error(envmap(data("textures/grey2x2.png")), "at least 2x3");
    expect_error(envmap(exr, "<float name=\"scale\" value=\"-1\"/>"), "scale must be finite and not negative");
    expect_error(envmap(exr, "<float name=\"scale\" value=\"nan\"/>"), "scale");
    expect_error(envmap(exr, "<float name=\"scales\" value=\"2\"/>"), "unused parameter 'scales'");
    expect_error("<emitter type=\"envmap\"/>", "envmap needs a filename");
    expect_error(envmap(exr, "<transform name=\"to_world\"><scale value=\"0\"/></transform>"), "singular");
    // One environment emitter per scene, as Mitsuba's Scene.
    expect_error(envmap(exr) + envmap(exr), "only one environment emitter");
    expect_error("<emitter type=\"constant\"/>" + envmap(exr), "only one environment emitter");
}
