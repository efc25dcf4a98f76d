// Chi-square tests of every warp in sampling/warp.h against its pdf, checks that the pdfs are
// normalised, and checks that the chi-square machinery (tests/support/stats) rejects wrong pdfs
// and wrong samplers. Also the special functions the p-values rest on.
#include <gtest/gtest.h>
#include <gtest/gtest-spi.h>
#include <cmath>
#include "sampling/warp.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;  // family-wise significance of each TEST below

vec2 next_2d(PCG32& rng) {
    float a = rng.next_float();
    return vec2(a, rng.next_float());
}
DomainSample smooth(vec3 p) {
    DomainSample s;
    s.kind = DomainSample::Smooth;
    s.p = dvec3(p);
    return s;
}
DomainSample smooth2(vec2 p) { return smooth(vec3(p, 0.f)); }

// The triangle used for the triangle warp: arbitrary, not axis-aligned, not right-angled.
const vec2 kT0(0.1f, 0.2f), kT1(1.3f, 0.45f), kT2(0.55f, 1.1f);
double triangle_area() { return 0.5 * std::abs(double(kT1.x - kT0.x) * (kT2.y - kT0.y) - double(kT1.y - kT0.y) * (kT2.x - kT0.x)); }
vec2 triangle_point(vec2 u) {
    vec2 b = square_to_uniform_triangle(u);
    return b.x * kT0 + b.y * kT1 + (1.f - b.x - b.y) * kT2;
}

struct WarpCase {
    const char* name;
    Domain domain;
    std::function<DomainSample(PCG32&)> sample;
    std::function<double(const dvec3&)> pdf;
};

std::vector<WarpCase> warp_cases() {
    return {
        {"disk concentric", disk_domain(), [](PCG32& r) { return smooth2(square_to_uniform_disk_concentric(next_2d(r))); },
         [](const dvec3& p) { return double(square_to_uniform_disk_pdf(vec2(p))); }},
        {"cosine hemisphere", hemisphere_domain(), [](PCG32& r) { return smooth(square_to_cosine_hemisphere(next_2d(r))); },
         [](const dvec3& p) { return double(square_to_cosine_hemisphere_pdf(vec3(p))); }},
        // The same on the whole sphere: nothing may land below the horizon.
        {"cosine hemisphere (sphere grid)", sphere_domain(),
         [](PCG32& r) { return smooth(square_to_cosine_hemisphere(next_2d(r))); },
         [](const dvec3& p) { return double(square_to_cosine_hemisphere_pdf(vec3(p))); }},
        {"uniform sphere", sphere_domain(), [](PCG32& r) { return smooth(square_to_uniform_sphere(next_2d(r))); },
         [](const dvec3& p) { return double(square_to_uniform_sphere_pdf(vec3(p))); }},
        {"uniform hemisphere", hemisphere_domain(),
         [](PCG32& r) { return smooth(square_to_uniform_hemisphere(next_2d(r))); },
         [](const dvec3& p) { return double(square_to_uniform_hemisphere_pdf(vec3(p))); }},
        {"uniform triangle", triangle_domain(dvec2(kT0), dvec2(kT1), dvec2(kT2)),
         [](PCG32& r) { return smooth2(triangle_point(next_2d(r))); },
         [](const dvec3&) { return 1.0 / triangle_area(); }},
    };
}

ChiSquareResult run(const Domain& d, std::function<DomainSample(PCG32&)> sample, std::function<double(const dvec3&)> pdf,
                    uint64_t seed = 7) {
    ChiSquareSetup s;
    s.domain = d;
    s.sample = std::move(sample);
    s.pdf = std::move(pdf);
    s.seed = seed;
    return chi_square_2d(s);
}

}  // namespace

// ---- the special functions ---------------------------------------------------------------------

TEST(Stats, IncompleteGammaMatchesClosedForms) {
    for (double x : {1e-3, 0.1, 0.5, 1.0, 2.0, 5.0, 20.0, 60.0}) {
        EXPECT_NEAR(gamma_q(1.0, x), std::exp(-x), 1e-13 * std::max(1.0, std::exp(-x))) << x;  // Q(1,x) = e^-x
        EXPECT_NEAR(gamma_q(0.5, x), std::erfc(std::sqrt(x)), 1e-13) << x;                     // Q(1/2,x) = erfc
        EXPECT_NEAR(gamma_p(3.0, x) + gamma_q(3.0, x), 1.0, 1e-14) << x;
        // Q(2, x) = (1 + x) e^-x; checks the continued fraction's relative accuracy in the far tail.
        EXPECT_NEAR(gamma_q(2.0, x) / ((1.0 + x) * std::exp(-x)), 1.0, 1e-12) << x;
    }
}

