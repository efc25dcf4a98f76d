// The emitters not on shapes (light/emitter.h) and emission sampling (issue 14):
// * chi-square tests of every sampling routine against its pdf: the spot's sample_le directions
//   (uniform in the cone, in the spot's local frame), the point's sample_le directions, the
//   constant light's sample_li directions, the area light's sample_le directions (cosine about
//   the normal) and positions (uniform by area on a triangle), the directional and constant
//   lights' sample_le positions (uniform on the disk of the scene's bounding sphere); and the
//   uniform choice of a light (the pmf LightSet::sample_li folds into its pdf).
// * the white furnace with `constant`: a white diffuse sphere inside a constant emitter of radiance
//   1 is exactly 1 everywhere, with the path tracer (light, BSDF, MIS) and direct (3 splits).
// * agreement with Mitsuba 3.9.1: tests/data/scenes/emitter_{point,spot,directional,constant}.xml
//   against references made by
//     $PY tests/data/make_reference.py tests/data/scenes/emitter_<name>.xml --res 32 --batches 16
//         --spp 1024 --out tests/data/emitter_<name>
//   (llvm_ad_rgb), block z-test on 8 x 8 blocks and whole-image z-test; control: the light 3%
//   dimmer is rejected.
// * bad input: one line with file:line.
#include <gtest/gtest.h>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include "core/error.h"
#include "light/area.h"
#include "render/renderer.h"
#include "sampling/pcg32.h"
#include "scene/camera.h"
#include "sampling/warp.h"
#include "scene/scene.h"
#include "support/furnace.h"
#include "support/load_error.h"
#include "support/render.h"
#include "support/run.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;

ChiSquareResult run(const Domain& d, std::function<DomainSample(PCG32&)> sample, std::function<double(const dvec3&)> pdf) {
    ChiSquareSetup s;
    s.domain = d;
    s.samples = 400000;
    s.sample = std::move(sample);
    s.pdf = std::move(pdf);
    return chi_square_2d(s);
}

DomainSample smooth(vec3 p) {
    DomainSample s;
    s.kind = DomainSample::Smooth;
    s.p = dvec3(p);
    return s;
}

// The cone cos(theta) >= cos_max about +z with equal-solid-angle cells: g = ((1 - cos theta) /
// (1 - cos_max), phi / 2pi). A sphere grid would cut the cone's rim through its cells.
Domain cone_domain(double cos_max) {
    Domain d;
    d.name = "cone";
    d.to_point = [=](dvec2 g) {
        double z = 1.0 - g.x * (1.0 - cos_max), r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * M_PI * g.y;
        return dvec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    d.to_grid = [=](const dvec3& p, dvec2& g) {
        double z = p.z / glm::length(p);
        if (z < cos_max) return false;
        double phi = std::atan2(p.y, p.x);
        if (phi < 0) phi += 2.0 * M_PI;
        g = dvec2(std::min((1.0 - z) / (1.0 - cos_max), 1.0), std::min(phi / (2.0 * M_PI), 1.0));
        return true;
    };
    d.jacobian = [=](dvec2) { return 2.0 * M_PI * (1.0 - cos_max); };
    return d;
}

SpotLight test_spot() {
    SpotLight l;
    l.to_world = glm::translate(mat4(1.f), vec3(1, 2, 3)) * glm::rotate(mat4(1.f), 0.7f, glm::normalize(vec3(1, 1, 0)));
    l.cutoff_angle = 35.f;
    l.beam_width = 20.f;
    return l;
}

// A projector's frustum parameterised by its image plane: g = uv (ProjectorLight::uv_of), points
// are local directions, and the solid angle of a cell is image area * cos^3(theta) per unit of uv.
Domain frustum_domain(const ProjectorLight& l) {
    Domain d;
    d.name = "frustum";
    const double tx = l.tan_x, ty = l.tan_y;
    d.to_point = [=](dvec2 g) { return glm::normalize(dvec3((1.0 - 2.0 * g.x) * tx, (1.0 - 2.0 * g.y) * ty, 1.0)); };
    d.to_grid = [=](const dvec3& p, dvec2& g) {
        if (!(p.z > 0)) return false;
        g = dvec2(0.5 - 0.5 * p.x / (p.z * tx), 0.5 - 0.5 * p.y / (p.z * ty));
        if (g.x < 0 || g.x > 1 || g.y < 0 || g.y > 1) return false;
        g = glm::min(g, dvec2(1.0 - 1e-12));
        return true;
    };
    d.jacobian = [=](dvec2 g) {
        const dvec3 q((1.0 - 2.0 * g.x) * tx, (1.0 - 2.0 * g.y) * ty, 1.0);
        const double c = 1.0 / glm::length(q);
        return 4.0 * tx * ty * c * c * c;
    };
    return d;
}

// A projector with a 4 x 4 bilinear texture that has dark texels (so that the density is far from
// uniform and has cells where only the uniform part reaches); its cells align with the chi-square
// grid's, so that the histogram's expected counts are exact.
ProjectorLight test_projector() {
    auto grid = std::make_shared<TexelGrid>();
    grid->width = 4;
    grid->height = 4;
    grid->channels = 3;
    const float v[16] = {0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.5f, 3.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.f};
    for (float x : v)
        for (int c = 0; c < 3; ++c) grid->data.push_back(x * (1.f + 0.1f * float(c)));
    BitmapTexture b;
    b.texels = grid;
    ProjectorLight l;
    l.irradiance = std::make_shared<Texture>(Texture{b});
    l.to_world = glm::translate(mat4(1.f), vec3(1, 2, 3)) * glm::rotate(mat4(1.f), 0.7f, glm::normalize(vec3(1, 1, 0)));
    l.scale = vec3(2.f);
    l.tan_x = 0.6f;
    l.tan_y = 0.45f;
    l.build_density();
    return l;
}

}  // namespace

