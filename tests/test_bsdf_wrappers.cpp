// The material wrappers (blendbsdf, mask, null, bumpmap, normalmap; docs/materials.md "Wrappers"):
// chi-square of the blend's (and a perturbed blend's) sampling against its pdf, sample/eval/pdf
// agreement, the perturbed frames (a constant-slope bump tilts the normal by atan(slope); a flat
// normal map changes nothing), masks against computed values (a black masked surface in front of
// an emitter lets 1 - opacity through; direct light through a masked occluder is (1 - opacity) of
// the unoccluded in light, BSDF and MIS sampling alike), and a scene with all three wrappers
// against Mitsuba 3.9.1.
#include <gtest/gtest.h>
#include <cstdio>
#include <cstring>
#include <fstream>
#include "bsdf/wrappers.h"
#include "film/film.h"
#include "integrator/path.h"
#include "render/renderer.h"
#include "sampling/pcg32.h"
#include "scene/scene.h"
#include "support/render.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;

DiffuseBsdf diffuse(vec3 r) { return DiffuseBsdf{r}; }
ConductorBsdf rough_metal(float alpha) {
    ConductorBsdf c;
    c.distribution = MicrofacetType::GGX;
    c.alpha_u = c.alpha_v = alpha;
    return c;
}
DielectricBsdf rough_glass(float alpha) {
    DielectricBsdf d;
    d.distribution = MicrofacetType::GGX;
    d.alpha_u = d.alpha_v = alpha;
    return d;
}

struct BlendCase {
    std::string name;
    std::vector<Bsdf> leaves;
    std::vector<float> w;
    vec3 wo;
    vec3 perturbed_n{0.f, 0.f, 1.f};  // (0, 0, 1): no perturbation
    std::vector<double> discrete;     // probabilities of the delta outcomes (reflection, refraction)
};

WrappedBsdf wrapped_of(const BlendCase& c) {
    WrappedBsdf w;
    w.n = int(c.leaves.size());
    for (size_t k = 0; k < c.leaves.size(); ++k) {
        w.leaf[k] = &c.leaves[k];
        w.w[k] = c.w[k];
    }
    if (c.perturbed_n != vec3(0.f, 0.f, 1.f)) {
        w.perturbed = true;
        w.frame = perturbed_frame(c.perturbed_n, c.wo, true);
        w.terminator = true;
    }
    return w;
}

std::vector<BlendCase> blend_cases() {
    const vec3 wo = glm::normalize(vec3(0.5f, 0.2f, 0.8f));
    const vec3 grazing = glm::normalize(vec3(0.9f, 0.f, 0.25f));
    ConductorBsdf mirror;  // alpha 0: a delta lobe of probability 1 within its leaf
    return {
        {"diffuse + rough metal 0.3, w 0.3", {diffuse(vec3(0.8f)), rough_metal(0.3f)}, {0.7f, 0.3f}, wo},
        {"diffuse + rough metal 0.1, grazing", {diffuse(vec3(0.5f)), rough_metal(0.1f)}, {0.4f, 0.6f}, grazing},
        {"rough glass 0.2 + diffuse", {rough_glass(0.2f), diffuse(vec3(0.6f))}, {0.6f, 0.4f}, wo},
        {"three leaves", {diffuse(vec3(0.5f)), rough_metal(0.5f), rough_glass(0.4f)}, {0.2f, 0.5f, 0.3f}, wo},
        {"mirror + diffuse (delta 0.35)", {mirror, diffuse(vec3(0.7f))}, {0.35f, 0.65f}, wo, vec3(0.f, 0.f, 1.f), {0.35, 0.0}},
        {"bump-tilted diffuse + metal", {diffuse(vec3(0.8f)), rough_metal(0.3f)}, {0.5f, 0.5f}, wo, glm::normalize(vec3(0.4f, -0.2f, 1.f))},
        {"bump-tilted, grazing", {diffuse(vec3(0.8f)), rough_metal(0.2f)}, {0.3f, 0.7f}, grazing, glm::normalize(vec3(-0.5f, 0.1f, 1.f))},
    };
}

