// Mitsuba's linearcurve (geometry/analytic.h, shapes/curve_file.h): the curve file's format and its
// errors, the segment's exact geometry (a capsule and a cone against closed forms, the first entry
// against a ray march of the swept sphere's distance, culled from inside), and a render against
// Mitsuba 3.9.1 with a control that must fail.
#include <gtest/gtest.h>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include "core/error.h"
#include "geometry/analytic.h"
#include "sampling/pcg32.h"
#include "sampling/warp.h"
#include "scene/loaders.h"
#include "scene/scene.h"
#include "shapes/curve_file.h"
#include "support/render.h"
#include "support/run.h"
#include "support/stats.h"

using namespace candela;

namespace {

std::string parse_error(const std::string& text) {
    try {
        parse_curve_file("c.txt", text);
    } catch (const Error& e) {
        return e.what();
    }
    return "<no error>";
}

bool hit_of(const AnalyticShape& s, vec3 o, vec3 d, Hit& h, float tmax = kInfinity) {
    Ray r;
    r.o = o;
    r.d = d;
    r.tmax = tmax;
    h = Hit();
    if (!intersect_analytic(s, r, h)) return false;
    h.prim = 0;
    return true;
}

// Distance from p to the swept sphere (c(v), r(v)), v in [0, 1]: the distance to a union of balls,
// min over v of |p - c(v)| - r(v), a convex function of v, minimised by ternary search.
double swept_distance(const AnalyticShape& s, dvec3 p) {
    auto f = [&](double v) {
        return glm::length(p - glm::mix(dvec3(s.center), dvec3(s.p1), v)) - (s.radius + v * (s.radius1 - s.radius));
    };
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 80; ++i) {
        const double a = lo + (hi - lo) / 3.0, b = hi - (hi - lo) / 3.0;
        (f(a) < f(b) ? hi : lo) = f(a) < f(b) ? b : a;
    }
    return std::min({f(0.0), f(1.0), f(0.5 * (lo + hi))});
}

// Sphere tracing of that distance from o along unit d: the first t where it reaches 0 (-1 when the
// ray leaves [0, 8] first), and the smallest distance seen on the way (a near miss is small).
double march(const AnalyticShape& s, dvec3 o, dvec3 d, double& closest) {
    closest = 1e300;
    double t = 0.0;
    for (int it = 0; it < 100000 && t < 8.0; ++it) {
        const double f = swept_distance(s, o + t * d);
        closest = std::min(closest, f);
        if (f < 1e-9) return t;
        t += std::max(f, 1e-6);
    }
    return -1.0;
}

}  // namespace

TEST(CurveFile, CurvesSeparatedByBlankLines) {
    CurveFile f = parse_curve_file("c.txt", "0 0 0 0.1\n1 0 0 0.2\n\n \t\n0 1 0 1\n0 2 0 1\n0 3 0 0.5 7\n");
    ASSERT_EQ(f.points.size(), 5u);
    EXPECT_EQ(f.starts, (std::vector<uint32_t>{0, 2}));
    EXPECT_FLOAT_EQ(f.radii[1], 0.2f);
    EXPECT_EQ(f.points[4], vec3(0.f, 3.f, 0.f));
    EXPECT_NE(parse_error("0 0 0 1\n1 1 1 1\n\n2 2 2 1\n").find("c.txt:4: a curve needs at least two control points"),
              std::string::npos);
    EXPECT_NE(parse_error("0 0 0 1\n1 1 x 1\n").find("c.txt:2: expected 'x y z radius'"), std::string::npos);
    EXPECT_NE(parse_error("0 0 0 1\n1 1 1 -1\n").find("c.txt:2: control point radius"), std::string::npos);
    EXPECT_NE(parse_error("0 0 0 1\nnan 1 1 1\n").find("c.txt:2: control point position is not finite"), std::string::npos);
    EXPECT_NE(parse_error("\n\n").find("no control points"), std::string::npos);
}