TEST(Emitters, SamplingRoutinesMatchTheirPdfs) {
    struct Case {
        const char* name;
        Domain domain;
        std::function<DomainSample(PCG32&)> sample;
        std::function<double(const dvec3&)> pdf;
    };
    const SceneSphere sphere{vec3(0.5f, -1.f, 2.f), 3.f};
    const SpotLight spot = test_spot();
    const ProjectorLight proj = test_projector();
    // A triangle area light in the plane z = 0 (the triangle domain's plane), facing +z.
    SceneDescription d;
    d.source = "<one emissive triangle>";
    d.materials.push_back({"m", DiffuseBsdf{vec3(0.5f)}, false});
    d.emitters.push_back({vec3(2.f)});
    d.add_shape("lamp", {vec3(0, 0, 0), vec3(2, 0, 0), vec3(0.5f, 1.5f, 0)}, {}, {uvec3(0, 1, 2)}, 0, 0);
    auto tri = build_scene(std::move(d));
    const LightSet& ls = tri->lights;

    std::vector<Case> cases = {
        {"spot sample_le direction (local)", cone_domain(std::cos(glm::radians(spot.cutoff_angle))),
         [&](PCG32& r) {
             auto es = sample_le(spot, sphere, vec2(r.next_float(), r.next_float()), vec2(r.next_float(), r.next_float()));
             return es ? smooth(glm::normalize(glm::inverse(glm::mat3(spot.to_world)) * es->ray.d)) : DomainSample{};
         },
         [&](const dvec3& w) {
             float pp, pd;
             pdf_le(spot, sphere, glm::mat3(spot.to_world) * vec3(w), pp, pd);
             return double(pd);
         }},
        {"projector sample_le direction (image plane)", frustum_domain(proj),
         [&](PCG32& r) {
             auto es = sample_le(proj, sphere, vec2(r.next_float(), r.next_float()), vec2(r.next_float(), r.next_float()));
             return es ? smooth(glm::normalize(proj.to_local(es->ray.d))) : DomainSample{};
         },
         [&](const dvec3& w) {
             float pp, pd;
             pdf_le(proj, sphere, proj.to_world_dir(vec3(w)), pp, pd);
             return double(pd);
         }},
        {"point sample_le direction", sphere_domain(),
         [&](PCG32& r) {
             auto es = sample_le(PointLight{}, sphere, vec2(r.next_float(), r.next_float()), vec2(r.next_float(), r.next_float()));
             return smooth(es->ray.d);
         },
         [&](const dvec3& w) {
             float pp, pd;
             pdf_le(PointLight{}, sphere, vec3(w), pp, pd);
             return double(pd);
         }},
        {"constant sample_li direction", sphere_domain(),
         [&](PCG32& r) {
             LightSample s;
             sample_li(ConstantLight{}, sphere, vec3(0.3f), vec2(r.next_float(), r.next_float()), s);
             return smooth(s.wi);
         },
         [&](const dvec3& w) { return double(pdf_li(ConstantLight{}, vec3(w))); }},
        {"area sample_le direction", hemisphere_domain(),
         [&](PCG32& r) {
             auto es = ls.sample_le(r.next_float(), vec2(r.next_float(), r.next_float()), vec2(r.next_float(), r.next_float()));
             return es ? smooth(es->ray.d) : DomainSample{};
         },
         [&](const dvec3& w) {
             SurfaceInteraction si;
             si.prim = 0;
             si.ns = si.ng = vec3(0, 0, 1);
             float pp, pd;
             ls.pdf_le(si, vec3(w), pp, pd);
             return double(pd);
         }},
        {"area sample_le position", triangle_domain(dvec2(0, 0), dvec2(2, 0), dvec2(0.5, 1.5)),
         [&](PCG32& r) {
             auto es = ls.sample_le(r.next_float(), vec2(r.next_float(), r.next_float()), vec2(r.next_float(), r.next_float()));
             return es ? smooth(vec3(es->ray.o.x, es->ray.o.y, 0.f)) : DomainSample{};
         },
         [&](const dvec3&) {
             SurfaceInteraction si;
             si.prim = 0;
             si.ns = si.ng = vec3(0, 0, 1);
             float pp, pd;
             ls.pdf_le(si, vec3(0, 0, 1), pp, pd);
             return double(pp);
         }},
    };
    // The infinite lights' ray origins: on the disk of the bounding sphere facing the light,
    // mapped back to the unit disk (scaled by the radius) in the frame of that direction.
    const vec3 dir = glm::normalize(vec3(-0.3f, -1.f, 0.4f));
    const DirectionalLight sun{dir, vec3(1.f)};
    cases.push_back({"directional sample_le position", disk_domain(),
                     [&](PCG32& r) {
                         auto es = sample_le(sun, sphere, vec2(r.next_float(), r.next_float()), vec2(r.next_float(), r.next_float()));
                         if (!es || glm::length(es->ray.d - dir) > 1e-5f) return DomainSample{};
                         Frame f(-dir);
                         vec3 q = (es->ray.o + sphere.radius * dir - sphere.center) / sphere.radius;
                         return smooth(vec3(glm::dot(q, f.s), glm::dot(q, f.t), 0.f));
                     },
                     [&](const dvec3&) {
                         float pp, pd;
                         pdf_le(sun, sphere, dir, pp, pd);
                         return double(pp) * sphere.radius * sphere.radius;  // to the unit disk's area
                     }});
    cases.push_back({"constant sample_le direction", sphere_domain(),
                     [&](PCG32& r) {
                         auto es = sample_le(ConstantLight{}, sphere, vec2(r.next_float(), r.next_float()),
                                             vec2(r.next_float(), r.next_float()));
                         return smooth(es->ray.d);
                     },
                     [&](const dvec3& w) {
                         float pp, pd;
                         pdf_le(ConstantLight{}, sphere, vec3(w), pp, pd);
                         return double(pd);
                     }});
    const double level = sidak_level(kAlpha, int(cases.size()));
    for (const Case& c : cases) {
        ChiSquareResult r = run(c.domain, c.sample, c.pdf);
        EXPECT_GE(r.p_value, level) << c.name << ": " << r.describe();
        EXPECT_EQ(r.outside_count, 0u) << c.name;
        std::printf("  %-34s %s\n", c.name, r.describe().c_str());
    }
}