ChiSquareSetup setup_for(const BlendCase& c, uint64_t seed) {
    ChiSquareSetup s;
    s.domain = sphere_domain();
    s.res_x = 20;
    s.res_y = 40;
    s.samples = 300000;
    s.integration_points = 31;
    s.seed = seed;
    auto leaves = std::make_shared<BlendCase>(c);  // the WrappedBsdf points into it
    auto w = std::make_shared<WrappedBsdf>(wrapped_of(*leaves));
    const vec3 wo = c.wo;
    s.sample = [leaves, w, wo](PCG32& rng) {
        float u1 = rng.next_float();
        float a = rng.next_float();
        vec2 u2(a, rng.next_float());
        DomainSample d;
        auto bs = w->sample_w(wo, u1, u2);
        if (!bs) return d;
        if (bs->delta) {
            d.kind = DomainSample::Discrete;
            d.component = bs->wi.z * wo.z > 0.f ? 0 : 1;
        } else {
            d.kind = DomainSample::Smooth;
            d.p = dvec3(bs->wi);
        }
        return d;
    };
    s.pdf = [leaves, w, wo](const dvec3& p) { return double(w->pdf_w(wo, glm::normalize(vec3(p)))); };
    s.discrete_probabilities = c.discrete;
    return s;
}

}  // namespace

TEST(BsdfWrappers, BlendSamplingMatchesPdf) {
    const auto cases = blend_cases();
    const double level = sidak_level(kAlpha, int(cases.size()));
    for (size_t i = 0; i < cases.size(); ++i) {
        const ChiSquareResult r = chi_square_2d(setup_for(cases[i], 700 + i));
        EXPECT_GT(r.dof, 0) << cases[i].name;
        EXPECT_GE(r.p_value, level) << cases[i].name << ": " << r.describe();
        EXPECT_LE(r.pdf_integral, 1.0 + 2e-3) << cases[i].name;
        std::printf("  %-36s p %.3g  dof %d  integral %.5f\n", cases[i].name.c_str(), r.p_value, r.dof, r.pdf_integral);
    }
}

// A pdf off by a few percent in one leaf must fail: the test above can detect what it checks.
TEST(BsdfWrappers, BlendChiSquareRejectsWrongWeights) {
    BlendCase c = blend_cases()[0];
    ChiSquareSetup s = setup_for(c, 9);
    BlendCase wrong = c;
    wrong.w = {0.75f, 0.25f};  // the pdf of a different mixture
    auto leaves = std::make_shared<BlendCase>(wrong);
    auto w = std::make_shared<WrappedBsdf>(wrapped_of(*leaves));
    s.pdf = [leaves, w, c](const dvec3& p) { return double(w->pdf_w(c.wo, glm::normalize(vec3(p)))); };
    EXPECT_LT(chi_square_2d(s).p_value, 1e-6);
}

// For a non-delta sample, f and pdf are the whole mixture's at the sampled direction.
TEST(BsdfWrappers, SampleAgreesWithEvalAndPdf) {
    for (const BlendCase& c : blend_cases()) {
        const WrappedBsdf w = wrapped_of(c);
        PCG32 rng(5, 7);
        int checked = 0;
        for (int i = 0; i < 20000; ++i) {
            float u1 = rng.next_float();
            float a = rng.next_float();
            auto bs = w.sample_w(c.wo, u1, vec2(a, rng.next_float()));
            if (!bs || bs->delta) continue;
            const vec3 f = w.eval_w(c.wo, bs->wi);
            const float p = w.pdf_w(c.wo, bs->wi);
            ASSERT_NEAR(bs->pdf, p, 1e-4f * std::max(1.f, p)) << c.name;
            for (int k = 0; k < 3; ++k) ASSERT_NEAR(bs->f[k], f[k], 1e-4f * std::max(1.f, f[k])) << c.name;
            ASSERT_TRUE(std::isfinite(bs->weight().x)) << c.name;
            ++checked;
        }
        EXPECT_GT(checked, 1000) << c.name;
    }
}