// A segment of constant radius is a capsule: cylinder side and hemispherical caps.
TEST(CurveGeometry, CapsuleAndConeClosedForms) {
    const AnalyticShape cap = make_curve_segment(vec3(0.f), 0.5f, vec3(0.f, 0.f, 2.f), 0.5f, 1, 4);
    Hit h;
    ASSERT_TRUE(hit_of(cap, vec3(5.f, 0.f, 1.5f), vec3(-1.f, 0.f, 0.f), h));
    EXPECT_NEAR(h.t, 4.5f, 1e-6f);
    EXPECT_NEAR(h.b1, 0.75f, 1e-6f);
    SurfaceInteraction si = analytic_interaction(cap, h);
    EXPECT_NEAR(glm::length(si.ng - vec3(1.f, 0.f, 0.f)), 0.f, 1e-6f);
    EXPECT_NEAR(si.uv.y, (0.75f + 1.f) / 4.f, 1e-6f);  // (v + segment) / segments
    // Along the axis: the cap sphere at p0, v = 0, normal -z.
    ASSERT_TRUE(hit_of(cap, vec3(0.f, 0.f, -5.f), vec3(0.f, 0.f, 1.f), h));
    EXPECT_NEAR(h.t, 4.5f, 1e-6f);
    EXPECT_EQ(h.b1, 0.f);
    si = analytic_interaction(cap, h);
    EXPECT_NEAR(si.ng.z, -1.f, 1e-6f);
    // From inside the tube nothing is seen (Embree culls the back faces of curves), nor from the
    // surface outwards.
    EXPECT_FALSE(hit_of(cap, vec3(0.f, 0.f, 1.f), vec3(1.f, 0.f, 0.f), h));
    EXPECT_FALSE(hit_of(cap, vec3(0.5001f, 0.f, 1.f), vec3(1.f, 0.f, 0.f), h));
    // A ray that passes beside it.
    EXPECT_FALSE(hit_of(cap, vec3(5.f, 0.51f, 1.f), vec3(-1.f, 0.f, 0.f), h));

    // A cone from radius 0.5 to 0.1 over length 2: its normal leans towards the thin end by
    // sin = (r0 - r1) / L = 0.2 on the lateral surface, and the point lies on the swept sphere.
    const AnalyticShape cone = make_curve_segment(vec3(0.f), 0.5f, vec3(0.f, 0.f, 2.f), 0.1f, 0, 1);
    ASSERT_TRUE(hit_of(cone, vec3(3.f, 0.3f, 1.f), vec3(-1.f, 0.f, 0.f), h));
    si = analytic_interaction(cone, h);
    EXPECT_NEAR(si.ng.z, 0.2f, 1e-5f);
    EXPECT_GT(h.b1, 0.f);
    EXPECT_LT(h.b1, 1.f);
    EXPECT_NEAR(swept_distance(cone, dvec3(si.p)), 0.0, 1e-5);
    // Mitsuba 3.9.1's curves have no dp/du, dp/dv (zero): the shading frame is Frame(n).
    EXPECT_EQ(si.dpdu, vec3(0.f));
    EXPECT_EQ(si.dpdv, vec3(0.f));
    // One sphere inside the other (|p1 - p0| < r0 - r1): just the big sphere.
    const AnalyticShape ball = make_curve_segment(vec3(0.f), 1.f, vec3(0.2f, 0.f, 0.f), 0.3f, 0, 1);
    ASSERT_TRUE(hit_of(ball, vec3(0.f, 4.f, 0.f), vec3(0.f, -1.f, 0.f), h));
    EXPECT_NEAR(h.t, 3.f, 1e-6f);
    EXPECT_EQ(h.b1, 0.f);
}