// The projector's three views of one ray agree: sample_le's pdf is pdf_le's, and its intensity is
// what sample_li gives (times dist^2) at a point along the ray, as Mitsuba's sample_ray and
// sample_direction agree.
TEST(Emitters, ProjectorSamplingIsConsistent) {
    const SceneSphere sphere;
    const ProjectorLight l = test_projector();
    PCG32 r(7, 1);
    int n = 0;
    for (int i = 0; i < 20000; ++i) {
        auto es = sample_le(l, sphere, vec2(r.next_float(), r.next_float()), vec2(r.next_float(), r.next_float()));
        ASSERT_TRUE(es);
        float pp, pd;
        pdf_le(l, sphere, es->ray.d, pp, pd);
        EXPECT_EQ(pp, 1.f);
        EXPECT_NEAR(pd, es->pdf_dir, 1e-4f * es->pdf_dir) << i;
        const float t = 0.5f + 3.f * r.next_float();
        LightSample ls;
        if (!sample_li(l, sphere, es->ray.o + t * es->ray.d, vec2(0.5f), ls)) {
            EXPECT_TRUE(is_black(es->Le)) << i;
            continue;
        }
        ++n;
        EXPECT_TRUE(ls.delta);
        EXPECT_NEAR(glm::dot(ls.wi, -es->ray.d), 1.f, 1e-5f);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(ls.Le[c] * t * t, es->Le[c], 2e-3f * es->Le[c] + 1e-6f) << i;
    }
    EXPECT_GT(n, 8000);
    // Outside the frustum: nothing, and density 0.
    LightSample ls;
    EXPECT_FALSE(sample_li(l, sphere, l.position() - 2.f * l.to_world_dir(vec3(0, 0, 1)), vec2(0.5f), ls));
    EXPECT_FALSE(sample_li(l, sphere, l.position() + l.to_world_dir(vec3(2, 0, 1)), vec2(0.5f), ls));
    float pp, pd;
    pdf_le(l, sphere, l.to_world_dir(glm::normalize(vec3(0.7f, 0.f, 1.f))), pp, pd);
    EXPECT_EQ(pd, 0.f);
}

