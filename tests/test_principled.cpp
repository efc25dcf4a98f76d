// Mitsuba 3.9's `principled` BSDF (src/bsdf/principled.h): chi-square of sample() against pdf()
// for the lobes one at a time and together, grazing and near-normal; eval, pdf (both transport
// modes) and directional albedo against Mitsuba (tests/data/principled_values_mitsuba.txt, made by
// tests/data/make_principled_values.py, loading the same <bsdf> through candela's XML reader); the
// XML rules; an image z-test of tests/data/scenes/principled.xml against Mitsuba.
#include <gtest/gtest.h>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include "bsdf/bsdf.h"
#include "core/error.h"
#include "scene/loaders.h"
#include "scene/scene.h"
#include "support/bsdf_xml.h"
#include "support/render.h"
#include "support/run.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;  // family-wise significance of each TEST

Material load_material(const std::string& name, const std::string& bsdf_xml) {
    return candela::test::load_bsdf_material("principled", name, bsdf_xml);
}
std::string load_error(const std::string& name, const std::string& bsdf_xml) {
    return candela::test::load_bsdf_error("principled", name, bsdf_xml);
}

vec3 dir(float cos_theta, float phi = 0.7f) {
    const float s = safe_sqrt(1.f - cos_theta * cos_theta);
    return vec3(s * std::cos(phi), s * std::sin(phi), cos_theta);
}

// The table written by make_principled_values.py.
struct ValueRow {
    vec3 wo, wi, f_radiance, f_importance;
    float pdf;
};
struct AlbedoRow {
    vec3 wo, albedo, std_error;
    double n;
};
struct TableEntry {
    std::string xml;
    std::vector<ValueRow> values;
    std::vector<AlbedoRow> albedos;
};

std::vector<TableEntry> read_table() {
    std::ifstream in(std::string(CANDELA_TEST_DATA) + "/principled_values_mitsuba.txt");
    EXPECT_TRUE(in.good());
    std::vector<TableEntry> t;
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        if (line.rfind("bsdf ", 0) == 0) {
            t.push_back({line.substr(5), {}, {}});
            continue;
        }
        std::istringstream ss(line.substr(2));
        if (line[0] == 'v') {
            ValueRow r;
            ss >> r.wo.x >> r.wo.y >> r.wo.z >> r.wi.x >> r.wi.y >> r.wi.z >> r.f_radiance.x >> r.f_radiance.y >>
                r.f_radiance.z >> r.f_importance.x >> r.f_importance.y >> r.f_importance.z >> r.pdf;
            t.back().values.push_back(r);
        } else if (line[0] == 'a') {
            AlbedoRow r;
            ss >> r.wo.x >> r.wo.y >> r.wo.z >> r.albedo.x >> r.albedo.y >> r.albedo.z >> r.std_error.x >>
                r.std_error.y >> r.std_error.z >> r.n;
            t.back().albedos.push_back(r);
        }
    }
    return t;
}

PrincipledBsdf principled(float roughness, vec3 base = vec3(0.6f, 0.4f, 0.3f)) {
    PrincipledBsdf p;
    p.base_color = base;
    p.roughness = roughness;
    return p;
}

// ---- chi-square ------------------------------------------------------------------------------

struct Case {
    std::string name;
    Bsdf bsdf;
    vec3 wo;
};