// A height h = k s x over the texels of a ramp bitmap (texel i holds s i) has dh/du = k s W in its
// interior; on a plane with dp/du = (1, 0, 0) and dp/dv = (0, 1, 0) the bumped normal is
// (-k s W, 0, 1) normalised: tilted by atan(k s W).
TEST(BsdfWrappers, ConstantSlopeBumpTiltsNormal) {
    auto grid = std::make_shared<TexelGrid>();
    grid->width = 16;
    grid->height = 4;
    grid->channels = 1;
    const float s = 0.05f, k = 0.3f;
    for (int y = 0; y < grid->height; ++y)
        for (int x = 0; x < grid->width; ++x) grid->data.push_back(s * float(x));
    BitmapTexture b;
    b.texels = grid;
    b.wrap = TextureWrap::Clamp;
    const Texture tex{b};
    for (float u : {0.2f, 0.41f, 0.5f, 0.77f}) {
        TextureQuery q;
        q.uv = vec2(u, 0.4f);
        const vec2 g = tex.eval_1_grad(q);
        EXPECT_NEAR(g.x, s * 16.f, 1e-4f);
        EXPECT_NEAR(g.y, 0.f, 1e-6f);
        const vec3 n = glm::normalize(bump_normal(vec3(0, 0, 1), vec3(0, 0, 1), vec3(1, 0, 0), vec3(0, 1, 0), k * g));
        EXPECT_NEAR(std::acos(n.z), std::atan(k * s * 16.f), 1e-4f);
        EXPECT_LT(n.x, 0.f);  // rising height in +u: the normal leans towards -u
    }
    // Finite differences of eval_1 agree with the gradient.
    TextureQuery q0, q1;
    q0.uv = vec2(0.45f, 0.5f);
    q1.uv = vec2(0.46f, 0.5f);
    EXPECT_NEAR((tex.eval_1(q1) - tex.eval_1(q0)) / 0.01f, tex.eval_1_grad(q0).x, 1e-3f);
}

// The flat normal map colour (0.5, 0.5, 1) is the shading normal itself: nothing changes.
TEST(BsdfWrappers, FlatNormalMapChangesNothing) {
    const vec3 ns = glm::normalize(vec3(0.3f, -0.2f, 0.9f));
    const vec3 n = normalmap_normal(ns, vec3(1.f, 0.5f, 0.f), vec3(0.5f, 0.5f, 1.f));
    EXPECT_NEAR(glm::length(glm::normalize(n) - ns), 0.f, 1e-6f);
    const Bsdf metal = rough_metal(0.2f);
    WrappedBsdf w;
    w.n = 1;
    w.leaf[0] = &metal;
    w.w[0] = 1.f;
    w.perturbed = true;
    w.terminator = true;
    const vec3 wo = glm::normalize(vec3(0.2f, 0.1f, 0.9f));
    w.frame = perturbed_frame(vec3(0.f, 0.f, 1.f), wo, true);
    PCG32 rng(3, 1);
    for (int i = 0; i < 1000; ++i) {
        const vec3 wi = glm::normalize(vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float()));
        const vec3 a = w.eval_w(wo, wi), b = eval(metal, wo, wi);
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(a[c], b[c], 1e-5f * std::max(1.f, b[c]));
        ASSERT_NEAR(w.pdf_w(wo, wi), pdf(metal, wo, wi), 1e-4f);
    }
}

// A direction below the tangent plane of either frame gets nothing (no light leak): a strongly
// tilted normal, light from just above the geometric horizon on the far side.
TEST(BsdfWrappers, TiltedFrameLeaksNoLight) {
    const Bsdf d = diffuse(vec3(1.f));
    WrappedBsdf w;
    w.n = 1;
    w.leaf[0] = &d;
    w.w[0] = 1.f;
    w.perturbed = true;
    const vec3 wo(0.f, 0.f, 1.f);
    w.frame = perturbed_frame(glm::normalize(vec3(1.f, 0.f, 1.f)), wo, true);  // 45 degrees towards +x
    const vec3 wi_below_perturbed = glm::normalize(vec3(-1.f, 0.f, 0.3f));  // above the surface, below P
    EXPECT_EQ(w.eval_w(wo, wi_below_perturbed), vec3(0.f));
    EXPECT_EQ(w.pdf_w(wo, wi_below_perturbed), 0.f);
    const vec3 wi_below_surface = glm::normalize(vec3(1.f, 0.f, -0.3f));  // above P, below the surface
    EXPECT_EQ(w.eval_w(wo, wi_below_surface), vec3(0.f));
    PCG32 rng(1, 2);
    for (int i = 0; i < 10000; ++i) {
        float a = rng.next_float();
        auto bs = w.sample_w(wo, rng.next_float(), vec2(a, rng.next_float()));
        if (bs) {
            ASSERT_GT(bs->wi.z, 0.f);
        }
    }
}