TEST(Emitters, ChiSquareRejectsAWrongConePdf) {
    // Control: the spot's cone pdf claimed for a cone 10% wider must fail.
    const SceneSphere sphere;
    const SpotLight spot = test_spot();
    SpotLight wide = spot;
    wide.cutoff_angle *= 1.1f;
    ChiSquareResult r = run(
        cone_domain(std::cos(glm::radians(spot.cutoff_angle))),
        [&](PCG32& rng) {
            auto es = sample_le(spot, sphere, vec2(0.5f), vec2(rng.next_float(), rng.next_float()));
            return smooth(glm::normalize(glm::inverse(glm::mat3(spot.to_world)) * es->ray.d));
        },
        [&](const dvec3& w) {
            float pp, pd;
            pdf_le(wide, sphere, glm::mat3(spot.to_world) * vec3(w), pp, pd);
            return double(pd);
        });
    EXPECT_LT(r.p_value, kAlpha) << r.describe();
}

TEST(Emitters, SpotFalloffIsMitsubas) {
    SpotLight l;  // cutoff 20, beam 15 (Mitsuba's defaults)
    auto at = [&](float deg) { return l.profile(vec3(std::sin(deg * kPi / 180.f), 0.f, std::cos(deg * kPi / 180.f))).x; };
    EXPECT_FLOAT_EQ(at(0.f), 1.f);
    EXPECT_FLOAT_EQ(at(14.9f), 1.f);
    EXPECT_NEAR(at(17.5f), 0.5f, 1e-4f);  // linear in angle between beam_width and cutoff_angle
    EXPECT_NEAR(at(19.f), 0.2f, 1e-4f);
    EXPECT_EQ(at(20.5f), 0.f);
    // sample_li: intensity x falloff / d^2, a delta light.
    l.intensity = vec3(4.f);
    LightSample s;
    ASSERT_TRUE(sample_li(l, SceneSphere{}, vec3(0, 0, 2), vec2(0.5f), s));
    EXPECT_TRUE(s.delta);
    EXPECT_NEAR(s.Le.x, 1.f, 1e-6f);
    EXPECT_NEAR(s.dist, 2.f, 1e-6f);
    EXPECT_FALSE(sample_li(l, SceneSphere{}, vec3(0, 2, 2), vec2(0.5f), s));  // 45 degrees: outside
}

TEST(Emitters, LightChoiceIsUniformOverAreaLightsAndOthers) {
    // One area light and two point lights: each choice has pmf 1/3, and a point light's pdf is
    // that pmf (a discrete choice of a delta light).
    SceneDescription d;
    d.source = "<choice>";
    d.materials.push_back({"m", DiffuseBsdf{vec3(0.5f)}, false});
    d.emitters.push_back({vec3(1.f)});
    d.add_shape("lamp", {vec3(-1, -1, 2), vec3(1, -1, 2), vec3(1, 1, 2), vec3(-1, 1, 2)}, {},
                {uvec3(0, 2, 1), uvec3(0, 3, 2)}, 0, 0);
    d.lights.push_back({"p0", PointLight{vec3(3, 0, 1), vec3(1.f)}});
    d.lights.push_back({"p1", PointLight{vec3(-3, 0, 1), vec3(2.f)}});
    auto sc = build_scene(std::move(d));
    std::vector<double> count(3, 0.0);
    PCG32 rng(7, 1);
    const int n = 60000;
    for (int i = 0; i < n; ++i) {
        LightSample s;
        ASSERT_TRUE(sc->lights.sample_li(vec3(0.f), rng.next_float(), vec2(rng.next_float(), rng.next_float()), s));
        int k = !s.delta ? 0 : s.p.x > 0.f ? 1 : 2;
        count[size_t(k)] += 1;
        if (s.delta) {
            EXPECT_FLOAT_EQ(s.pdf, 1.f / 3.f);
        }
    }
    ChiSquareResult r = chi_square_counts(count, {n / 3.0, n / 3.0, n / 3.0});
    EXPECT_GE(r.p_value, kAlpha) << r.describe();
}

