// Agreement with Mitsuba 3 of the microfacet plugins' values, named conductors and thindielectric:
// tests/data/bsdf_values_mitsuba.txt holds Mitsuba's bsdf.eval for a table of direction pairs
// (made by tests/data/make_bsdf_values.py); the same <bsdf> is read here by candela's XML
// loader and evaluated. Also the XML rules of the new parameters (distribution, alpha_u/alpha_v,
// material names) and the thindielectric's lobes.
#include <gtest/gtest.h>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include "bsdf/bsdf.h"
#include "bsdf/named_conductors.h"
#include "core/error.h"
#include "scene/loaders.h"
#include "scene/scene.h"
#include "support/bsdf_xml.h"
#include "support/render.h"
#include "support/run.h"
#include "support/stats.h"

using namespace candela;

namespace {

Material load_material(const std::string& name, const std::string& bsdf_xml) {
    return candela::test::load_bsdf_material("bsdf_mitsuba", name, bsdf_xml);
}
std::string load_error(const std::string& name, const std::string& bsdf_xml) {
    return candela::test::load_bsdf_error("bsdf_mitsuba", name, bsdf_xml);
}

}  // namespace

// f(wo, wi) |cos wi| of candela against Mitsuba's bsdf.eval, for each BSDF of the table. The
// values are float computations of the same formulas: 2e-4 relative (plus 1e-6 absolute) covers
// their rounding; the plastic's coat tables are quadratures on both sides (Mitsuba's on a
// different rule), so it gets 1 %.
TEST(BsdfMitsuba, ValuesAgree) {
    std::ifstream in(std::string(CANDELA_TEST_DATA) + "/bsdf_values_mitsuba.txt");
    ASSERT_TRUE(in.good());
    std::string line, xml;
    Material m;
    int n = 0, bsdfs = 0, nonzero = 0;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        if (line.rfind("bsdf ", 0) == 0) {
            xml = line.substr(5);
            m = load_material("table" + std::to_string(bsdfs++), xml);
            prepare(m.bsdf);
            continue;
        }
        std::istringstream ss(line);
        vec3 wo, wi, expected;
        ss >> wo.x >> wo.y >> wo.z >> wi.x >> wi.y >> wi.z >> expected.x >> expected.y >> expected.z;
        const vec3 f = eval(m.bsdf, wo, wi, TransportMode::Radiance);
        const bool coat = xml.find("type=\"plastic\"") != std::string::npos ||
                          xml.find("type=\"roughplastic\"") != std::string::npos;
        const float rel = coat ? 1e-2f : 2e-4f;
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(f[k], expected[k], rel * std::abs(expected[k]) + 1e-6f)
                << xml << "\n wo " << wo.x << " " << wo.y << " " << wo.z << " wi " << wi.x << " " << wi.y << " " << wi.z;
        nonzero += expected.x > 0.f;
        ++n;
    }
    EXPECT_EQ(bsdfs, 8);
    EXPECT_GT(n, 140);
    EXPECT_GT(nonzero, 100);
}

// Every name Mitsuba ships both tables for is accepted, with Mitsuba's RGB conversion (spot
// checks against Mitsuba 3.9.1's mi.traverse values), and "none" is the (0, 1) mirror.
TEST(BsdfMitsuba, NamedConductors) {
    const std::vector<std::string> names = named_conductor_names();
    EXPECT_EQ(names.size(), 71u);
    for (const char* n : {"Ag", "Al", "Au", "Cu", "Cr", "W", "a-C", "d-C", "Cu_palik", "TiO2-e"})
        EXPECT_NE(named_conductor(n), nullptr) << n;
    const Material au = load_material("au", "<bsdf type=\"conductor\"><string name=\"material\" value=\"Au\"/></bsdf>");
    const ConductorBsdf& c = std::get<ConductorBsdf>(au.bsdf);
    EXPECT_NEAR(c.eta.x, 0.143036f, 1e-5f);
    EXPECT_NEAR(c.eta.z, 1.44205f, 1e-4f);
    EXPECT_NEAR(c.k.y, 2.38556f, 1e-4f);
    const Material none = load_material("none", "<bsdf type=\"roughconductor\"><string name=\"material\" value=\"none\"/></bsdf>");
    EXPECT_EQ(std::get<ConductorBsdf>(none.bsdf).eta, vec3(0.f));
    EXPECT_EQ(std::get<ConductorBsdf>(none.bsdf).k, vec3(1.f));
    EXPECT_NE(load_error("unknown", "<bsdf type=\"conductor\">\n<string name=\"material\" value=\"Unobtainium\"/></bsdf>")
                  .find("unknown conductor material 'Unobtainium'"),
              std::string::npos);
}

