// LightSet: the solid angle of emitters estimated from light samples against the analytic value,
// pdf_li against the pdf of sample_li, one-sidedness, and selection proportional to power.
#include <gtest/gtest.h>
#include <memory>
#include "accel/accel.h"
#include "scene/scene.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;

struct LightSpec {
    std::vector<vec3> positions;
    std::vector<uvec3> triangles;
    vec3 radiance;
};

// A scene holding only emitters (and one diffuse material).
std::shared_ptr<const Scene> make_scene(const std::vector<LightSpec>& lights) {
    auto sc = std::make_unique<SceneDescription>();
    sc->source = "<test_light>";
    sc->materials.push_back(Material{"white", DiffuseBsdf{vec3(0.5f)}, false});
    for (size_t i = 0; i < lights.size(); ++i) {
        sc->emitters.push_back(AreaEmitter{lights[i].radiance});
        sc->add_shape("light" + std::to_string(i), lights[i].positions, {}, lights[i].triangles, 0, int32_t(i));
    }
    return build_scene(std::move(*sc), "brute");
}

// Solid angle of triangle (a, b, c) seen from p (Van Oosterom and Strackee 1983):
// tan(omega / 2) = |A . (B x C)| / (abc + (A.B) c + (A.C) b + (B.C) a), with A = a - p etc.
double triangle_solid_angle(dvec3 p, dvec3 a, dvec3 b, dvec3 c) {
    dvec3 A = a - p, B = b - p, C = c - p;
    double la = glm::length(A), lb = glm::length(B), lc = glm::length(C);
    double num = std::abs(glm::dot(A, glm::cross(B, C)));
    double den = la * lb * lc + glm::dot(A, B) * lc + glm::dot(A, C) * lb + glm::dot(B, C) * la;
    return 2.0 * std::atan2(num, den);  // atan2: the denominator is negative beyond a hemisphere
}

double solid_angle(dvec3 p, const LightSpec& l) {
    double sum = 0;
    for (const uvec3& t : l.triangles)
        sum += triangle_solid_angle(p, dvec3(l.positions[t.x]), dvec3(l.positions[t.y]), dvec3(l.positions[t.z]));
    return sum;
}

// Facing -z (towards the reference points below it): the winding makes cross(p1-p0, p2-p0) = -z.
const LightSpec kTriangle{{vec3(-0.5f, -0.5f, 2.f), vec3(0.f, 0.8f, 2.f), vec3(0.7f, -0.3f, 2.f)}, {uvec3(0, 1, 2)}, vec3(1.f)};
// A unit square in the plane x = 3 facing -x, as two triangles.
const LightSpec kQuad{{vec3(3.f, -0.5f, -0.5f), vec3(3.f, 0.5f, -0.5f), vec3(3.f, 0.5f, 0.5f), vec3(3.f, -0.5f, 0.5f)},
                      {uvec3(0, 2, 1), uvec3(0, 3, 2)},
                      vec3(2.f, 1.f, 0.5f)};

// E[1 / pdf] over light samples, where a failed sample counts 0: the total solid angle of the
// emitters' front sides seen from p.
RunningStats inverse_pdf(const Scene& sc, vec3 p, int n, uint64_t seed) {
    PCG32 rng(seed, 1u);
    RunningStats s;
    for (int i = 0; i < n; ++i) {
        float u1 = rng.next_float(), ux = rng.next_float();
        LightSample ls;
        bool ok = sc.lights.sample_li(p, u1, vec2(ux, rng.next_float()), ls);
        s.add(ok ? 1.0 / double(ls.pdf) : 0.0);
    }
    return s;
}

}  // namespace

TEST(LightSet, BuildsFromTheScene) {
    auto sc = make_scene({kTriangle, kQuad});
    EXPECT_EQ(sc->lights.triangle_count(), 3u);
    EXPECT_EQ(sc->lights.emitter_of(0), 0);
    EXPECT_EQ(sc->lights.emitter_of(1), 1);
    EXPECT_EQ(sc->lights.emitter_of(2), 1);
}