// ---- the white furnace with `constant` ----------------------------------------------------------

namespace {

std::shared_ptr<const Scene> furnace_scene(IntegratorType type, SamplingMode mode, int es, int bs) {
    SceneDescription d = candela::test::sphere_under_sky(1.f);
    d.settings.sampling = mode;
    d.settings.integrator.type = type;
    d.settings.integrator.emitter_samples = es;
    d.settings.integrator.bsdf_samples = bs;
    return build_scene(std::move(d));
}

}  // namespace

TEST(Emitters, WhiteFurnaceWithConstantIsOneEverywhere) {
    struct Case {
        const char* name;
        IntegratorType type;
        SamplingMode mode;
        int es, bs;
    };
    const std::vector<Case> cases = {
        {"path light", IntegratorType::Path, SamplingMode::Light, 1, 1},
        {"path bsdf", IntegratorType::Path, SamplingMode::Bsdf, 1, 1},
        {"path mis", IntegratorType::Path, SamplingMode::Mis, 1, 1},
        {"direct 1/1", IntegratorType::Direct, SamplingMode::Mis, 1, 1},
        {"direct 2/0", IntegratorType::Direct, SamplingMode::Mis, 2, 0},
        {"direct 0/3", IntegratorType::Direct, SamplingMode::Mis, 0, 3},
    };
    const int tests = int(cases.size()) * 3;
    for (const Case& c : cases) {
        auto sc = furnace_scene(c.type, c.mode, c.es, c.bs);
        ImageEstimate est = candela::test::render_batch_estimate(*sc, sc->params(), 4, 16);
        // Pixels are independent estimates of 1: the mean over all, with its standard error.
        for (int ch = 0; ch < 3; ++ch) {
            double sum = 0, var = 0;
            for (size_t i = 0; i < est.mean.size(); ++i) {
                sum += est.mean[i][ch];
                var += est.var_of_mean[i][ch];
                EXPECT_TRUE(std::isfinite(est.mean[i][ch]));
            }
            const double n = double(est.mean.size());
            MeanTest t = z_test(sum / n, std::sqrt(var) / n, 1.0, 1e-6);
            EXPECT_GE(t.p_value, sidak_level(kAlpha, tests)) << c.name << ": " << t.describe();
            EXPECT_LT(t.std_error, 0.01) << c.name;
            if (ch == 0) std::printf("  %-12s %s\n", c.name, t.describe().c_str());
        }
    }
}

TEST(Emitters, HideEmittersHidesTheConstantFromCameraRays) {
    auto sc = furnace_scene(IntegratorType::Path, SamplingMode::Mis, 1, 1);
    SceneParams p = sc->params();
    p.settings.integrator.hide_emitters = true;
    ImageEstimate est = candela::test::render_batch_estimate(*sc, p, 2, 4);
    // The corner pixel sees only the sky: black; the centre sees the ball, lit: about 1.
    EXPECT_EQ(est.mean[0].x, 0.0);
    const size_t centre = size_t(8 * 16 + 8);
    EXPECT_NEAR(est.mean[centre].x, 1.0, 0.1);
}

// ---- agreement with Mitsuba ---------------------------------------------------------------------

namespace {

ImageEstimate render_emitter_scene(const std::string& name, float scale) {
    auto built = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/emitter_" + name + ".xml", {{"res", "32"}}));
    SceneParams p = built->params();
    for (Light& l : p.lights) light_strength(l.model) *= scale;
    return candela::test::render_batch_estimate(*built, p, 8, 64);
}

}  // namespace