TEST(BsdfMitsuba, MicrofacetParameters) {
    // Mitsuba's default distribution is Beckmann; alpha_u / alpha_v are anisotropic.
    const Material d = load_material("default", "<bsdf type=\"roughconductor\"/>");
    EXPECT_EQ(std::get<ConductorBsdf>(d.bsdf).distribution, MicrofacetType::Beckmann);
    EXPECT_FLOAT_EQ(std::get<ConductorBsdf>(d.bsdf).alpha_u, 0.1f);
    const Material a = load_material("aniso", "<bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"GGX\"/>"
                                              "<float name=\"alpha_u\" value=\"0.2\"/><float name=\"alpha_v\" value=\"0.6\"/></bsdf>");
    const DielectricBsdf& g = std::get<DielectricBsdf>(a.bsdf);
    EXPECT_EQ(g.distribution, MicrofacetType::GGX);
    EXPECT_FLOAT_EQ(g.alpha_u, 0.2f);
    EXPECT_FLOAT_EQ(g.alpha_v, 0.6f);
    const Material p = load_material("plastic", "<bsdf type=\"roughplastic\"/>");
    EXPECT_EQ(std::get<PlasticBsdf>(p.bsdf).distribution, MicrofacetType::Beckmann);
    // pplastic: Mitsuba's defaults (Beckmann, alpha 0.1, polypropylene in air), anisotropic allowed.
    const Material pp = load_material("pplastic", "<bsdf type=\"pplastic\"/>");
    const PPlasticBsdf& ppb = std::get<PPlasticBsdf>(pp.bsdf);
    EXPECT_EQ(ppb.distribution, MicrofacetType::Beckmann);
    EXPECT_FLOAT_EQ(ppb.alpha_u, 0.1f);
    EXPECT_FLOAT_EQ(ppb.alpha_v, 0.1f);
    EXPECT_FLOAT_EQ(ppb.int_ior, 1.49f);
    EXPECT_EQ(ppb.diffuse_reflectance, vec3(0.5f));
    const Material ppa = load_material("pplastic_aniso", "<bsdf type=\"pplastic\"><float name=\"alpha_u\" value=\"0.3\"/>"
                                                         "<float name=\"alpha_v\" value=\"0.05\"/></bsdf>");
    EXPECT_TRUE(is_anisotropic(ppa.bsdf));
    EXPECT_NE(load_error("pp_tex", "<bsdf type=\"pplastic\">\n<texture type=\"checkerboard\" name=\"alpha\"/></bsdf>")
                  .find("pplastic's roughness is a number"),
              std::string::npos);
    EXPECT_NE(load_error("pp_ior", "<bsdf type=\"pplastic\">\n<float name=\"int_ior\" value=\"1.3\"/>"
                                   "<float name=\"ext_ior\" value=\"1.3\"/></bsdf>")
                  .find("must differ"),
              std::string::npos);
    EXPECT_NE(load_error("pp_nl", "<bsdf type=\"pplastic\">\n<boolean name=\"nonlinear\" value=\"true\"/></bsdf>")
                  .find("nonlinear"),
              std::string::npos);
    // Refusals, one line with file:line each.
    EXPECT_NE(load_error("bad_dist", "<bsdf type=\"roughconductor\">\n<string name=\"distribution\" value=\"phong\"/></bsdf>")
                  .find("must be beckmann or ggx"),
              std::string::npos);
    EXPECT_NE(load_error("both", "<bsdf type=\"roughconductor\">\n<float name=\"alpha\" value=\"0.1\"/>"
                                 "<float name=\"alpha_u\" value=\"0.1\"/><float name=\"alpha_v\" value=\"0.1\"/></bsdf>")
                  .find("either alpha or alpha_u/alpha_v"),
              std::string::npos);
    EXPECT_NE(load_error("half", "<bsdf type=\"roughdielectric\">\n<float name=\"alpha_u\" value=\"0.1\"/></bsdf>")
                  .find("both alpha_u and alpha_v"),
              std::string::npos);
    EXPECT_NE(load_error("iso", "<bsdf type=\"roughplastic\">\n<float name=\"alpha_u\" value=\"0.1\"/>"
                                "<float name=\"alpha_v\" value=\"0.2\"/></bsdf>")
                  .find("isotropic"),
              std::string::npos);
}