TEST(Stats, ChiSquareAndStudentQuantiles) {
    // Table values (Abramowitz & Stegun 26.4, 26.7): critical points and their tail probabilities.
    EXPECT_NEAR(chi_square_sf(3.841459, 1), 0.05, 1e-7);
    EXPECT_NEAR(chi_square_sf(23.209251, 10), 0.01, 1e-7);
    EXPECT_NEAR(chi_square_sf(124.342113, 100), 0.05, 1e-7);
    EXPECT_NEAR(chi_square_sf(2.0 * 3.0, 2), std::exp(-3.0), 1e-14);  // dof 2 is exponential
    EXPECT_NEAR(student_t_two_sided_p(2.228139, 10), 0.05, 1e-6);
    EXPECT_NEAR(student_t_two_sided_p(63.656741, 1), 0.01, 1e-7);
    EXPECT_NEAR(normal_two_sided_p(1.959964), 0.05, 1e-6);
    EXPECT_NEAR(beta_inc(2.5, 2.5, 0.5), 0.5, 1e-14);
    EXPECT_NEAR(beta_inc(2.0, 3.0, 0.3), 0.3483, 1e-12);  // 1 - sum_{k<2} C(4,k) .3^k .7^(4-k)
}

TEST(Stats, SidakCorrection) {
    EXPECT_NEAR(sidak_level(0.05, 1), 0.05, 1e-15);
    EXPECT_NEAR(sidak_level(0.01, 10), 1.0 - std::pow(0.99, 0.1), 1e-15);
    for (int m : {1, 5, 100, 10000}) EXPECT_NEAR(sidak_adjust(sidak_level(0.01, m), m), 0.01, 1e-12) << m;
}

// Under the null hypothesis p-values are uniform: over 200 fair multinomial histograms the
// fraction of p < 0.1 is about 0.1 (binomial sd 0.021). Checks the pooling and degrees of freedom.
TEST(Stats, ChiSquareIsCalibratedUnderTheNull) {
    PCG32 rng(3, 5);
    const std::vector<double> probs = {0.3, 0.2, 0.15, 0.1, 0.1, 0.08, 0.05, 0.01, 0.005, 0.005};
    int below = 0;
    const int runs = 200, n = 2000;
    for (int r = 0; r < runs; ++r) {
        std::vector<double> obs(probs.size(), 0.0), expct(probs.size());
        for (int i = 0; i < n; ++i) {
            double u = rng.next_float(), c = 0;
            size_t k = 0;
            while (k + 1 < probs.size() && u >= c + probs[k]) c += probs[k++];
            obs[k] += 1;
        }
        for (size_t k = 0; k < probs.size(); ++k) expct[k] = n * probs[k];
        if (chi_square_counts(obs, expct).p_value < 0.1) ++below;
    }
    // 0.1 +- 4.5 sd: a broken dof or pooling moves it far outside (fixed seed: deterministic).
    EXPECT_GT(below, 1);
    EXPECT_LT(below, 40);
}

// A chi-square test left with no degree of freedom (everything pooled into one cell, or as many
// constraints as cells) tests nothing: it must fail the test that ran it and give a p that passes
// no comparison. It used to return p = 1, which passed silently.
TEST(Stats, ChiSquareWithoutDegreesOfFreedomFails) {
    ChiSquareResult r;
    // Four cells expecting 1 each (min_expected 5): all pooled into one cell, dof 0.
    EXPECT_NONFATAL_FAILURE(r = chi_square_counts({4, 0, 0, 0}, {1, 1, 1, 1}), "0 degrees of freedom");
    EXPECT_EQ(r.dof, 0);
    EXPECT_TRUE(std::isnan(r.p_value)) << r.describe();
    EXPECT_FALSE(r.p_value >= 0.01);
    EXPECT_FALSE(r.p_value < 0.01);
    // Two cells, one constraint besides the total: dof 0 as well.
    EXPECT_NONFATAL_FAILURE(r = chi_square_counts({50, 50}, {50, 50}, 5.0, 1), "0 degrees of freedom");
    EXPECT_TRUE(std::isnan(chi_square_sf(1.0, 0)));
    // Control: the same counts on enough cells are a valid test.
    r = chi_square_counts({50, 50}, {50, 50});
    EXPECT_EQ(r.dof, 1);
    EXPECT_NEAR(r.p_value, 1.0, 1e-12);
}