// Random rays from outside against a ray march of the swept sphere's distance: the same rays hit,
// at the first entry, and the reported point is on the surface with the outward normal.
TEST(CurveGeometry, FirstEntryAgreesWithRayMarching) {
    PCG32 rng(7, 3);
    int hits = 0, checked = 0;
    for (int k = 0; k < 300; ++k) {
        const vec3 p0 = vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 2.f - 1.f;
        const vec3 p1 = vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 2.f - 1.f;
        const float r0 = 0.05f + 0.4f * rng.next_float(), r1 = 0.05f + 0.4f * rng.next_float();
        const AnalyticShape s = make_curve_segment(p0, r0, p1, r1, 0, 1);
        for (int j = 0; j < 20; ++j) {
            const vec3 o = 4.f * square_to_uniform_sphere(vec2(rng.next_float(), rng.next_float()));
            const vec3 target = glm::mix(p0, p1, rng.next_float()) +
                                0.5f * vec3(rng.next_float(), rng.next_float(), rng.next_float()) - 0.25f;
            const vec3 d = glm::normalize(target - o);
            if (swept_distance(s, dvec3(o)) <= 0.0) continue;
            double closest;
            const double t_march = march(s, dvec3(o), dvec3(d), closest);
            Hit h;
            const bool found = hit_of(s, o, d, h);
            // Near misses and grazing hits are left out: there a float ray and the march may differ.
            if (t_march < 0.0 && closest < 2e-3) continue;
            if (found && std::abs(glm::dot(analytic_interaction(s, h).ng, d)) < 0.05f) continue;
            ++checked;
            ASSERT_EQ(found, t_march >= 0.0) << "segment " << k << " ray " << j;
            if (!found) continue;
            ++hits;
            EXPECT_NEAR(h.t, t_march, 1e-4) << "segment " << k << " ray " << j;
            const SurfaceInteraction si = analytic_interaction(s, h);
            EXPECT_NEAR(swept_distance(s, dvec3(si.p)), 0.0, 2e-4);
            EXPECT_LT(glm::dot(si.ng, d), 0.f);
            // The normal is the distance's gradient (central differences).
            dvec3 grad;
            for (int a = 0; a < 3; ++a) {
                dvec3 e(0.0);
                e[a] = 1e-5;
                grad[a] = (swept_distance(s, dvec3(si.p) + e) - swept_distance(s, dvec3(si.p) - e)) / 2e-5;
            }
            EXPECT_GT(glm::dot(dvec3(si.ng), glm::normalize(grad)), 0.9999) << "segment " << k << " ray " << j;
        }
    }
    std::printf("  %d rays checked, %d hits\n", checked, hits);
    EXPECT_GT(checked, 4000);
    EXPECT_GT(hits, 1000);
}

// Hit by hit against Mitsuba 3.9.1 (Embree's round linear curves): tests/data/curve_hits_mitsuba.txt,
// made by tests/data/make_curve_hits.py, holds 300 rays at the curves of scenes/curves.txt and
// what Mitsuba's ray_intersect returned. The same rays through candela's scene: the same misses, and
// for hits the same segment, t, normal and uv (float rounding on both sides; u wraps around at 1).
TEST(CurveGeometry, HitsAgreeWithMitsuba) {
    const std::string d = test::temp_dir("curve-hits");
    test::write_text(d + "/s.xml", "<scene version=\"3.0.0\"><shape type=\"linearcurve\"><string name=\"filename\" value=\"" +
                                       std::string(CANDELA_TEST_DATA) + "/scenes/curves.txt\"/></shape></scene>\n");
    const auto scene = build_scene(load_scene(d + "/s.xml"));
    std::ifstream in(std::string(CANDELA_TEST_DATA) + "/curve_hits_mitsuba.txt");
    ASSERT_TRUE(in.good());
    std::string line;
    int rays = 0, hits = 0, u_checked = 0;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream ss(line);
        Ray r;
        ss >> r.o.x >> r.o.y >> r.o.z >> r.d.x >> r.d.y >> r.d.z;
        std::string first;
        ss >> first;
        ++rays;
        Hit h;
        const bool found = scene->accel->intersect(r, h);
        if (first == "miss") {
            EXPECT_FALSE(found) << line;
            continue;
        }
        ASSERT_TRUE(found) << line;
        ++hits;
        const float t = std::stof(first);
        vec3 n;
        vec2 uv;
        uint32_t seg;
        ss >> n.x >> n.y >> n.z >> uv.x >> uv.y >> seg;
        const SurfaceInteraction si = scene->interaction(h);
        EXPECT_NEAR(h.t, t, 1e-5f * std::max(1.f, t)) << line;
        EXPECT_EQ(h.prim - uint32_t(scene->shapes[si.shape].analytic), seg) << line;
        EXPECT_NEAR(glm::length(si.ng - n), 0.f, 1e-3f) << line;
        // u is the angle around the axis: ill-conditioned where the normal is nearly the axis (the
        // poles of the caps), so checked elsewhere.
        const AnalyticShape& a = scene->analytic[h.prim];
        const float du = std::abs(si.uv.x - uv.x);
        if (std::abs(glm::dot(si.ng, glm::normalize(a.p1 - a.center))) < 0.99f) {
            EXPECT_NEAR(std::min(du, 1.f - du), 0.f, 1e-3f) << line;
            ++u_checked;
        }
        EXPECT_NEAR(si.uv.y, uv.y, 1e-4f) << line;
    }
    std::printf("  %d rays, %d hits, u compared on %d\n", rays, hits, u_checked);
    EXPECT_EQ(rays, 300);
    EXPECT_GT(hits, 250);
    EXPECT_GT(u_checked, 250);
}