// ---- masks in scenes -----------------------------------------------------------------------------

namespace {

// A unit-square light facing down at height 2 and (optionally) a masked occluder at height 1
// between it and a white diffuse floor; or, with `behind`, a big light seen through a black masked
// plane by the camera.
std::string mask_scene(const std::string& occluder_bsdf, bool behind) {
    std::string s = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="2"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="20"/>
    <transform name="to_world"><lookat origin="0, 0.5, 0.001" target="0, 0, 0" up="0, 0, -1"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
  </sensor>
)";
    if (behind) {
        s += R"(  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="5"/><translate y="-1"/></transform>
    <emitter type="area"><rgb name="radiance" value="2, 1, 0.5"/></emitter></shape>
)";
        if (!occluder_bsdf.empty())
            s += "  <shape type=\"rectangle\"><transform name=\"to_world\"><rotate x=\"1\" angle=\"-90\"/><scale value=\"3\"/></transform>\n" +
                 occluder_bsdf + "</shape>\n";
    } else {
        s += R"(  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="4"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="1, 1, 1"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="90"/><scale value="0.3"/><translate y="2"/></transform>
    <emitter type="area"><rgb name="radiance" value="10, 10, 10"/></emitter></shape>
)";
        if (!occluder_bsdf.empty())
            s += "  <shape type=\"rectangle\"><transform name=\"to_world\"><rotate x=\"1\" angle=\"90\"/><scale value=\"1.5\"/><translate y=\"1\"/></transform>\n" +
                 occluder_bsdf + "</shape>\n";
    }
    return s + "</scene>\n";
}

std::shared_ptr<const Scene> build_from(const std::string& xml, const std::string& tag) {
    const std::string path = std::string("/tmp/candela_wrappers_") + tag + ".xml";
    std::ofstream(path) << xml;
    return build_scene(load_scene(path));
}

// The mean over the image (every channel) and its standard error, from batches.
RunningStats mean_radiance(const Scene& sc, SamplingMode mode, int channel, uint64_t seed0) {
    RunningStats rs;
    SceneParams p = sc.params();
    p.settings.sampling = mode;
    for (int b = 0; b < 16; ++b) {
        p.settings.seed = seed0 + uint64_t(b);
        Film film(p.settings.width, p.settings.height);
        Renderer::render_pass(*sc.with_params(p), film, 0, 64, 0);
        double sum = 0;
        for (int y = 0; y < film.height(); ++y)
            for (int x = 0; x < film.width(); ++x) sum += film.pixel(x, y)[channel];
        rs.add(sum / double(film.width() * film.height()));
    }
    return rs;
}

}  // namespace

// The camera looks through a black masked plane of opacity 0.3 at an emitter: the expected
// radiance is exactly 0.7 Le (the nested BSDF reflects nothing); null lets all of it through.
TEST(BsdfWrappers, MaskLetsOneMinusOpacityThrough) {
    const char* masked = R"(<bsdf type="mask"><float name="opacity" value="0.3"/><bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf></bsdf>)";
    for (auto [bsdf, expected] : {std::pair<const char*, double>{masked, 0.7}, {R"(<bsdf type="null"/>)", 1.0}}) {
        auto sc = build_from(mask_scene(bsdf, true), "behind");
        for (SamplingMode mode : {SamplingMode::Light, SamplingMode::Bsdf, SamplingMode::Mis}) {
            const RunningStats r = mean_radiance(*sc, mode, 0, 11);
            const MeanTest t = t_test(r, 2.0 * expected, 1e-6);
            EXPECT_GE(t.p_value, kAlpha / 6) << "opacity case " << expected << " mode " << int(mode) << ": mean " << r.mean();
        }
    }
}