// ---- the warps ------------------------------------------------------------------------------------

TEST(Warp, ChiSquareAgainstPdf) {
    auto cases = warp_cases();
    const double level = sidak_level(kAlpha, int(cases.size()));
    for (const WarpCase& c : cases) {
        ChiSquareResult r = run(c.domain, c.sample, c.pdf);
        EXPECT_GE(r.p_value, level) << c.name << ": " << r.describe();
        EXPECT_EQ(r.outside_count, 0u) << c.name;
        EXPECT_EQ(r.failed_count, 0u) << c.name;
        std::printf("  %-32s %s\n", c.name, r.describe().c_str());
    }
}

TEST(Warp, PdfsIntegrateToOne) {
    for (const WarpCase& c : warp_cases()) {
        double integral = integrate_over_domain(c.domain, c.pdf, 40, 80, 9);
        EXPECT_NEAR(integral, 1.0, 1e-6) << c.name;
    }
    // The hemisphere pdfs vanish below the horizon, the disk pdf outside the disk.
    EXPECT_EQ(square_to_cosine_hemisphere_pdf(vec3(0.6f, 0.f, -0.8f)), 0.f);
    EXPECT_EQ(square_to_uniform_hemisphere_pdf(vec3(0.6f, 0.f, -0.8f)), 0.f);
    EXPECT_EQ(square_to_uniform_disk_pdf(vec2(0.8f, 0.7f)), 0.f);
}

TEST(Warp, OutputsStayInTheirDomains) {
    PCG32 rng(11, 13);
    // The corners of the square, where the concentric map's branches meet, plus random points.
    std::vector<vec2> us = {vec2(0.f), vec2(0.5f), vec2(0.f, 0x1.fffffep-1f), vec2(0x1.fffffep-1f), vec2(0.5f, 0.f)};
    for (int i = 0; i < 100000; ++i) us.push_back(next_2d(rng));
    for (vec2 u : us) {
        vec2 d = square_to_uniform_disk_concentric(u);
        ASSERT_LE(glm::dot(d, d), 1.f + 1e-6f);
        vec3 c = square_to_cosine_hemisphere(u);
        ASSERT_GE(c.z, 0.f);
        ASSERT_NEAR(glm::length(c), 1.f, 1e-5f);
        ASSERT_NEAR(glm::length(square_to_uniform_sphere(u)), 1.f, 1e-5f);
        vec3 h = square_to_uniform_hemisphere(u);
        ASSERT_GE(h.z, 0.f);
        vec2 b = square_to_uniform_triangle(u);
        ASSERT_GE(b.x, 0.f);
        ASSERT_GE(b.y, 0.f);
        ASSERT_LE(b.x + b.y, 1.f);
    }
}

// The largest error of f against the exact g over [-pi/4, pi/4], in units of the float spacing at
// the exact value.
template <class F, class G>
double max_ulp_error(F f, G g) {
    double worst = 0;
    const int n = 1 << 20;
    for (int i = 0; i <= n; ++i) {
        const float a = float((double(i) / n * 2.0 - 1.0) * (kPi / 4.0));
        const double exact = g(double(a));
        const float e = float(std::abs(exact));
        const double ulp = double(std::nextafter(e, kInfinity)) - double(e);
        worst = std::max(worst, std::abs(double(f(a)) - exact) / ulp);
    }
    return worst;
}