TEST(Emitters, MitsubaAgreement) {
    for (const char* name : {"point", "spot", "directional", "constant"}) {
        ImageEstimate ref = ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/emitter_" + name);
        ASSERT_EQ(ref.width, 32) << name;
        ImageEstimate test = render_emitter_scene(name, 1.f);
        // rel_floor 1e-5: Mitsuba's RGB round trip puts the constant sky at 0.9000005 where the file
        // says 0.9; both are noise-free there (far below the 3% the control must detect).
        BlockTestResult r = block_z_test(test, ref, 8, sidak_level(kAlpha, 4), 1e-5);
        dvec3 rel;
        double p = whole_image_p(test, ref, &rel);
        std::printf("  %-12s blocks: %s\n               whole image: p = %.3g, relative (%.4f, %.4f, %.4f)\n", name,
                    r.describe().c_str(), p, rel.x, rel.y, rel.z);
        EXPECT_TRUE(r.passed(sidak_level(kAlpha, 4))) << name << ": " << r.describe();
        EXPECT_GE(p, sidak_level(kAlpha, 4)) << name;
        // Control: 3% dimmer is rejected.
        ImageEstimate dim = render_emitter_scene(name, 0.97f);
        BlockTestResult rd = block_z_test(dim, ref, 8, kAlpha, 1e-5);
        EXPECT_TRUE(!rd.passed(kAlpha) || whole_image_p(dim, ref, nullptr) < kAlpha) << name << " 3% dimmer passed";
    }
}

// The projector (tests/data/scenes/emitter_projector.xml: a 3 x 2 texture of six colours with
// nearest texels, fov along y) against Mitsuba 3.9.1, with the three integrators that reach it
// differently: the path tracer by sample_li, the particle tracer by sample_le, BDPT by both under
// MIS. Controls: 3% dimmer, and the image turned half a turn about the projector's axis, are
// rejected.
TEST(Emitters, ProjectorMatchesMitsuba) {
    const std::string dir = std::string(CANDELA_TEST_DATA);
    ImageEstimate ref = ImageEstimate::from_reference_files(dir + "/emitter_projector");
    ASSERT_EQ(ref.width, 32);
    const char* integrators[] = {"path", "ptracer", "bdpt"};
    const double level = sidak_level(kAlpha, 3);
    for (const char* integ : integrators) {
        auto built = build_scene(load_scene(dir + "/scenes/emitter_projector.xml", {{"res", "32"}, {"integrator", integ}}));
        SceneParams p = built->params();
        ASSERT_EQ(p.lights.size(), 1u);
        ASSERT_TRUE(std::holds_alternative<ProjectorLight>(p.lights[0].model));
        ImageEstimate test = candela::test::render_batch_estimate(*built, p, 8, 64);
        BlockTestResult r = block_z_test(test, ref, 8, level);
        dvec3 rel;
        const double pw = whole_image_p(test, ref, &rel);
        std::printf("  projector %-8s blocks: %s\n                     whole image: p = %.3g, relative (%.4f, %.4f, %.4f)\n",
                    integ, r.describe().c_str(), pw, rel.x, rel.y, rel.z);
        EXPECT_TRUE(r.passed(level)) << integ << ": " << r.describe();
        EXPECT_GE(pw, level) << integ;
        if (std::string(integ) != "path") continue;
        SceneParams dim = p;
        light_strength(dim.lights[0].model) *= 0.97f;
        ImageEstimate d = candela::test::render_batch_estimate(*built, dim, 8, 64);
        EXPECT_TRUE(!block_z_test(d, ref, 8, kAlpha).passed(kAlpha) || whole_image_p(d, ref, nullptr) < kAlpha)
            << "3% dimmer passed";
        SceneParams turned = p;
        ProjectorLight& l = std::get<ProjectorLight>(turned.lights[0].model);
        l.to_world = l.to_world * glm::rotate(mat4(1.f), float(M_PI), vec3(0.f, 0.f, 1.f));
        ImageEstimate t = candela::test::render_batch_estimate(*built, turned, 8, 64);
        EXPECT_FALSE(block_z_test(t, ref, 8, kAlpha).passed(kAlpha)) << "the image turned half a turn passed";
    }
}