// Light on a white floor through a masked occluder of opacity 0.3 is 0.7 of the unoccluded light,
// in light, BSDF and MIS sampling alike. The camera sits between occluder and floor and sees only
// the floor; the occluder's nested BSDF is black, so that all the floor receives is the light's
// direct contribution times the transmittance (bounces off the floor then leave the scene).
TEST(BsdfWrappers, ShadowRaysCrossMasks) {
    const char* masked = R"(<bsdf type="mask"><float name="opacity" value="0.3"/><bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf></bsdf>)";
    auto open = build_from(mask_scene("", false), "open");
    auto occluded = build_from(mask_scene(masked, false), "masked");
    auto opaque = build_from(mask_scene(R"(<bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>)", false), "opaque");
    const RunningStats ref = mean_radiance(*open, SamplingMode::Mis, 1, 100);
    ASSERT_GT(ref.mean(), 0.01);
    for (SamplingMode mode : {SamplingMode::Light, SamplingMode::Bsdf, SamplingMode::Mis}) {
        const RunningStats m = mean_radiance(*occluded, mode, 1, 200 + 20 * uint64_t(mode));
        const double se = std::sqrt(sqr(m.std_error()) + 0.49 * sqr(ref.std_error()));
        const double z = (m.mean() - 0.7 * ref.mean()) / se;
        std::printf("  mode %d: masked %.5f, 0.7 x open %.5f, z %.2f\n", int(mode), m.mean(), 0.7 * ref.mean(), z);
        EXPECT_LT(std::abs(z), 3.5) << "mode " << int(mode);
        // An opaque occluder of the same shape blocks it all: the test sees the occluder.
        EXPECT_EQ(mean_radiance(*opaque, mode, 1, 300).mean(), 0.0);
    }
}

// ---- the mask experiment of issue 43: a sun through a mask onto a plane -------------------------------
//
// tests/data/scenes/sun_mask.xml (a sphere sun) and sun_mask_directional.xml (a directional one): a
// diffuse plane (rho = 0.5) lit through a black mask of opacity 0.5 has the exact radiance
// rho (1 - a) Ls (r/d)^2 cos 30deg = 0.2165064 (sphere; pi Ls (r/d)^2 cos is a sphere's
// irradiance) and rho / pi (1 - a) E cos 30deg = 0.0689161 (directional). candela's light
// sampling crosses the mask with transmittance 1 - a; BSDF sampling passes it with probability
// 1 - a; both, and MIS, must give the exact value (docs/materials.md has the experiment and
// Mitsuba 3.9.1's figures: its shadow rays stop at masks).

namespace {

RunningStats sun_mask_mean(const std::string& file, const std::string& opacity, SamplingMode mode, int spp, uint64_t seed0) {
    auto sc = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/" + file, {{"res", "8"}, {"opacity", opacity}}));
    RunningStats rs;
    SceneParams p = sc->params();
    p.settings.sampling = mode;
    for (int b = 0; b < 16; ++b) {
        p.settings.seed = seed0 + uint64_t(b);
        Film film(p.settings.width, p.settings.height);
        Renderer::render_pass(*sc->with_params(p), film, 0, spp, 0);
        double sum = 0;
        for (int y = 0; y < film.height(); ++y)
            for (int x = 0; x < film.width(); ++x) sum += film.pixel(x, y)[1];
        rs.add(sum / double(film.width() * film.height()));
    }
    return rs;
}

const double kSunExact = 0.5 * 0.5 * 400.0 * 0.0025 * 0.86602540378;        // sphere sun, opacity 0.5
const double kDirectionalExact = 0.5 / 3.14159265358979 * 0.5 * 0.86602540378;  // directional, opacity 0.5

}  // namespace