// A roughness texture drives alpha (and alpha_u / alpha_v) per point, Mitsuba's float reading
// of a texture (the luminance of its colour).
TEST(BsdfMitsuba, TexturedRoughness) {
    const Material m = load_material("tex", "<bsdf type=\"roughconductor\"><texture type=\"checkerboard\" name=\"alpha\">"
                                            "<rgb name=\"color0\" value=\"0.05\"/><rgb name=\"color1\" value=\"0.6\"/>"
                                            "</texture></bsdf>");
    ASSERT_EQ(m.textures.size(), 1u);
    EXPECT_STREQ(m.textures[0].parameter, "alpha");
    Bsdf scratch;
    std::vector<float> seen;
    for (float u : {0.25f, 0.75f}) {
        TextureQuery q;
        q.uv = vec2(u, 0.25f);
        const ConductorBsdf& c = std::get<ConductorBsdf>(bsdf_at(m, q, scratch));
        EXPECT_EQ(c.alpha_u, c.alpha_v);
        seen.push_back(c.alpha_u);
    }
    std::sort(seen.begin(), seen.end());
    EXPECT_NEAR(seen[0], 0.05f, 1e-6f);
    EXPECT_NEAR(seen[1], 0.6f, 1e-6f);
    const Material d = load_material("texd", "<bsdf type=\"roughdielectric\"><texture type=\"checkerboard\" name=\"alpha_u\"/>"
                                             "<float name=\"alpha_v\" value=\"0.3\"/></bsdf>");
    EXPECT_EQ(d.textures.size(), 1u);
}

// thindielectric: R' = 2R / (1 + R) reflected, the rest straight through, from both sides;
// sample frequencies against those probabilities (binomial z-test) and the weights are the tints.
TEST(BsdfMitsuba, ThinDielectric) {
    const Material m = load_material("thin", "<bsdf type=\"thindielectric\"><float name=\"int_ior\" value=\"1.5\"/>"
                                             "<float name=\"ext_ior\" value=\"1.0\"/>"
                                             "<rgb name=\"specular_transmittance\" value=\"0.9 0.8 0.7\"/></bsdf>");
    const ThinDielectricBsdf& t = std::get<ThinDielectricBsdf>(m.bsdf);
    // Normal incidence: R = 0.04, R' = 0.08 / 1.04.
    EXPECT_NEAR(t.reflectance(1.f), 0.08f / 1.04f, 1e-6f);
    for (float side : {1.f, -1.f})
        for (float c : {0.9f, 0.3f}) {
            const vec3 wo = side * vec3(safe_sqrt(1.f - c * c), 0.f, c);
            PCG32 rng(11, 2);
            const int n = 200000;
            int refl = 0;
            for (int i = 0; i < n; ++i) {
                auto s = t.sample(wo, rng.next_float(), vec2(0.5f), TransportMode::Radiance);
                ASSERT_TRUE(s && s->delta);
                if (s->wi.z * wo.z > 0.f) {
                    ++refl;
                    EXPECT_NEAR(glm::length(s->wi - reflect_z(wo)), 0.f, 1e-6f);
                    EXPECT_NEAR(s->weight().x, 1.f, 1e-6f);
                } else {
                    EXPECT_NEAR(glm::length(s->wi + wo), 0.f, 1e-6f);
                    EXPECT_NEAR(s->weight().y, 0.8f, 1e-6f);
                    EXPECT_EQ(s->eta, 1.f);
                }
            }
            const double r = t.reflectance(c);
            const stats::MeanTest z = stats::z_test(double(refl) / n, std::sqrt(r * (1 - r) / n), r);
            EXPECT_GT(z.p_value, 1e-3) << z.describe();
        }
    EXPECT_EQ(t.pdf(vec3(0, 0, 1), vec3(0, 0, -1), TransportMode::Radiance), 0.f);
}