// The sphere with cells that thin out towards the horizon (as test_bsdf_models.cpp): at grazing
// incidence the lobes hug the horizon, where the equal-area grid is too coarse for the quadrature.
Domain horizon_domain() {
    Domain d;
    d.name = "sphere (horizon-refined)";
    d.to_point = [](dvec2 g) {
        double t = 1.0 - 2.0 * g.x, z = t * t * t, r = std::sqrt(std::max(0.0, 1.0 - z * z));
        double phi = 2.0 * M_PI * g.y;
        return dvec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    d.to_grid = [](const dvec3& p, dvec2& g) {
        double len = glm::length(p);
        if (!(len > 0.0)) return false;
        double phi = std::atan2(p.y, p.x);
        if (phi < 0.0) phi += 2.0 * M_PI;
        g = dvec2((1.0 - std::cbrt(std::clamp(p.z / len, -1.0, 1.0))) / 2.0, std::min(phi / (2.0 * M_PI), 1.0 - 1e-12));
        g.x = std::clamp(g.x, 0.0, 1.0 - 1e-12);
        return true;
    };
    d.jacobian = [](dvec2 g) {
        double t = 1.0 - 2.0 * g.x;
        return 6.0 * t * t * 2.0 * M_PI;
    };
    return d;
}

ChiSquareSetup setup_for(const Bsdf& bsdf, vec3 wo, const Bsdf& claimed, uint64_t seed) {
    ChiSquareSetup s;
    const bool grazing = std::abs(wo.z) < 0.3f;
    s.domain = grazing ? horizon_domain() : sphere_domain();
    // Finer than test_bsdf_models.cpp's 20 x 40: the GGX lobes of roughness 0.3 (alpha 0.09) are
    // narrow enough for that grid's quadrature to be off by 3e-4 of the mass (RoughGlassNearNormal).
    s.res_x = 40;
    s.res_y = grazing ? 160 : 80;
    s.samples = 300000;
    s.integration_points = 31;
    s.seed = seed;
    s.sample = [bsdf, wo](PCG32& rng) {
        float u1 = rng.next_float();
        float a = rng.next_float();
        vec2 u2(a, rng.next_float());
        DomainSample d;
        auto bs = sample(bsdf, wo, u1, u2, TransportMode::Radiance);
        if (!bs) return d;
        d.kind = DomainSample::Smooth;
        d.p = dvec3(bs->wi);
        return d;
    };
    s.pdf = [claimed, wo](const dvec3& p) { return double(pdf(claimed, wo, glm::normalize(vec3(p)))); };
    return s;
}

std::vector<Case> chi2_cases() {
    std::vector<Case> cs;
    auto add = [&](const std::string& n, PrincipledBsdf b, bool inside) {
        for (float c : {0.95f, 0.5f, 0.2f}) {
            cs.push_back({n + " cos " + std::to_string(c).substr(0, 4), b, dir(c)});
            if (inside) cs.push_back({n + " inside cos " + std::to_string(c).substr(0, 4), b, -dir(c, 2.1f)});
        }
    };
    add("default", PrincipledBsdf{}, false);
    PrincipledBsdf metal = principled(0.5f);
    metal.metallic = 1.f;
    add("metallic r0.5", metal, false);
    metal.roughness = 0.3f;
    add("metallic r0.3", metal, false);
    PrincipledBsdf glass = principled(0.3f);
    glass.spec_trans = 1.f, glass.has_spec_trans = true, glass.eta = 1.5f;
    add("glass r0.3 eta1.5", glass, true);
    glass.roughness = 0.6f, glass.eta = 1.33f;
    add("glass r0.6 eta1.33", glass, true);
    PrincipledBsdf cc = principled(0.5f);
    cc.clearcoat = 1.f, cc.clearcoat_gloss = 0.3f;
    add("clearcoat 1 gloss 0.3", cc, false);
    PrincipledBsdf sh = principled(0.7f);
    sh.sheen = 1.f, sh.sheen_tint = 0.5f;
    add("sheen 1", sh, false);
    PrincipledBsdf an = principled(0.5f);
    an.anisotropic = 0.8f, an.metallic = 0.5f;
    add("anisotropic 0.8", an, false);
    PrincipledBsdf mix = principled(0.4f);
    mix.metallic = 0.3f, mix.spec_trans = 0.4f, mix.has_spec_trans = true, mix.clearcoat = 0.6f, mix.clearcoat_gloss = 0.2f;
    mix.sheen = 0.3f, mix.spec_tint = 0.4f, mix.anisotropic = 0.3f, mix.flatness = 0.5f;
    add("every lobe", mix, true);
    mix.main_specular_sampling_rate = 0.5f, mix.clearcoat_sampling_rate = 2.f, mix.diffuse_reflectance_sampling_rate = 0.3f;
    add("every lobe, sampling rates", mix, true);
    return cs;
}

}  // namespace