TEST(BsdfWrappers, SunThroughMaskIsExact) {
    struct Case {
        const char* file;
        SamplingMode mode;
        int spp;
        double exact;
    } cases[] = {
        {"sun_mask.xml", SamplingMode::Mis, 16, kSunExact},
        {"sun_mask.xml", SamplingMode::Light, 16, kSunExact},
        {"sun_mask.xml", SamplingMode::Bsdf, 1024, kSunExact},  // hits the sun 1 time in ~900
        {"sun_mask_directional.xml", SamplingMode::Mis, 4, kDirectionalExact},
        {"sun_mask_directional.xml", SamplingMode::Light, 4, kDirectionalExact},
    };
    uint64_t seed = 500;
    for (const Case& c : cases) {
        const RunningStats r = sun_mask_mean(c.file, "0.5", c.mode, c.spp, seed += 100);
        const MeanTest t = t_test(r, c.exact, 1e-6 * c.exact);
        std::printf("  %s mode %d: %.6f +- %.6f, exact %.6f, p %.3g\n", c.file, int(c.mode), r.mean(), r.std_error(), c.exact,
                    t.p_value);
        EXPECT_GE(t.p_value, kAlpha / 5) << c.file << " mode " << int(c.mode);
        // Precise enough that the control (1.2 times the light) is rejected by 5 standard errors.
        EXPECT_LT(r.std_error(), 0.04 * c.exact) << c.file << " mode " << int(c.mode);
    }
}

// The control: the same renders against the answer for another opacity (0.4: 1.2 times the light)
// and against Mitsuba's rule (shadow rays stop at masks: light sampling would see 0) must fail.
TEST(BsdfWrappers, SunThroughMaskDetectsWrongTransmittance) {
    for (SamplingMode mode : {SamplingMode::Mis, SamplingMode::Bsdf}) {
        const RunningStats r = sun_mask_mean("sun_mask.xml", "0.5", mode, mode == SamplingMode::Bsdf ? 1024 : 16, 900);
        EXPECT_LT(t_test(r, 1.2 * kSunExact, 1e-6 * kSunExact).p_value, kAlpha) << "mode " << int(mode);
    }
    const RunningStats light = sun_mask_mean("sun_mask_directional.xml", "0.5", SamplingMode::Light, 4, 950);
    EXPECT_LT(t_test(light, 0.0, 1e-6 * kDirectionalExact).p_value, kAlpha);
    EXPECT_LT(t_test(light, 1.2 * kDirectionalExact, 1e-6 * kDirectionalExact).p_value, kAlpha);
}

// ---- a blend with a delta leaf (issue 43), against Mitsuba 3.9.1 renders of its two leaves ------------
//
// tests/data/scenes/blend_delta.xml: a sphere whose blendbsdf mixes a GGX roughplastic and a smooth
// conductor (eta, k as wavelength:value spectra) under an environment map. The image is linear in the
// BSDF (a lone convex sphere: no interreflection), so the blend of weight 0.5 must render the mean of
// the weight-0 and weight-1 images. The references are Mitsuba 3.9.1's renders of those two (which it
// renders correctly: one leaf is sampled alone), 16 x 1024 spp at 32 x 32:
//   $PY tests/data/make_reference.py tests/data/scenes/blend_delta.xml --res 32 --batches 16 --spp 1024
//       -D weight=0 --out tests/data/blend_delta_w0       (and weight=1 --out .../blend_delta_w1)
// Mitsuba's own weight-0.5 image is 21% darker in red than that mean (docs/materials.md): its blend
// adds the delta leaf's discrete probability to the other leaf's density.

namespace {

ImageEstimate blend_delta_reference(double w) {
    const std::string d = std::string(CANDELA_TEST_DATA) + "/blend_delta_w";
    const ImageEstimate a = ImageEstimate::from_reference_files(d + "0"), b = ImageEstimate::from_reference_files(d + "1");
    ImageEstimate m = a;
    for (size_t i = 0; i < m.mean.size(); ++i) {
        m.mean[i] = (1.0 - w) * a.mean[i] + w * b.mean[i];
        m.var_of_mean[i] = (1.0 - w) * (1.0 - w) * a.var_of_mean[i] + w * w * b.var_of_mean[i];
    }
    return m;
}

ImageEstimate render_blend_delta(const std::string& weight) {
    auto built = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/blend_delta.xml", {{"res", "32"}, {"weight", weight}}));
    return candela::test::render_batch_estimate(*built, built->params(), 8, 128);
}

}  // namespace