TEST(Warp, QuarterSinCosWithinTwoUlp) {
    // The concentric map's sin and cos (no libm) over the whole range it uses, on 2^20 + 1 angles.
    const double es = max_ulp_error([](float a) { float s, c; sincos_quarter(a, s, c); return s; },
                                    [](double a) { return std::sin(a); });
    const double ec = max_ulp_error([](float a) { float s, c; sincos_quarter(a, s, c); return c; },
                                    [](double a) { return std::cos(a); });
    std::printf("  sin within %.2f ulp, cos within %.2f ulp\n", es, ec);
    EXPECT_LE(es, 2.0);
    EXPECT_LE(ec, 2.0);
    // The measure can fail: sin without its last term is off by far more.
    const double crude = max_ulp_error([](float a) { return a - a * a * a * (1.f / 6.f) + a * a * a * a * a * (1.f / 120.f); },
                                       [](double a) { return std::sin(a); });
    EXPECT_GT(crude, 2.0);
}

TEST(Warp, BranchlessFormsMatchTheBranchingOnes) {
    // The triangle warp chooses its half without a branch; it must give the branching form's bits.
    // The concentric map's wedge likewise (its angle then goes to sincos_quarter, tested above).
    PCG32 rng(3, 7);
    std::vector<vec2> us = {vec2(0.f), vec2(0.5f), vec2(0.25f), vec2(0.f, 0x1.fffffep-1f), vec2(0x1.fffffep-1f, 0.f)};
    for (int i = 0; i < 200000; ++i) us.push_back(next_2d(rng));
    for (vec2 u : us) {
        float b0, b1;
        if (u.x < u.y) {
            b0 = u.x / 2.f;
            b1 = u.y - b0;
        } else {
            b1 = u.y / 2.f;
            b0 = u.x - b1;
        }
        const vec2 b = square_to_uniform_triangle(u);
        ASSERT_EQ(float_to_bits(b.x), float_to_bits(b0)) << u.x << " " << u.y;
        ASSERT_EQ(float_to_bits(b.y), float_to_bits(b1)) << u.x << " " << u.y;
        // The concentric map against its angle written out with libm: the same point to float
        // rounding (r cos theta, r sin theta).
        const vec2 o = 2.f * u - vec2(1.f);
        if (o.x == 0.f && o.y == 0.f) continue;
        const bool xm = std::abs(o.x) > std::abs(o.y);
        const double r = xm ? o.x : o.y;
        const double theta = xm ? kPi / 4.0 * (double(o.y) / o.x) : kPi / 2.0 - kPi / 4.0 * (double(o.x) / o.y);
        const vec2 d = square_to_uniform_disk_concentric(u);
        ASSERT_NEAR(d.x, r * std::cos(theta), 4e-7) << u.x << " " << u.y;
        ASSERT_NEAR(d.y, r * std::sin(theta), 4e-7) << u.x << " " << u.y;
    }
}

TEST(Warp, MaxDimensionAndAbs3) {
    // max_dimension is branchless; the branching form's answer on every order of three values,
    // with ties, signed zeros and a NaN.
    const float vals[] = {-2.f, -0.f, 0.f, 1.f, 3.f, std::nanf("")};
    for (float x : vals)
        for (float y : vals)
            for (float z : vals) {
                const int want = (x > y) ? (x > z ? 0 : 2) : (y > z ? 1 : 2);
                ASSERT_EQ(max_dimension(vec3(x, y, z)), want) << x << " " << y << " " << z;
                const vec3 a = abs3(vec3(x, y, z));
                ASSERT_FALSE(std::signbit(a.x) || std::signbit(a.y) || std::signbit(a.z));
            }
}

// ---- the test must be able to fail --------------------------------------------------------------