// ---- image agreement ------------------------------------------------------------------------------
// tests/data/scenes/microfacet.xml (a Beckmann copper sphere, a GGX roughdielectric
// pane with a textured alpha, a thindielectric pane, a Beckmann roughplastic cube) against the
// mean of 16 Mitsuba 3.9.1 renders of 1024 spp at 32 x 32 and the variance of that mean, made by
//   $PY tests/data/make_reference.py tests/data/scenes/microfacet.xml --res 32 --batches 16
//       --spp 1024 --out tests/data/microfacet32
// candela renders 16 batches of 128 spp; block z-test on 8 x 8 blocks. Control: the sphere with
// GGX instead of Beckmann (same alpha) must fail. Anisotropy: see BsdfMitsuba.Anisotropic* below.

namespace {

stats::ImageEstimate render_scene32(const char* scene, const std::vector<std::pair<std::string, std::string>>& defines) {
    auto d = defines;
    d.push_back({"res", "32"});
    auto built = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/" + scene, d));
    return candela::test::render_batch_estimate(*built, built->params(), 16, 128);
}

}  // namespace

TEST(BsdfMitsuba, RenderAgreement) {
    const stats::ImageEstimate ref = stats::ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/microfacet32");
    ASSERT_EQ(ref.width, 32);
    const stats::BlockTestResult r = stats::block_z_test(render_scene32("microfacet.xml", {}), ref, 8, 0.01);
    std::printf("  microfacet scene: %s\n", r.describe().c_str());
    EXPECT_TRUE(r.passed(0.01)) << r.describe();
}

TEST(BsdfMitsuba, RenderAgreementDetectsGgxForBeckmann) {
    const stats::ImageEstimate ref = stats::ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/microfacet32");
    const stats::BlockTestResult r = stats::block_z_test(render_scene32("microfacet.xml", {{"dist", "ggx"}}), ref, 8, 0.01);
    std::printf("  ggx sphere for beckmann: %s\n", r.describe().c_str());
    EXPECT_FALSE(r.passed(0.01)) << r.describe();
}

// ---- pplastic ------------------------------------------------------------------------------------
// tests/data/scenes/pplastic.xml: a Beckmann pplastic sphere, an anisotropic GGX one with a tinted
// specular term and int_ior 1.8, and a pplastic floor with a checkerboard diffuse reflectance,
// under an area light and a constant sky. Reference made by
//   $PY tests/data/make_reference.py tests/data/scenes/pplastic.xml --res 32 --batches 16
//       --spp 1024 --out tests/data/pplastic32
// Control: the first sphere as a roughplastic with the same parameters (a coat model whose diffuse
// term is brighter by 1 / ((1 - Ri) eta^2) times the transmittances) must fail.