TEST(BsdfWrappers, BlendWithDeltaLeafIsLinear) {
    const ImageEstimate ref = blend_delta_reference(0.5);
    ASSERT_EQ(ref.width, 32);
    const ImageEstimate test = render_blend_delta("0.5");
    BlockTestResult r = block_z_test(test, ref, 8, kAlpha);
    dvec3 rel;
    const double p = whole_image_p(test, ref, &rel);
    std::printf("  blocks: %s\n  whole image: p = %.3g, relative difference (%.4f, %.4f, %.4f)\n", r.describe().c_str(), p,
                rel.x, rel.y, rel.z);
    EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
    EXPECT_GE(p, kAlpha);
}

// The control: weight 0.4 against the weight-0.5 reference must fail.
TEST(BsdfWrappers, BlendWithDeltaLeafDetectsWrongWeight) {
    const ImageEstimate ref = blend_delta_reference(0.5);
    const ImageEstimate test = render_blend_delta("0.4");
    BlockTestResult r = block_z_test(test, ref, 8, kAlpha);
    const double p = whole_image_p(test, ref, nullptr);
    std::printf("  weight 0.4: blocks %s, whole image p = %.3g\n", r.describe().c_str(), p);
    EXPECT_TRUE(!r.passed(kAlpha) || p < kAlpha);
}

// ---- the wrappers in a scene, against Mitsuba 3.9.1 -------------------------------------------------
//
// tests/data/scenes/wrappers.xml (a bump-mapped floor, a normal-mapped wall, a cube blending a
// diffuse and a rough metal by a checkerboard weight) against the mean of 16 Mitsuba 3.9.1
// llvm_ad_rgb renders of 2048 spp at 32 x 32 and the variance of that mean, made by
//   $PY tests/data/make_reference.py tests/data/scenes/wrappers.xml --res 32 --batches 16 --spp 2048
//       --out tests/data/wrappers32
// candela renders 8 batches of 256 spp. Control: the bump scale 0.4 -> 0.2 must fail.

namespace {

ImageEstimate render_wrappers(const std::string& bump) {
    auto built = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/wrappers.xml", {{"res", "32"}, {"bump", bump}}));
    return candela::test::render_batch_estimate(*built, built->params(), 8, 256);
}

}  // namespace

TEST(BsdfWrappers, MitsubaAgreementRender) {
    ImageEstimate ref = ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/wrappers32");
    ASSERT_EQ(ref.width, 32);
    ImageEstimate test = render_wrappers("0.4");
    BlockTestResult r = block_z_test(test, ref, 8, kAlpha);
    dvec3 rel;
    double p = whole_image_p(test, ref, &rel);
    std::printf("  blocks: %s\n  whole image: p = %.3g, relative difference (%.4f, %.4f, %.4f)\n", r.describe().c_str(), p,
                rel.x, rel.y, rel.z);
    EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
    EXPECT_GE(p, kAlpha);
}

TEST(BsdfWrappers, MitsubaAgreementDetectsWrongBumpScale) {
    ImageEstimate ref = ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/wrappers32");
    ImageEstimate test = render_wrappers("0.2");
    BlockTestResult r = block_z_test(test, ref, 8, kAlpha);
    double p = whole_image_p(test, ref, nullptr);
    std::printf("  bump scale halved: blocks %s, whole image p = %.3g\n", r.describe().c_str(), p);
    EXPECT_TRUE(!r.passed(kAlpha) || p < kAlpha);
}

// eval_pdf is what next-event estimation calls in place of eval then pdf: it must give exactly their
// bits (the images stay the same), for every BSDF of the closed set, both sides, both transport
// modes, grazing and random directions, and through the wrappers (blends, perturbed frames).
namespace {
bool same_bits(const BsdfEval& e, vec3 f, float p) {
    return std::memcmp(&e.f, &f, sizeof f) == 0 && std::memcmp(&e.pdf, &p, sizeof p) == 0;
}
vec3 random_direction(PCG32& rng) {
    const float z = 1.f - 2.f * rng.next_float(), phi = 2.f * kPi * rng.next_float();
    const float r = std::sqrt(std::max(0.f, 1.f - z * z));
    return vec3(r * std::cos(phi), r * std::sin(phi), z);
}
}  // namespace