TEST(Emitters, ProjectorErrors) {
    const std::string dir = test::temp_dir("emitters-projector-bad");
    auto expect_error = [&](const std::string& body, const std::string& needle) {
        test::expect_load_error(dir, "<emitter type=\"projector\">\n" + body + "\n</emitter>", needle);
    };
    expect_error("<float name=\"fov\" value=\"40\"/>", "needs an 'irradiance'");
    expect_error("<rgb name=\"irradiance\" value=\"1\"/><float name=\"fov\" value=\"180\"/>", "fov must be in (0, 180)");
    expect_error("<rgb name=\"irradiance\" value=\"1\"/><float name=\"scale\" value=\"-1\"/>", "scale must be finite");
    expect_error("<rgb name=\"irradiance\" value=\"1\"/><transform name=\"to_world\"><scale value=\"2\"/></transform>",
                 "rotation and a translation");
    expect_error("<rgb name=\"irradiance\" value=\"1, -1, 1\"/>", "must be finite and not negative");
    // A constant irradiance loads, with the aspect ratio 1 of a texture without a resolution.
    const std::string ok = dir + "/ok.xml";
    test::write_text(ok, "<scene version=\"3.0.0\"><emitter type=\"projector\"><float name=\"fov\" value=\"90\"/>"
                         "<spectrum name=\"irradiance\" value=\"1\"/></emitter></scene>\n");
    SceneDescription d = load_scene(ok);
    ASSERT_EQ(d.lights.size(), 1u);
    const ProjectorLight& l = std::get<ProjectorLight>(d.lights[0].model);
    EXPECT_NEAR(l.tan_x, 1.f, 1e-6f);
    EXPECT_NEAR(l.tan_y, 1.f, 1e-6f);
}

// A textured area radiance (a checkerboard on a rectangle that faces the camera) against Mitsuba:
// the pattern is seen directly and in the light on the floor. Control: the same emitter with a
// constant radiance equal to the texture's mean must be rejected, so the test sees the texture.
TEST(Emitters, TexturedAreaRadianceMatchesMitsuba) {
    ImageEstimate ref = ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/emitter_textured_area");
    ASSERT_EQ(ref.width, 32);
    auto built = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/emitter_textured_area.xml", {{"res", "32"}}));
    SceneParams p = built->params();
    ASSERT_EQ(p.emitters.size(), 1u);
    ASSERT_TRUE(p.emitters[0].texture);
    ImageEstimate test = candela::test::render_batch_estimate(*built, p, 8, 64);
    BlockTestResult r = block_z_test(test, ref, 8, kAlpha);
    dvec3 rel;
    double pw = whole_image_p(test, ref, &rel);
    std::printf("  textured area blocks: %s\n                whole image: p = %.3g, relative (%.4f, %.4f, %.4f)\n",
                r.describe().c_str(), pw, rel.x, rel.y, rel.z);
    EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
    EXPECT_GE(pw, kAlpha);
    // Control: the checkerboard's two colours in equal parts, as a constant.
    p.emitters[0].radiance = 0.5f * (vec3(1.f, 0.85f, 0.6f) + vec3(0.08f, 0.15f, 0.4f));
    p.emitters[0].texture = nullptr;
    ImageEstimate flat = candela::test::render_batch_estimate(*built, p, 8, 64);
    EXPECT_FALSE(block_z_test(flat, ref, 8, kAlpha).passed(kAlpha)) << "a constant radiance passed for the texture";
}

TEST(Emitters, TexturedRadianceErrors) {
    const std::string dir = test::temp_dir("emitters-textured-bad");
    auto expect_error = [&](const std::string& shape, const std::string& needle) { test::expect_load_error(dir, shape, needle); };
    const std::string checker = "<texture type=\"checkerboard\" name=\"radiance\"/>";
    expect_error("<shape type=\"sphere\"><emitter type=\"area\">" + checker + "</emitter></shape>",
                 "supported on meshes only");
    expect_error("<shape type=\"rectangle\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/>" + checker +
                     "</emitter></shape>",
                 "both as a value and as a texture");
    expect_error("<shape type=\"rectangle\"><emitter type=\"area\"><texture type=\"mesh_attribute\" name=\"radiance\">"
                 "<string name=\"name\" value=\"vertex_color\"/></texture></emitter></shape>",
                 "vertex colours");
}

// ---- bad input -----------------------------------------------------------------------------------