TEST(LightSet, SolidAngleFromInversePdf) {
    struct Case {
        const char* name;
        std::vector<LightSpec> lights;
        vec3 p;
        double omega;
    };
    std::vector<Case> cases = {
        {"triangle, below", {kTriangle}, vec3(0.f), 0},
        {"triangle, oblique", {kTriangle}, vec3(2.f, 1.f, 1.5f), 0},
        {"triangle, close", {kTriangle}, vec3(0.1f, 0.f, 1.7f), 0},
        {"quad", {kQuad}, vec3(0.5f, 0.2f, -0.3f), 0},
        {"triangle + quad", {kTriangle, kQuad}, vec3(0.f), 0},
        // Behind the quad (x > 3) but below the triangle: only the triangle counts.
        {"quad from behind", {kTriangle, kQuad}, vec3(4.f, 0.f, 0.f), 0},
    };
    for (Case& c : cases) {
        dvec3 p(c.p);
        c.omega = 0;
        for (const LightSpec& l : c.lights) {
            // A one-sided light counts only when p is on its front side.
            const uvec3 t = l.triangles[0];
            dvec3 a(l.positions[t.x]), b(l.positions[t.y]), e(l.positions[t.z]);
            if (glm::dot(p - a, glm::cross(b - a, e - a)) > 0) c.omega += solid_angle(p, l);
        }
    }
    const double level = sidak_level(kAlpha, 2 * int(cases.size()));
    uint64_t seed = 1;
    for (const Case& c : cases) {
        auto sc = make_scene(c.lights);
        RunningStats s = inverse_pdf(*sc, c.p, 400000, seed++);
        MeanTest t = z_test(s, c.omega);
        EXPECT_GE(t.p_value, level) << c.name << ": " << t.describe();
        EXPECT_LT(t.std_error, 0.005 * c.omega) << c.name << ": too noisy to see a 1.5% error";
        // The same statistics reject a solid angle 1.5% off.
        EXPECT_LT(z_test(s, 1.015 * c.omega).p_value, level) << c.name;
        std::printf("  %-20s %s\n", c.name, t.describe().c_str());
    }
}

TEST(LightSet, PdfLiMatchesSampleLi) {
    // The integrator's MIS path: a ray from p towards the sampled point hits the light; pdf_li of
    // that hit must equal the pdf sample_li returned.
    auto sc = make_scene({kTriangle, kQuad});
    PCG32 rng(3u, 4u);
    int valid = 0;
    for (vec3 p : {vec3(0.f), vec3(0.5f, 0.2f, -0.3f), vec3(1.f, -1.f, 1.f)})
        for (int i = 0; i < 2000; ++i) {
            float u1 = rng.next_float(), ux = rng.next_float();
            LightSample ls;
            if (!sc->lights.sample_li(p, u1, vec2(ux, rng.next_float()), ls)) continue;
            ++valid;
            ASSERT_NEAR(glm::length(ls.wi), 1.f, 1e-5f);
            ASSERT_NEAR(ls.dist, glm::length(ls.p - p), 1e-5f * ls.dist);
            Ray r;
            r.o = p;
            r.d = ls.wi;
            Hit hit;
            ASSERT_TRUE(sc->accel->intersect(r, hit));
            SurfaceInteraction si = sc->interaction(hit);
            ASSERT_NEAR(hit.t, ls.dist, 1e-4f * ls.dist);
            float pdf = sc->lights.pdf_li(p, si);
            ASSERT_NEAR(pdf, ls.pdf, 1e-3f * ls.pdf) << "p = " << p.x << "," << p.y << "," << p.z;
            // The radiance the sample carries is what the hit emits back towards p.
            vec3 Le = sc->lights.emitted(si, -ls.wi);
            ASSERT_EQ(Le, ls.Le);
        }
    EXPECT_GT(valid, 5000);
}

TEST(LightSet, OneSided) {
    auto sc = make_scene({kTriangle, kQuad});
    PCG32 rng(5u, 6u);
    // Above the triangle's plane and behind the quad: both lights show their backs.
    for (vec3 p : {vec3(3.5f, 0.f, 2.5f), vec3(10.f, 0.1f, 2.01f)})
        for (int i = 0; i < 10000; ++i) {
            float u1 = rng.next_float(), ux = rng.next_float();
            LightSample ls;
            ASSERT_FALSE(sc->lights.sample_li(p, u1, vec2(ux, rng.next_float()), ls));
        }
    // In the plane of the triangle (and behind the quad): no sample either.
    LightSample ls;
    EXPECT_FALSE(sc->lights.sample_li(vec3(5.f, 0.f, 2.f), 0.1f, vec2(0.3f, 0.3f), ls));
}

