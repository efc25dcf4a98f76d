// DiffuseBsdf: chi-square of sample() against pdf() at several incident directions, consistency of
// sample / eval / pdf, reciprocity, the albedo (white furnace) and one-sidedness.
#include <gtest/gtest.h>
#include "bsdf/bsdf.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;
const TransportMode kRad = TransportMode::Radiance;

vec3 direction(float cos_theta, float phi) {
    float s = safe_sqrt(1.f - cos_theta * cos_theta);
    return vec3(s * std::cos(phi), s * std::sin(phi), cos_theta);
}

// The incident directions tested: normal, oblique, grazing, and nearly tangent (wo.z = 1e-3).
const std::vector<vec3> kWos = {direction(1.f, 0.f), direction(0.8f, 0.3f), direction(0.3f, 2.f), direction(0.05f, 4.f),
                                direction(1e-3f, 1.f)};

// The chi-square setup for a BSDF at one wo, on the whole sphere so that samples below the
// horizon are caught (the grid's cos theta = 0 line is a cell boundary: res_x is even).
ChiSquareSetup bsdf_setup(const Bsdf& b, vec3 wo, uint64_t seed) {
    ChiSquareSetup s;
    s.domain = sphere_domain();
    s.res_x = 20;
    s.res_y = 40;
    s.seed = seed;
    s.sample = [b, wo](PCG32& r) {
        float u1 = r.next_float();
        float ux = r.next_float();
        vec2 u2(ux, r.next_float());
        DomainSample d;
        std::optional<BsdfSample> bs = sample(b, wo, u1, u2, kRad);
        if (!bs) return d;
        d.kind = bs->delta ? DomainSample::Discrete : DomainSample::Smooth;
        d.p = dvec3(bs->wi);
        return d;
    };
    s.pdf = [b, wo](const dvec3& wi) { return double(pdf(b, wo, vec3(wi), kRad)); };
    return s;
}

}  // namespace

TEST(DiffuseBsdf, ChiSquareAtSeveralIncidentDirections) {
    Bsdf b = DiffuseBsdf{vec3(0.7f, 0.5f, 0.2f)};
    const double level = sidak_level(kAlpha, int(kWos.size()));
    uint64_t seed = 100;
    for (vec3 wo : kWos) {
        ChiSquareResult r = chi_square_2d(bsdf_setup(b, wo, seed++));
        EXPECT_GE(r.p_value, level) << "wo.z = " << wo.z << ": " << r.describe();
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-6);
        std::printf("  wo.z = %-6g %s\n", wo.z, r.describe().c_str());
    }
}

// The same test rejects a pdf that disagrees with the sampler: the uniform hemisphere pdf, and a
// normalised cos^1.1 lobe that is only slightly narrower than the cosine.
TEST(DiffuseBsdf, ChiSquareRejectsAWrongPdf) {
    Bsdf b = DiffuseBsdf{vec3(0.5f)};
    ChiSquareSetup s = bsdf_setup(b, kWos[1], 5);
    s.pdf = [](const dvec3& wi) { return wi.z > 0 ? 1.0 / (2.0 * M_PI) : 0.0; };
    ChiSquareResult uniform = chi_square_2d(s);
    s.pdf = [](const dvec3& wi) { return wi.z > 0 ? 2.1 / (2.0 * M_PI) * std::pow(wi.z, 1.1) : 0.0; };
    ChiSquareResult narrow = chi_square_2d(s);
    const double level = sidak_level(kAlpha, 2);
    EXPECT_LT(uniform.p_value, level) << uniform.describe();
    EXPECT_LT(narrow.p_value, level) << narrow.describe();
    std::printf("  uniform pdf p = %g, cos^1.1 pdf p = %g\n", uniform.p_value, narrow.p_value);
}

TEST(DiffuseBsdf, SampleAgreesWithEvalAndPdf) {
    DiffuseBsdf d{vec3(0.7f, 0.5f, 0.2f)};
    Bsdf b = d;
    PCG32 rng(1u, 1u);
    for (vec3 wo : kWos)
        for (int i = 0; i < 10000; ++i) {
            float u1 = rng.next_float();
            float ux = rng.next_float();
            std::optional<BsdfSample> s = sample(b, wo, u1, vec2(ux, rng.next_float()), kRad);
            ASSERT_TRUE(s.has_value());
            ASSERT_FALSE(s->delta);
            ASSERT_GT(s->wi.z, 0.f);
            ASSERT_NEAR(glm::length(s->wi), 1.f, 1e-5f);
            // pdf() and eval() for the returned direction give what sample() returned.
            float p = pdf(b, wo, s->wi, kRad);
            vec3 f = eval(b, wo, s->wi, kRad);
            ASSERT_NEAR(s->pdf, p, 1e-6f * p);
            for (int c = 0; c < 3; ++c) ASSERT_NEAR(s->f[c], f[c], 1e-6f * f[c]);
            // The weight f cos / pdf of cosine sampling is exactly the albedo.
            vec3 w = s->weight();
            for (int c = 0; c < 3; ++c) ASSERT_NEAR(w[c], d.albedo[c], 1e-5f * d.albedo[c]);
        }
}