TEST(BsdfEvalPdf, SameBitsAsEvalAndPdf) {
    std::vector<std::pair<std::string, Bsdf>> set;
    set.push_back({"diffuse", diffuse(vec3(0.2f, 0.5f, 0.9f))});
    set.push_back({"mirror", ConductorBsdf{}});
    for (float a : {1e-4f, 0.05f, 0.3f, 1.f}) {
        set.push_back({"rough metal " + std::to_string(a), rough_metal(a)});
        ConductorBsdf beck;
        beck.alpha_u = a;
        beck.alpha_v = 0.5f * a;
        set.push_back({"anisotropic Beckmann metal " + std::to_string(a), beck});
        set.push_back({"rough glass " + std::to_string(a), rough_glass(a)});
        PlasticBsdf pl;
        pl.alpha = a;
        pl.distribution = MicrofacetType::GGX;
        pl.nonlinear = a > 0.2f;
        pl.prepare();
        set.push_back({"rough plastic " + std::to_string(a), pl});
        PPlasticBsdf pp;
        pp.alpha_u = a;
        pp.alpha_v = 2.f * a;
        set.push_back({"pplastic " + std::to_string(a), pp});
    }
    PlasticBsdf smooth_plastic;
    smooth_plastic.prepare();
    set.push_back({"smooth plastic", smooth_plastic});
    set.push_back({"unprepared plastic", PlasticBsdf{}});
    set.push_back({"smooth glass", DielectricBsdf{}});
    set.push_back({"thin glass", ThinDielectricBsdf{}});
    PrincipledBsdf pr;
    pr.metallic = 0.3f;
    pr.spec_trans = 0.4f;
    pr.has_spec_trans = true;
    pr.clearcoat = 0.5f;
    pr.sheen = 0.6f;
    pr.anisotropic = 0.5f;
    set.push_back({"principled", pr});
    set.push_back({"principled default", PrincipledBsdf{}});

    PCG32 rng(11, 3);
    for (const auto& [name, b] : set) {
        int nonzero = 0;
        for (int i = 0; i < 4000; ++i) {
            vec3 wo = random_direction(rng), wi = random_direction(rng);
            if (i % 4 == 0) wo = glm::normalize(vec3(wo.x, wo.y, 1e-4f * wo.z));  // grazing
            if (i % 8 == 1) wi = glm::normalize(vec3(-wo.x, -wo.y, wo.z) + 1e-3f * wi);  // near the mirror
            for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
                const BsdfEval e = eval_pdf(b, wo, wi, mode);
                ASSERT_TRUE(same_bits(e, eval(b, wo, wi, mode), pdf(b, wo, wi, mode)))
                    << name << " wo " << wo.x << " " << wo.y << " " << wo.z << " wi " << wi.x << " " << wi.y << " " << wi.z;
                nonzero += e.pdf > 0.f;
            }
        }
        // Every non-delta BSDF is evaluated somewhere (so that the comparison is not of zeros; at
        // alpha 1e-4 only the near-mirror pairs are).
        if (has_smooth_component(b) && name != "unprepared plastic") {
            EXPECT_GT(nonzero, 200) << name;
        }
    }
    for (const BlendCase& c : blend_cases()) {
        const WrappedBsdf w = wrapped_of(c);
        int nonzero = 0;
        for (int i = 0; i < 4000; ++i) {
            const vec3 wi = random_direction(rng);
            const BsdfEval e = w.eval_pdf_w(c.wo, wi);
            ASSERT_TRUE(same_bits(e, w.eval_w(c.wo, wi), w.pdf_w(c.wo, wi))) << c.name;
            nonzero += e.pdf > 0.f;
        }
        EXPECT_GT(nonzero, 1000) << c.name;
    }
}