TEST(Warp, ChiSquareRejectsWrongPdfsAndSamplers) {
    struct Bad {
        const char* name;
        Domain domain;
        std::function<DomainSample(PCG32&)> sample;
        std::function<double(const dvec3&)> pdf;
    };
    std::vector<Bad> bad = {
        // Cosine samples judged by the uniform hemisphere pdf.
        {"cosine vs uniform pdf", hemisphere_domain(), [](PCG32& r) { return smooth(square_to_cosine_hemisphere(next_2d(r))); },
         [](const dvec3&) { return 1.0 / (2.0 * M_PI); }},
        // A pdf that is 5% off in a normalised way (its integral is still 1).
        {"sphere pdf (1 + 0.05 z)", sphere_domain(), [](PCG32& r) { return smooth(square_to_uniform_sphere(next_2d(r))); },
         [](const dvec3& p) { return (1.0 + 0.05 * p.z) / (4.0 * M_PI); }},
        // A sampler that is slightly wrong: its u.x is bent by a power of 1.03.
        {"disk sampler u^1.03", disk_domain(),
         [](PCG32& r) {
             vec2 u = next_2d(r);
             u.x = std::pow(u.x, 1.03f);
             return smooth2(square_to_uniform_disk_concentric(u));
         },
         [](const dvec3& p) { return double(square_to_uniform_disk_pdf(vec2(p))); }},
        // The classic mistake: barycentrics (u, (1-u) v) crowd towards one vertex.
        {"naive triangle sampler", triangle_domain(dvec2(kT0), dvec2(kT1), dvec2(kT2)),
         [](PCG32& r) {
             vec2 u = next_2d(r);
             float b0 = u.x, b1 = (1.f - u.x) * u.y;
             return smooth2(b0 * kT0 + b1 * kT1 + (1.f - b0 - b1) * kT2);
         },
         [](const dvec3&) { return 1.0 / triangle_area(); }},
        // Uniform hemisphere with phi covering only [0, 1.9 pi): a sampler that misses a wedge.
        {"hemisphere missing a wedge", hemisphere_domain(),
         [](PCG32& r) {
             vec2 u = next_2d(r);
             u.y *= 0.95f;
             return smooth(square_to_uniform_hemisphere(u));
         },
         [](const dvec3& p) { return double(square_to_uniform_hemisphere_pdf(vec3(p))); }},
        // Samples below the horizon where the pdf says there are none.
        {"sphere samples on the hemisphere", hemisphere_domain(),
         [](PCG32& r) { return smooth(square_to_uniform_sphere(next_2d(r))); },
         [](const dvec3& p) { return double(square_to_uniform_hemisphere_pdf(vec3(p))); }},
    };
    const double level = sidak_level(kAlpha, int(bad.size()));
    for (const Bad& b : bad) {
        ChiSquareResult r = run(b.domain, b.sample, b.pdf);
        EXPECT_LT(r.p_value, level) << b.name << " was not rejected: " << r.describe();
        std::printf("  rejected %-32s p = %g\n", b.name, r.p_value);
    }
}

// Delta components and failed samples, as a dielectric or a BSDF with energy loss will need:
// with probability 0.3 a "specular" discrete sample, with 0.1 no sample, else cosine-weighted.
TEST(Warp, ChiSquareWithDiscreteComponentsAndFailures) {
    auto mixture = [](PCG32& r) {
        float u = r.next_float();
        vec2 u2 = next_2d(r);
        DomainSample s;
        if (u < 0.3f) {
            s.kind = DomainSample::Discrete;
            s.component = 0;
        } else if (u < 0.4f) {
            s.kind = DomainSample::Failed;
        } else {
            s = smooth(square_to_cosine_hemisphere(u2));
        }
        return s;
    };
    auto pdf = [](const dvec3& p) { return 0.6 * double(square_to_cosine_hemisphere_pdf(vec3(p))); };
    ChiSquareSetup s;
    s.domain = sphere_domain();
    s.sample = mixture;
    s.pdf = pdf;
    s.discrete_probabilities = {0.3};
    ChiSquareResult good = chi_square_2d(s);
    const double level = sidak_level(kAlpha, 3);
    EXPECT_GE(good.p_value, level) << good.describe();
    ASSERT_EQ(good.discrete_count.size(), 1u);
    EXPECT_NEAR(good.discrete_expected[0], 3e5, 1e-6);
    EXPECT_NEAR(good.failed_expected, 1e5, 1.0);  // from 1 - 0.6 - 0.3, with the integration error
    std::printf("  mixture: %s\n", good.describe().c_str());

    // A wrong discrete probability is rejected...
    s.discrete_probabilities = {0.29};
    ChiSquareResult wrong_delta = chi_square_2d(s);
    EXPECT_LT(wrong_delta.p_value, level) << wrong_delta.describe();
    // ... and so is a pdf that does not account for the failures (it claims 0.7 of the mass).
    s.discrete_probabilities = {0.3};
    s.pdf = [](const dvec3& p) { return 0.7 * double(square_to_cosine_hemisphere_pdf(vec3(p))); };
    ChiSquareResult wrong_smooth = chi_square_2d(s);
    EXPECT_LT(wrong_smooth.p_value, level) << wrong_smooth.describe();
}