// Scene-file errors name the file and line.
TEST(CurveXml, Errors) {
    const std::string d = test::temp_dir("curve-xml");
    test::write_text(d + "/one.txt", "0 0 0 1\n1 1 1 1\n\n2 2 2 1\n");
    auto load_error = [&](const std::string& shape) {
        test::write_text(d + "/s.xml", "<scene version=\"3.0.0\">\n" + shape + "\n</scene>\n");
        try {
            load_scene(d + "/s.xml");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("<no error>");
    };
    std::string e = load_error("<shape type=\"linearcurve\"><string name=\"filename\" value=\"missing.txt\"/></shape>");
    EXPECT_NE(e.find("s.xml:2"), std::string::npos) << e;
    EXPECT_NE(e.find("missing.txt"), std::string::npos) << e;
    e = load_error("<shape type=\"linearcurve\"><string name=\"filename\" value=\"one.txt\"/></shape>");
    EXPECT_NE(e.find("one.txt:4: a curve needs at least two control points"), std::string::npos) << e;
    test::write_text(d + "/two.txt", "0 0 0 1\n1 1 1 1\n");
    e = load_error("<shape type=\"linearcurve\"><string name=\"filename\" value=\"two.txt\"/>\n"
                   "<emitter type=\"area\"/></shape>");
    EXPECT_NE(e.find("s.xml:3: a linearcurve cannot be an area emitter"), std::string::npos) << e;
}

// tests/data/scenes/curves.xml against the mean of 16 Mitsuba 3.9.1 renders of 1024 spp (llvm_ad_rgb,
// Embree's round linear curves):
//   $PY tests/data/make_reference.py tests/data/scenes/curves.xml --res 32 --batches 16 --spp 1024
//       --out tests/data/curves32
// Control: the same curves with every radius 0.8 times as large must fail.
TEST(CurveRender, MatchesMitsuba) {
    using namespace candela::stats;
    const ImageEstimate ref = ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/curves32");
    ASSERT_EQ(ref.width, 32);
    auto render = [](const char* file) {
        auto built = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/curves.xml", {{"res", "32"}, {"file", file}}));
        return test::render_batch_estimate(*built, built->params(), 16, 128);
    };
    // rel_floor 1e-5: the sky seen directly is noise-free in both, a few 1e-7 apart.
    const BlockTestResult r = block_z_test(render("curves.txt"), ref, 8, 0.01, 1e-5);
    std::printf("  curves: %s\n", r.describe().c_str());
    EXPECT_TRUE(r.passed(0.01)) << r.describe();
    const BlockTestResult c = block_z_test(render("curves_thin.txt"), ref, 8, 0.01, 1e-5);
    std::printf("  control, radii x 0.8: %s\n", c.describe().c_str());
    EXPECT_FALSE(c.passed(0.01)) << c.describe();
}