TEST(DiffuseBsdf, Reciprocity) {
    // eval includes |cos wi|; f itself must be symmetric: eval(wo,wi)/|wi.z| == eval(wi,wo)/|wo.z|.
    Bsdf b = DiffuseBsdf{vec3(0.7f, 0.5f, 0.2f)};
    PCG32 rng(2u, 3u);
    for (int i = 0; i < 10000; ++i) {
        float a = rng.next_float(), c = rng.next_float(), e = rng.next_float(), g = rng.next_float();
        vec3 wo = direction(std::max(a, 1e-3f), 2.f * kPi * c), wi = direction(std::max(e, 1e-3f), 2.f * kPi * g);
        vec3 f1 = eval(b, wo, wi, kRad) / std::abs(wi.z), f2 = eval(b, wi, wo, kRad) / std::abs(wo.z);
        for (int k = 0; k < 3; ++k) ASSERT_NEAR(f1[k], f2[k], 1e-5f * f1[k]);
    }
}

// White furnace: the hemispherical-directional reflectance int f cos dwi equals the albedo.
// Estimated with directions drawn uniformly on the hemisphere (not the BSDF's own sampler, whose
// weight is constant), as E[eval / pdf_uniform]; z-test per wo and channel, Sidak-corrected. A
// wrong albedo (2% too high) must be rejected by the same statistics.
TEST(DiffuseBsdf, AlbedoByMonteCarlo) {
    const vec3 albedo(0.7f, 0.5f, 0.2f);
    Bsdf b = DiffuseBsdf{albedo};
    const int tests = int(kWos.size()) * 3;
    const double level = sidak_level(kAlpha, 2 * tests);
    PCG32 rng(4u, 5u);
    for (vec3 wo : kWos) {
        RunningStats s[3];
        for (int i = 0; i < 200000; ++i) {
            float ux = rng.next_float();
            vec3 wi = square_to_uniform_hemisphere(vec2(ux, rng.next_float()));
            vec3 v = eval(b, wo, wi, kRad) / square_to_uniform_hemisphere_pdf(wi);
            for (int c = 0; c < 3; ++c) s[c].add(v[c]);
        }
        for (int c = 0; c < 3; ++c) {
            MeanTest t = z_test(s[c], albedo[c]);
            EXPECT_GE(t.p_value, level) << "wo.z = " << wo.z << " channel " << c << ": " << t.describe();
            EXPECT_LT(t.std_error, 0.01 * albedo[c]) << "too noisy to detect a 1% bias";
            MeanTest wrong = z_test(s[c], 1.02 * albedo[c]);
            EXPECT_LT(wrong.p_value, level) << "a 2% albedo error went undetected: " << wrong.describe();
        }
        if (wo.z == kWos[0].z)
            std::printf("  wo.z = 1: %s\n", z_test(s[0], albedo[0]).describe().c_str());
    }
}

TEST(DiffuseBsdf, OneSided) {
    Bsdf b = DiffuseBsdf{vec3(0.5f)};
    const vec3 below = direction(-0.5f, 1.f), above = direction(0.5f, 2.f);
    for (float u : {0.f, 0.3f, 0.9f}) EXPECT_FALSE(sample(b, below, 0.5f, vec2(u, 0.5f), kRad).has_value());
    EXPECT_FALSE(sample(b, vec3(1.f, 0.f, 0.f), 0.5f, vec2(0.5f), kRad).has_value());  // wo.z = 0
    EXPECT_TRUE(is_black(eval(b, below, above, kRad)));
    EXPECT_TRUE(is_black(eval(b, above, below, kRad)));
    EXPECT_TRUE(is_black(eval(b, below, below, kRad)));
    EXPECT_EQ(pdf(b, below, above, kRad), 0.f);
    EXPECT_EQ(pdf(b, above, below, kRad), 0.f);
    EXPECT_GT(pdf(b, above, above, kRad), 0.f);
}