TEST(Emitters, BadInputIsOneLineWithFileAndLine) {
    const std::string dir = test::temp_dir("emitters-bad");
    auto expect_error = [&](const std::string& emitter, const std::string& needle) { test::expect_load_error(dir, emitter, needle); };
    expect_error("<emitter type=\"point\"><rgb name=\"intensity\" value=\"-1\"/></emitter>", "must be finite and not negative");
    expect_error("<emitter type=\"spot\"><float name=\"cutoff_angle\" value=\"95\"/></emitter>", "cutoff_angle must be in (0, 90]");
    expect_error("<emitter type=\"spot\"><float name=\"cutoff_angle\" value=\"0\"/></emitter>", "cutoff_angle must be in (0, 90]");
    expect_error("<emitter type=\"spot\"><float name=\"beam_width\" value=\"30\"/></emitter>", "beam_width");
    expect_error("<emitter type=\"directional\"><vector name=\"direction\" x=\"0\" y=\"0\" z=\"0\"/></emitter>",
                 "direction must not be zero");
    expect_error("<emitter type=\"directional\"><rgb name=\"irradiance\" value=\"1, -2, 1\"/></emitter>", "not negative");
    expect_error("<emitter type=\"constant\"><rgb name=\"radiance\" value=\"-0.5\"/></emitter>", "not negative");
    expect_error("<emitter type=\"point\"><point name=\"position\" x=\"0\" y=\"0\" z=\"0\"/>"
                 "<transform name=\"to_world\"><translate x=\"1\"/></transform></emitter>",
                 "only one of");
    expect_error("<emitter type=\"point\"><float name=\"radius\" value=\"1\"/></emitter>", "unused parameter 'radius'");
    expect_error("<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/></emitter>", "envmap");
    expect_error("<emitter type=\"sunsky\"/>", "unsupported emitter type 'sunsky'");
}

TEST(Emitters, XmlDefaultsAreMitsubas) {
    const std::string dir = test::temp_dir("emitters-defaults");
    const std::string path = dir + "/scene.xml";
    test::write_text(path, "<scene version=\"3.0.0\">\n<emitter type=\"point\"/>\n<emitter type=\"spot\"/>\n"
                           "<emitter type=\"directional\"/>\n<emitter type=\"constant\" id=\"sky\"/>\n"
                           "<emitter type=\"spot\"><transform name=\"to_world\"><lookat origin=\"1, 1, 1\" target=\"1, 2, 1\"/>"
                           "</transform></emitter>\n</scene>\n");
    SceneDescription d = load_scene(path);
    ASSERT_EQ(d.lights.size(), 5u);
    EXPECT_EQ(std::get<PointLight>(d.lights[0].model).intensity, vec3(1.f));
    const SpotLight& s = std::get<SpotLight>(d.lights[1].model);
    EXPECT_FLOAT_EQ(s.cutoff_angle, 20.f);
    EXPECT_FLOAT_EQ(s.beam_width, 15.f);
    EXPECT_EQ(std::get<DirectionalLight>(d.lights[2].model).direction, vec3(0, 0, 1));
    EXPECT_EQ(d.lights[3].name, "sky");
    const SpotLight& s2 = std::get<SpotLight>(d.lights[4].model);
    EXPECT_NEAR(glm::length(s2.position() - vec3(1, 1, 1)), 0.f, 1e-6f);
    EXPECT_NEAR(glm::length(s2.axis() - vec3(0, 1, 0)), 0.f, 1e-6f);  // Mitsuba's lookat points +z at the target
}

TEST(Emitters, EditingALightRebuildsTheLightSetOnly) {
    // The viewer's path: SceneParams edited, Scene::with_params. The geometry and the accelerator
    // are shared; the light set is rebuilt when a light changed and shared when nothing did.
    auto sc = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/emitter_spot.xml", {{"res", "8"}}));
    SceneParams p = sc->params();
    ASSERT_EQ(p.lights.size(), 1u);
    auto same = sc->with_params(p);
    EXPECT_EQ(same->light_set, sc->light_set);
    light_strength(p.lights[0].model) *= 2.f;
    auto edited = sc->with_params(p);
    EXPECT_EQ(edited->geometry, sc->geometry);
    EXPECT_EQ(edited->accel, sc->accel);
    EXPECT_NE(edited->light_set, sc->light_set);
    LightSample a, b;
    ASSERT_TRUE(sc->lights.sample_li(vec3(0, 0.3f, 0), 0.5f, vec2(0.5f), a));
    ASSERT_TRUE(edited->lights.sample_li(vec3(0, 0.3f, 0), 0.5f, vec2(0.5f), b));
    EXPECT_FLOAT_EQ(b.Le.x, 2.f * a.Le.x);
    // A negative strength from an edit is refused like one from a file.
    light_strength(p.lights[0].model) = vec3(-1.f);
    EXPECT_THROW(sc->with_params(p), Error);
}