// The sampler's directions follow pdf() (which is also what the sample's weight divides by).
// The rough glass at cos 0.95 is where a pdf missing a refraction Jacobian or choosing reflection
// with a different Fresnel term than the sampler shows first.
TEST(PrincipledChi2, SamplingMatchesPdf) {
    const std::vector<Case> cases = chi2_cases();
    const double level = sidak_level(kAlpha, int(cases.size()));
    std::vector<ChiSquareResult> results(cases.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (int i = 0; i < int(cases.size()); ++i)
        results[size_t(i)] = chi_square_2d(setup_for(cases[size_t(i)].bsdf, cases[size_t(i)].wo, cases[size_t(i)].bsdf, 300 + uint64_t(i)));
    for (size_t i = 0; i < cases.size(); ++i) {
        const ChiSquareResult& r = results[i];
        EXPECT_GT(r.dof, 0) << cases[i].name;
        EXPECT_GE(r.p_value, level) << cases[i].name << ": " << r.describe();
        EXPECT_LE(r.pdf_integral, 1.0 + 2e-3) << cases[i].name;
        std::printf("  %-40s p %.3g  dof %d  integral %.5f  failed %llu\n", cases[i].name.c_str(), r.p_value, r.dof,
                    r.pdf_integral, (unsigned long long)r.failed_count);
    }
}

// The same test rejects a slightly wrong pdf: another eta for the glass, another roughness.
TEST(PrincipledChi2, RejectsWrongPdfs) {
    PrincipledBsdf glass = principled(0.3f);
    glass.spec_trans = 1.f, glass.has_spec_trans = true, glass.eta = 1.5f;
    PrincipledBsdf glass2 = glass;
    glass2.eta = 1.45f;
    PrincipledBsdf metal = principled(0.4f), metal2;
    metal.metallic = 1.f;
    metal2 = metal;
    metal2.roughness = 0.43f;
    PrincipledBsdf cc = principled(0.5f), cc2;
    cc.clearcoat = 1.f, cc.clearcoat_gloss = 0.3f;
    cc2 = cc;
    cc2.clearcoat_sampling_rate = 1.5f;  // the right shapes, the wrong mixture weights
    struct Bad {
        const char* name;
        Bsdf sampled, claimed;
        vec3 wo;
    };
    const std::vector<Bad> bad = {{"glass eta 1.5 vs 1.45", glass, glass2, dir(0.95f)},
                                  {"glass inside eta 1.5 vs 1.45", glass, glass2, -dir(0.9f)},
                                  {"metal roughness 0.4 vs 0.43", metal, metal2, dir(0.5f)},
                                  {"clearcoat rate 1 vs 1.5", cc, cc2, dir(0.7f)}};
    const double level = sidak_level(kAlpha, int(bad.size()));
    for (const Bad& b : bad) {
        const ChiSquareResult r = chi_square_2d(setup_for(b.sampled, b.wo, b.claimed, 7));
        EXPECT_LT(r.p_value, level) << b.name << " was not rejected: " << r.describe();
        std::printf("  rejected %-36s p = %.3g\n", b.name, r.p_value);
    }
}

// Weight = eval / pdf at the sampled direction (nothing is a delta lobe), finite and positive;
// BsdfSample::eta is the relative IOR crossed.
TEST(PrincipledConsistency, WeightIsEvalOverPdf) {
    PCG32 rng(11, 3);
    int checked = 0, refracted = 0;
    for (const Case& c : chi2_cases()) {
        for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
            for (int i = 0; i < 2000; ++i) {
                const float u1 = rng.next_float(), a = rng.next_float();
                auto bs = sample(c.bsdf, c.wo, u1, vec2(a, rng.next_float()), mode);
                if (!bs) continue;
                ASSERT_FALSE(bs->delta) << c.name;
                ASSERT_TRUE(all_finite(bs->f) && std::isfinite(bs->pdf) && bs->pdf > 0.f) << c.name;
                ASSERT_NEAR(glm::length(bs->wi), 1.f, 1e-4f) << c.name;
                const vec3 f = eval(c.bsdf, c.wo, bs->wi, mode);
                const float p = pdf(c.bsdf, c.wo, bs->wi, mode);
                for (int k = 0; k < 3; ++k) ASSERT_NEAR(bs->weight()[k], f[k] / p, 1e-4f * (1.f + f[k] / p)) << c.name;
                const PrincipledBsdf& pb = std::get<PrincipledBsdf>(c.bsdf);
                if (bs->wi.z * c.wo.z < 0.f) {
                    EXPECT_FLOAT_EQ(bs->eta, c.wo.z > 0.f ? pb.eta : 1.f / pb.eta) << c.name;
                    ++refracted;
                } else {
                    EXPECT_EQ(bs->eta, 1.f);
                }
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, 100000);
    EXPECT_GT(refracted, 5000);
}

// ---- against Mitsuba -----------------------------------------------------------------------

// eval (Radiance and Importance) and pdf of candela against Mitsuba's, for every parameter set and
// direction pair of the table: 1e-3 relative or 1e-5 absolute (float computations of the same
// formulas; the float rounding of the half vector at grazing angles is most of the difference).
TEST(PrincipledMitsuba, ValuesAgree) {
    const std::vector<TableEntry> table = read_table();
    ASSERT_EQ(table.size(), 10u);
    int n = 0, nonzero = 0, transmitted = 0;
    for (size_t k = 0; k < table.size(); ++k) {
        const TableEntry& e = table[k];
        Material m = load_material("values" + std::to_string(k), e.xml);
        ASSERT_TRUE(std::holds_alternative<PrincipledBsdf>(m.bsdf));
        for (const ValueRow& r : e.values) {
            const vec3 fr = eval(m.bsdf, r.wo, r.wi, TransportMode::Radiance);
            const vec3 fi = eval(m.bsdf, r.wo, r.wi, TransportMode::Importance);
            const float p = pdf(m.bsdf, r.wo, r.wi, TransportMode::Radiance);
            auto tol = [](float x) { return std::max(1e-3f * std::abs(x), 1e-5f); };
            const std::string where = e.xml + "\n wo " + std::to_string(r.wo.x) + " " + std::to_string(r.wo.y) + " " +
                                      std::to_string(r.wo.z) + " wi " + std::to_string(r.wi.x) + " " +
                                      std::to_string(r.wi.y) + " " + std::to_string(r.wi.z);
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(fr[c], r.f_radiance[c], tol(r.f_radiance[c])) << "radiance " << where;
                EXPECT_NEAR(fi[c], r.f_importance[c], tol(r.f_importance[c])) << "importance " << where;
            }
            EXPECT_NEAR(p, r.pdf, tol(r.pdf)) << "pdf " << where;
            nonzero += r.f_radiance.x > 0.f;
            transmitted += r.f_radiance.x > 0.f && r.wo.z * r.wi.z < 0.f;
            ++n;
        }
    }
    EXPECT_EQ(n, 500);
    EXPECT_GT(nonzero, 300);
    EXPECT_GT(transmitted, 20);
}

// The directional albedo (the mean sample weight) against Mitsuba's, sampled the same way by
// make_principled_values.py (2^21 samples): a z-test on the difference with both standard errors
// per parameter set, direction and channel, Sidak over all of them. Where Mitsuba exceeds 1 (the
// clearcoat without its 1 / (4 cos cos), spec_tint 1 at grazing, 1 / eta^2 from inside the glass)
// candela must too; this, not "<= 1", is the energy check.
TEST(PrincipledMitsuba, AlbedoAgrees) {
    const std::vector<TableEntry> table = read_table();
    int tests = 0;
    for (const TableEntry& e : table) tests += 3 * int(e.albedos.size());
    const double level = sidak_level(kAlpha, tests);
    struct Job {
        Bsdf bsdf;
        AlbedoRow row;
        std::string xml;
    };
    std::vector<Job> jobs;
    for (size_t k = 0; k < table.size(); ++k) {
        const Material m = load_material("albedo" + std::to_string(k), table[k].xml);
        for (const AlbedoRow& r : table[k].albedos) jobs.push_back({m.bsdf, r, table[k].xml});
    }
    std::vector<RunningStats> stats(jobs.size() * 3);
#pragma omp parallel for schedule(dynamic, 1)
    for (int j = 0; j < int(jobs.size()); ++j) {
        PCG32 rng(77, uint64_t(j));
        for (int i = 0; i < (1 << 20); ++i) {
            const float u1 = rng.next_float(), a = rng.next_float();
            auto bs = sample(jobs[size_t(j)].bsdf, jobs[size_t(j)].row.wo, u1, vec2(a, rng.next_float()));
            const vec3 w = bs ? bs->weight() : vec3(0.f);
            for (int c = 0; c < 3; ++c) stats[size_t(j) * 3 + size_t(c)].add(w[c]);
        }
    }
    int above_one = 0;
    for (size_t j = 0; j < jobs.size(); ++j) {
        const AlbedoRow& r = jobs[j].row;
        for (int c = 0; c < 3; ++c) {
            const RunningStats& s = stats[j * 3 + size_t(c)];
            const double se = std::sqrt(s.std_error() * s.std_error() + double(r.std_error[c]) * r.std_error[c]);
            const MeanTest t = z_test(s.mean(), se, r.albedo[c]);
            EXPECT_GE(t.p_value, level) << jobs[j].xml << " wo.z " << r.wo.z << " channel " << c << ": " << t.describe();
            above_one += r.albedo[c] > 1.f + 5.f * float(se);
        }
        std::printf("  wo.z %6.3f  candela %.4f %.4f %.4f  mitsuba %.4f %.4f %.4f\n", r.wo.z, stats[j * 3].mean(),
                    stats[j * 3 + 1].mean(), stats[j * 3 + 2].mean(), r.albedo.x, r.albedo.y, r.albedo.z);
    }
    EXPECT_GT(above_one, 0);  // the table does hold configurations beyond 1 (see above)
}

// ---- the XML rules -------------------------------------------------------------------------

TEST(PrincipledXml, Parameters) {
    const Material d = load_material("default", "<bsdf type=\"principled\"/>");
    const PrincipledBsdf& p = std::get<PrincipledBsdf>(d.bsdf);
    EXPECT_EQ(p.base_color, vec3(0.5f));
    EXPECT_FLOAT_EQ(p.roughness, 0.5f);
    EXPECT_NEAR(p.eta, 1.5f, 1e-6f);  // specular 0.5: 2 / (1 - sqrt(0.04)) - 1
    EXPECT_FALSE(p.has_spec_trans);
    EXPECT_FALSE(d.two_sided);
    const Material s = load_material("specular", "<bsdf type=\"principled\"><float name=\"specular\" value=\"0.2\"/>"
                                                 "<float name=\"spec_trans\" value=\"0.5\"/></bsdf>");
    EXPECT_NEAR(std::get<PrincipledBsdf>(s.bsdf).eta, 2.f / (1.f - std::sqrt(0.016f)) - 1.f, 1e-6f);
    EXPECT_TRUE(std::get<PrincipledBsdf>(s.bsdf).has_spec_trans);
    EXPECT_NEAR(PrincipledBsdf::specular_from_eta(PrincipledBsdf::eta_from_specular(0.2f)), 0.2f, 1e-5f);
    // A transmitting principled with eta 1 or specular 0: Mitsuba's 1.001 and 1e-3.
    EXPECT_FLOAT_EQ(std::get<PrincipledBsdf>(load_material("eta1", "<bsdf type=\"principled\"><float name=\"eta\" value=\"1\"/>"
                                                                   "<float name=\"spec_trans\" value=\"1\"/></bsdf>")
                                                 .bsdf)
                        .eta,
                    1.001f);
    EXPECT_FLOAT_EQ(std::get<PrincipledBsdf>(load_material("eta1r", "<bsdf type=\"principled\"><float name=\"eta\" value=\"1\"/></bsdf>").bsdf).eta,
                    1.f);
    EXPECT_NEAR(std::get<PrincipledBsdf>(load_material("spec0", "<bsdf type=\"principled\"><float name=\"specular\" value=\"0\"/>"
                                                                "<float name=\"spec_trans\" value=\"1\"/></bsdf>")
                                             .bsdf)
                    .eta,
                PrincipledBsdf::eta_from_specular(1e-3f), 1e-7f);
    // spec_trans given as 0 is Mitsuba's "no transmission lobe".
    EXPECT_FALSE(std::get<PrincipledBsdf>(load_material("st0", "<bsdf type=\"principled\"><float name=\"spec_trans\" value=\"0\"/></bsdf>").bsdf)
                     .has_spec_trans);
    // Refusals, one line with file:line each.
    EXPECT_NE(load_error("both", "<bsdf type=\"principled\">\n<float name=\"eta\" value=\"1.4\"/><float name=\"specular\" value=\"0.3\"/></bsdf>")
                  .find("either eta or specular"),
              std::string::npos);
    EXPECT_NE(load_error("range", "<bsdf type=\"principled\">\n<float name=\"metallic\" value=\"1.5\"/></bsdf>").find("metallic must be in [0, 1]"),
              std::string::npos);
    EXPECT_NE(load_error("typo", "<bsdf type=\"principled\">\n<float name=\"metalic\" value=\"0.5\"/></bsdf>").find("metalic"),
              std::string::npos);
    EXPECT_NE(load_error("spectex", "<bsdf type=\"principled\">\n<texture type=\"checkerboard\" name=\"specular\"/></bsdf>")
                  .find("not supported"),
              std::string::npos);
}

// Textured parameters: the base colour (a colour) and the float ones (their eval_1) per point.
TEST(PrincipledXml, Textures) {
    const Material m = load_material(
        "tex", "<bsdf type=\"principled\"><texture type=\"checkerboard\" name=\"base_color\">"
               "<rgb name=\"color0\" value=\"0.8 0.1 0.1\"/><rgb name=\"color1\" value=\"0.1 0.1 0.8\"/></texture>"
               "<texture type=\"checkerboard\" name=\"roughness\"><float name=\"color0\" value=\"0.2\"/>"
               "<float name=\"color1\" value=\"0.7\"/></texture>"
               "<texture type=\"checkerboard\" name=\"metallic\"><float name=\"color0\" value=\"0\"/>"
               "<float name=\"color1\" value=\"1\"/></texture>"
               "<texture type=\"checkerboard\" name=\"spec_trans\"><float name=\"color0\" value=\"0.3\"/>"
               "<float name=\"color1\" value=\"0.9\"/></texture></bsdf>");
    ASSERT_EQ(m.textures.size(), 4u);
    EXPECT_TRUE(std::get<PrincipledBsdf>(m.bsdf).has_spec_trans);  // a texture turns the lobe on
    Bsdf scratch;
    std::vector<PrincipledBsdf> seen;
    for (float u : {0.25f, 0.75f}) {
        TextureQuery q;
        q.uv = vec2(u, 0.25f);
        seen.push_back(std::get<PrincipledBsdf>(bsdf_at(m, q, scratch)));
    }
    EXPECT_NE(seen[0].base_color, seen[1].base_color);
    EXPECT_NE(seen[0].roughness, seen[1].roughness);
    EXPECT_NE(seen[0].metallic, seen[1].metallic);
    EXPECT_NE(seen[0].spec_trans, seen[1].spec_trans);
    for (const PrincipledBsdf& p : seen) {
        // A float texture's value is the luminance of its grey: equal to it up to rounding.
        EXPECT_TRUE(std::abs(p.roughness - 0.2f) < 1e-6f || std::abs(p.roughness - 0.7f) < 1e-6f) << p.roughness;
        EXPECT_TRUE(p.metallic == 0.f || std::abs(p.metallic - 1.f) < 1e-6f) << p.metallic;
    }
}

// ---- image ---------------------------------------------------------------------------------

// tests/data/scenes/principled.xml against the mean of 16 Mitsuba 3.9.1 renders of 1024 spp at
// 32 x 32 and the variance of that mean, made by
//   $PY tests/data/make_reference.py tests/data/scenes/principled.xml --res 32 --batches 16
//       --spp 1024 --out tests/data/principled32
// candela renders 16 batches of 128 spp; block z-test on 8 x 8 blocks. Control: the metal sphere
// with roughness 0.5 instead of 0.3 must fail.
namespace {

ImageEstimate render_principled(const std::vector<std::pair<std::string, std::string>>& defines) {
    auto d = defines;
    d.push_back({"res", "32"});
    auto built = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/principled.xml", d));
    return candela::test::render_batch_estimate(*built, built->params(), 16, 128);
}

}  // namespace

TEST(PrincipledMitsuba, RenderAgreement) {
    const ImageEstimate ref = ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/principled32");
    ASSERT_EQ(ref.width, 32);
    const BlockTestResult r = block_z_test(render_principled({}), ref, 8, 0.01);
    std::printf("  principled scene: %s\n", r.describe().c_str());
    EXPECT_TRUE(r.passed(0.01)) << r.describe();
}

TEST(PrincipledMitsuba, RenderAgreementDetectsWrongRoughness) {
    const ImageEstimate ref = ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/principled32");
    const BlockTestResult r = block_z_test(render_principled({{"metal_rough", "0.5"}}), ref, 8, 0.01);
    std::printf("  metal roughness 0.5 for 0.3: %s\n", r.describe().c_str());
    EXPECT_FALSE(r.passed(0.01)) << r.describe();
}
// The case a previous attempt failed (rough glass seen at cos 0.95), at 1M samples. Its refracted
// lobe is narrow (alpha 0.09, compressed by eta): on the 20 x 40 grid of test_bsdf_models.cpp the
// per-cell quadrature overestimates the pdf's mass (0.99945 against 0.99911 converged) and the
// chi-square rejects candela's principled and dielectric alike (p ~ 1e-10 for both): the grid,
// not the model. On 40 x 80 cells the quadrature has converged; the sampled directions follow the
// pdf, and the failed samples (refractions that leave above the horizon, reflections below it)
// are as many as the pdf's missing mass says.
TEST(PrincipledChi2, RoughGlassNearNormal) {
    PrincipledBsdf glass = principled(0.3f);
    glass.spec_trans = 1.f, glass.has_spec_trans = true, glass.eta = 1.5f;
    const std::vector<vec3> wos = {dir(0.95f), -dir(0.95f, 2.1f)};
    const double level = sidak_level(kAlpha, 2 * int(wos.size()));
    for (size_t k = 0; k < wos.size(); ++k) {
        ChiSquareSetup s = setup_for(glass, wos[k], glass, 900 + k);
        s.samples = 1000000;
        const ChiSquareResult r = chi_square_2d(s);
        EXPECT_GE(r.p_value, level) << r.describe();
        const double n = double(s.samples), miss = 1.0 - r.pdf_integral;
        const MeanTest t = z_test(double(r.failed_count) / n, std::sqrt(std::max(miss * (1.0 - miss), 1e-9) / n), miss, 1e-5);
        EXPECT_GE(t.p_value, level) << t.describe();
        std::printf("  wo.z %+.2f  p %.3g  dof %d  integral %.6f  failed fraction %.6f (p %.3g)\n", wos[k].z, r.p_value, r.dof,
                    r.pdf_integral, double(r.failed_count) / n, t.p_value);
    }
}