// Triangles are chosen with probability proportional to area x luminance. Four equal-area
// triangles along x: radiance 1, 2 (twice the power), 0 (never chosen), and red (luminance
// 0.2126); plus one of twice the area with radiance 1. Chi-square of the choice frequencies.
TEST(LightSet, SelectionProportionalToPower) {
    auto tri = [](float x0, float size, vec3 L) {
        return LightSpec{{vec3(x0, 0.f, 2.f), vec3(x0, size, 2.f), vec3(x0 + size, 0.f, 2.f)}, {uvec3(0, 1, 2)}, L};
    };
    const float s2 = std::sqrt(2.f);
    std::vector<LightSpec> lights = {tri(0.f, 1.f, vec3(1.f)), tri(2.f, 1.f, vec3(2.f)), tri(4.f, 1.f, vec3(0.f)),
                                     tri(6.f, 1.f, vec3(1.f, 0.f, 0.f)), tri(8.f, s2, vec3(1.f))};
    auto sc = make_scene(lights);
    EXPECT_EQ(sc->lights.triangle_count(), 4u);  // the black one is not a light to sample
    std::vector<double> power = {1.0, 2.0, 0.0, luminance(vec3(1.f, 0.f, 0.f)), 2.0};
    double total = 0;
    for (double w : power) total += w;

    const int n = 1000000;
    PCG32 rng(7u, 8u);
    std::vector<double> obs(lights.size(), 0.0), expct(lights.size()), uniform(lights.size());
    const vec3 p(5.f, 0.5f, 0.f);  // below all of them
    for (int i = 0; i < n; ++i) {
        float u1 = rng.next_float(), ux = rng.next_float();
        LightSample ls;
        ASSERT_TRUE(sc->lights.sample_li(p, u1, vec2(ux, rng.next_float()), ls));
        obs[size_t(std::clamp(int(ls.p.x / 2.f), 0, 4))] += 1;
    }
    for (size_t k = 0; k < lights.size(); ++k) {
        expct[k] = n * power[k] / total;
        uniform[k] = power[k] > 0 ? n / 4.0 : 0.0;  // the wrong rule: every light alike
    }
    EXPECT_EQ(obs[2], 0.0);
    ChiSquareResult good = chi_square_counts(obs, expct), bad = chi_square_counts(obs, uniform);
    const double level = sidak_level(kAlpha, 2);
    EXPECT_GE(good.p_value, level) << good.describe();
    EXPECT_LT(bad.p_value, level) << bad.describe();
    EXPECT_NEAR(obs[1] / obs[0], 2.0, 0.02);
    std::printf("  selection: %s; uniform selection p = %g\n", good.describe().c_str(), bad.p_value);
}

// The point chosen on a triangle is uniform in area: chi-square over the triangle domain.
TEST(LightSet, PointsAreUniformOnTheTriangle) {
    auto sc = make_scene({kTriangle});
    ChiSquareSetup s;
    const dvec2 p0(kTriangle.positions[0]), p1(kTriangle.positions[1]), p2(kTriangle.positions[2]);
    s.domain = triangle_domain(p0, p1, p2);
    const double area = 0.5 * std::abs((p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x));
    const Scene* scp = sc.get();
    s.sample = [scp](PCG32& r) {
        DomainSample d;
        float u1 = r.next_float(), ux = r.next_float();
        LightSample ls;
        if (scp->lights.sample_li(vec3(0.f), u1, vec2(ux, r.next_float()), ls)) {
            d.kind = DomainSample::Smooth;
            d.p = dvec3(ls.p.x, ls.p.y, 0.0);
        }
        return d;
    };
    s.pdf = [area](const dvec3&) { return 1.0 / area; };
    ChiSquareResult r = chi_square_2d(s);
    EXPECT_GE(r.p_value, kAlpha) << r.describe();
    std::printf("  points on the light: %s\n", r.describe().c_str());
}