TEST(BsdfMitsuba, PPlasticRenderAgreement) {
    const stats::ImageEstimate ref = stats::ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/pplastic32");
    ASSERT_EQ(ref.width, 32);
    // rel_floor 1e-5: the sky seen directly is noise-free in both, a few 1e-7 apart after Mitsuba's
    // RGB round trip.
    const stats::BlockTestResult r = stats::block_z_test(render_scene32("pplastic.xml", {}), ref, 8, 0.01, 1e-5);
    std::printf("  pplastic scene: %s\n", r.describe().c_str());
    EXPECT_TRUE(r.passed(0.01)) << r.describe();
    const stats::BlockTestResult c =
        stats::block_z_test(render_scene32("pplastic.xml", {{"type", "roughplastic"}}), ref, 8, 0.01, 1e-5);
    std::printf("  control, roughplastic for pplastic: %s\n", c.describe().c_str());
    EXPECT_FALSE(c.passed(0.01)) << c.describe();
}

// ---- anisotropy --------------------------------------------------------------------------------
// tests/data/scenes/anisotropic.xml: anisotropic GGX and Beckmann conductors on a sphere, a cylinder
// and a two-sided rectangle seen from its back, and a rough glass disk; the shading frame follows
// each surface's dp/du as Mitsuba's does. Reference made by
//   $PY tests/data/make_reference.py tests/data/scenes/anisotropic.xml --res 32 --batches 16
//       --spp 1024 --out tests/data/anisotropic32
// Control: the sphere's alpha_u and alpha_v swapped (the highlight stretched the other way, i.e.
// what a frame rotated by 90 degrees would give) must fail.

TEST(BsdfMitsuba, AnisotropicFrameFollowsDpDu) {
    // The frame's x axis is dp/du made orthogonal to n; y = n x s.
    const Frame f = Frame::from_tangent(vec3(0.f, 0.f, 1.f), vec3(2.f, 0.f, 1.f));
    EXPECT_NEAR(glm::length(f.s - vec3(1.f, 0.f, 0.f)), 0.f, 1e-6f);
    EXPECT_NEAR(glm::length(f.t - vec3(0.f, 1.f, 0.f)), 0.f, 1e-6f);
    // A tangent along n (or zero) falls back to the normal-only frame.
    const Frame g = Frame::from_tangent(vec3(0.f, 0.f, 1.f), vec3(0.f, 0.f, 3.f));
    const Frame h(vec3(0.f, 0.f, 1.f));
    EXPECT_EQ(g.s, h.s);
    // Only anisotropic materials pay for it.
    const Material iso = load_material("iso", "<bsdf type=\"roughconductor\"><float name=\"alpha\" value=\"0.2\"/></bsdf>");
    const Material an = load_material("an", "<bsdf type=\"roughconductor\"><float name=\"alpha_u\" value=\"0.2\"/>"
                                            "<float name=\"alpha_v\" value=\"0.1\"/></bsdf>");
    Material a = an, b = iso;
    prepare(a);
    prepare(b);
    EXPECT_TRUE(a.tangent_frame);
    EXPECT_FALSE(b.tangent_frame);
}

TEST(BsdfMitsuba, AnisotropicRenderAgreement) {
    const stats::ImageEstimate ref = stats::ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/anisotropic32");
    ASSERT_EQ(ref.width, 32);
    const stats::BlockTestResult r = stats::block_z_test(render_scene32("anisotropic.xml", {}), ref, 8, 0.01);
    std::printf("  anisotropic scene: %s\n", r.describe().c_str());
    EXPECT_TRUE(r.passed(0.01)) << r.describe();
}

TEST(BsdfMitsuba, AnisotropicRenderDetectsRotatedLobe) {
    const stats::ImageEstimate ref = stats::ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/anisotropic32");
    const stats::BlockTestResult r =
        stats::block_z_test(render_scene32("anisotropic.xml", {{"au", "0.4"}, {"av", "0.03"}}), ref, 8, 0.01);
    std::printf("  sphere's lobe rotated by 90 degrees: %s\n", r.describe().c_str());
    EXPECT_FALSE(r.passed(0.01)) << r.describe();
}
