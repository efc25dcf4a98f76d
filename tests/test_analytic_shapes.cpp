// Analytic shapes (sphere, disk, cylinder; geometry/analytic.h): intersection against the exact
// geometry, Mitsuba's normals and uv, chi-square tests of every new light-sampling routine against
// its claimed density, the irradiance of a spherical light against pi L (r/d)^2, and bad input in the
// scene file. Robust ray offsets at 1e-4 and 1e5 scale: tests/test_self_intersection.cpp.
#include <gtest/gtest.h>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include "accel/with_analytic.h"
#include "core/error.h"
#include "film/film.h"
#include "film/image_io.h"
#include "geometry/analytic.h"
#include "integrator/path.h"
#include "render/renderer.h"
#include "sampling/pcg32.h"
#include "sampling/warp.h"
#include "scene/scene.h"
#include "support/render.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;
constexpr double kPiD = 3.14159265358979323846;

vec3 random_dir(PCG32& rng) { return square_to_uniform_sphere(vec2(rng.next_float(), rng.next_float())); }

mat4 rotation(float deg, vec3 axis) { return glm::rotate(mat4(1.f), glm::radians(deg), glm::normalize(axis)); }
mat4 translation(vec3 t) { return glm::translate(mat4(1.f), t); }
mat4 scaling(vec3 s) { return glm::scale(mat4(1.f), s); }

// One scene of the given analytic shapes; shape i emits `radiance` when emissive[i].
std::shared_ptr<const Scene> make_scene(const std::vector<AnalyticShape>& shapes, const std::vector<bool>& emissive = {},
                                        vec3 radiance = vec3(1.f), const std::string& accel = "kdtree") {
    SceneDescription d;
    d.source = "<test_analytic_shapes>";
    d.materials.push_back(Material{"white", DiffuseBsdf{vec3(0.5f)}, false});
    d.settings.width = d.settings.height = 4;
    for (size_t i = 0; i < shapes.size(); ++i) {
        int32_t e = -1;
        if (i < emissive.size() && emissive[i]) {
            d.emitters.push_back(AreaEmitter{radiance});
            e = int32_t(d.emitters.size() - 1);
        }
        d.add_analytic_shape("shape" + std::to_string(i), shapes[i], 0, e);
    }
    return build_scene(std::move(d), accel);
}

}  // namespace

// ---- intersection and the interaction -----------------------------------------------------------

TEST(AnalyticShapes, SphereHitsAreOnTheSphereWithMitsubaUv) {
    // Mitsuba's parameterisation: to_world x translate(center) x scale(radius).
    AnalyticShape s = make_sphere(translation(vec3(1, 2, 3)) * rotation(30.f, vec3(0, 0, 1)), vec3(0.5f, 0, 0), 2.f, false);
    EXPECT_NEAR(s.radius, 2.f, 1e-6f);
    vec3 c = vec3(1, 2, 3) + vec3(rotation(30.f, vec3(0, 0, 1)) * glm::vec4(0.5f, 0, 0, 1)) - vec3(0.f);
    EXPECT_NEAR(glm::length(s.center - c), 0.f, 1e-5f);
    EXPECT_NEAR(s.area, 4.f * kPi * 4.f, 1e-3f);
    PCG32 rng(3, 1);
    double max_dev = 0;
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        Ray r;
        r.o = s.center + 10.f * random_dir(rng);
        vec3 target = s.center + 2.5f * vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
        r.d = target - r.o;  // not unit: the intersector must not assume it
        Hit h;
        if (!intersect_analytic(s, r, h)) continue;
        ++hits;
        h.prim = 0;
        SurfaceInteraction si = analytic_interaction(s, h);
        max_dev = std::max(max_dev, std::abs(double(glm::length(dvec3(si.p) - dvec3(s.center))) - 2.0));
        EXPECT_GT(glm::dot(si.ng, si.p - s.center), 0.f);
        EXPECT_LE(glm::dot(si.ng, r.d), 0.f);  // from outside we see the outer side
        // The point along the ray agrees with the reprojected one within float rounding.
        EXPECT_LT(glm::length(r.o + h.t * r.d - si.p), 1e-4f);
        // uv as Mitsuba: local = R^T (p - c) / r; u = phi / 2pi, v = theta / pi.
        vec3 local = glm::transpose(glm::mat3(rotation(30.f, vec3(0, 0, 1)))) * (si.p - s.center) / 2.f;
        float phi = std::atan2(local.y, local.x);
        if (phi < 0.f) phi += 2.f * kPi;
        EXPECT_NEAR(si.uv.x, phi / (2.f * kPi), 1e-4f);
        EXPECT_NEAR(si.uv.y, std::acos(std::clamp(local.z, -1.f, 1.f)) / kPi, 1e-4f);
    }
    EXPECT_GT(hits, 5000);
    std::printf("  %d hits, max | |p - c| - r | = %.3g\n", hits, max_dev);
    EXPECT_LT(max_dev, 2e-6);  // a couple of float ulps at radius 2 (the reprojection)
}

TEST(AnalyticShapes, SphereFlipAndMirror) {
    AnalyticShape a = make_sphere(mat4(1.f), vec3(0.f), 1.f, true);
    AnalyticShape b = make_sphere(scaling(vec3(-1.f, 1.f, 1.f)), vec3(0.f), 1.f, false);  // mirrored
    AnalyticShape c = make_sphere(scaling(vec3(-1.f, 1.f, 1.f)), vec3(0.f), 1.f, true);
    EXPECT_TRUE(a.flip);
    EXPECT_TRUE(b.flip);   // Mitsuba: a negative scale turns the normals inwards
    EXPECT_FALSE(c.flip);
    Ray r;
    r.o = vec3(0, 0, 5);
    r.d = vec3(0, 0, -1);
    Hit h;
    ASSERT_TRUE(intersect_analytic(a, r, h));
    EXPECT_NEAR(h.t, 4.f, 1e-6f);
    SurfaceInteraction si = analytic_interaction(a, h);
    EXPECT_NEAR(si.ng.z, -1.f, 1e-6f);
    EXPECT_NEAR(si.ns.z, -1.f, 1e-6f);
    // From inside, the far side.
    Ray in;
    in.o = vec3(0.f);
    in.d = vec3(1, 0, 0);
    Hit hi;
    ASSERT_TRUE(intersect_analytic(a, in, hi));
    EXPECT_NEAR(hi.t, 1.f, 1e-6f);
}

TEST(AnalyticShapes, DiskAndCylinderGeometry) {
    // Disk: an ellipse under to_world = translate x rotate x scale(2, 0.5, 1).
    mat4 m = translation(vec3(0, 1, 0)) * rotation(-90.f, vec3(1, 0, 0)) * scaling(vec3(2.f, 0.5f, 1.f));
    AnalyticShape d = make_disk(m, false);
    EXPECT_NEAR(d.area, kPi * 1.f, 1e-5f);
    EXPECT_NEAR(d.normal.y, 1.f, 1e-6f);  // rotate(-90 about x) takes +z to +y
    Ray r;
    r.o = vec3(1.5f, 5.f, 0.1f);
    r.d = vec3(0, -1, 0);
    Hit h;
    ASSERT_TRUE(intersect_analytic(d, r, h));
    EXPECT_NEAR(h.t, 4.f, 1e-6f);
    SurfaceInteraction si = analytic_interaction(d, h);
    EXPECT_NEAR(si.p.y, 1.f, 1e-6f);
    // object point (0.75, -0.2) (y_obj = -z_world / 0.5): uv = (r, phi / 2pi).
    double ro = std::hypot(0.75, 0.2), v = std::atan2(-0.2, 0.75) / (2 * kPiD) + 1.0;
    EXPECT_NEAR(si.uv.x, ro, 1e-5);
    EXPECT_NEAR(si.uv.y, v, 1e-5);
    r.o = vec3(2.1f, 5.f, 0.f);  // outside the ellipse along x
    r.tmax = kInfinity;
    EXPECT_FALSE(intersect_analytic(d, r, h));
    EXPECT_TRUE(make_disk(m, true).normal.y < 0.f);

    // Cylinder from p0 = (0,0,0) to p1 = (0,2,0), radius 0.5: outward normals, no caps.
    AnalyticShape c = make_cylinder(mat4(1.f), vec3(0.f), vec3(0, 2, 0), 0.5f, false);
    EXPECT_NEAR(c.area, 2.f * kPi * 0.5f * 2.f, 1e-5f);
    Ray rc;
    rc.o = vec3(3.f, 1.f, 0.f);
    rc.d = vec3(-1.f, 0.f, 0.f);
    Hit hc;
    ASSERT_TRUE(intersect_analytic(c, rc, hc));
    EXPECT_NEAR(hc.t, 2.5f, 1e-6f);
    SurfaceInteraction sc = analytic_interaction(c, hc);
    EXPECT_NEAR(sc.ng.x, 1.f, 1e-6f);
    EXPECT_NEAR(sc.uv.y, 0.5f, 1e-6f);  // z / length
    Ray cap;  // along the axis: no caps, so it passes through
    cap.o = vec3(0.f, -1.f, 0.1f);
    cap.d = vec3(0.f, 1.f, 0.f);
    Hit hcap;
    EXPECT_FALSE(intersect_analytic(c, cap, hcap));
    Ray inside;  // from inside: the inner side, normal still outwards
    inside.o = vec3(0.f, 1.f, 0.f);
    inside.d = vec3(0.f, 0.f, 1.f);
    Hit hin;
    ASSERT_TRUE(intersect_analytic(c, inside, hin));
    EXPECT_NEAR(hin.t, 0.5f, 1e-6f);
    EXPECT_NEAR(analytic_interaction(c, hin).ng.z, 1.f, 1e-6f);
    Ray above;  // beyond p1
    above.o = vec3(3.f, 2.1f, 0.f);
    above.d = vec3(-1.f, 0.f, 0.f);
    EXPECT_FALSE(occluded_analytic(c, above));
}

// Hits, normals and uv against Mitsuba 3.9.1 (scalar_rgb, mi.load_dict + scene.ray_intersect on
// the same shapes and rays; the numbers below are its output, rounded to 7 digits).
TEST(AnalyticShapes, HitsNormalsAndUvMatchMitsuba) {
    struct Case {
        const char* name;
        AnalyticShape s;
        vec3 o, d;
        float t;
        vec3 n;
        vec2 uv;
    };
    const float h = 0.70710678f;
    const mat4 cyl_world = rotation(20.f, vec3(0, h, h));
    const Case cases[] = {
        {"sphere", make_sphere(translation(vec3(1, 2, 3)) * rotation(30.f, vec3(0, 0, 1)), vec3(0.5f, 0, 0), 2.f, false),
         vec3(1.3f, 9, 2.5f), vec3(0, -1, 0.05f), 4.7775855f, vec3(-0.0665064f, 0.9891876f, -0.1307094f),
         vec2(0.1773511f, 0.5417254f)},
        {"sphere", make_sphere(translation(vec3(1, 2, 3)) * rotation(30.f, vec3(0, 0, 1)), vec3(0.5f, 0, 0), 2.f, false),
         vec3(5, 2.2f, 3.1f), vec3(-1, 0, 0), 1.5701147f, vec3(0.9984363f, -0.025f, 0.05f), vec2(0.9126823f, 0.4840779f)},
        {"mirrored sphere", make_sphere(translation(vec3(0, 1, 0)) * scaling(vec3(-0.5f, 0.5f, 0.5f)), vec3(0.f), 1.f, false),
         vec3(0.1f, 5, 0.2f), vec3(0, -1, 0), 3.5527864f, vec3(-0.2f, -0.8944272f, -0.4f), vec2(0.2850122f, 0.3690102f)},
        {"disk", make_disk(translation(vec3(0, 1, 0)) * rotation(-90.f, vec3(1, 0, 0)) * scaling(vec3(2, 0.5f, 1)), false),
         vec3(1.5f, 5, 0.1f), vec3(0, -1, 0), 4.f, vec3(0, 1, 0), vec2(0.7762086f, 0.9585238f)},
        {"disk", make_disk(translation(vec3(0, 1, 0)) * rotation(-90.f, vec3(1, 0, 0)) * scaling(vec3(2, 0.5f, 1)), false),
         vec3(-0.3f, 5, -0.2f), vec3(0, -1, 0), 4.f, vec3(0, 1, 0), vec2(0.4272001f, 0.3071001f)},
        {"cylinder", make_cylinder(cyl_world, vec3(0.2f, 0, 0.1f), vec3(0.5f, 2, 0.3f), 0.5f, false), vec3(3, 1, 0.3f),
         vec3(-1, 0, 0), 2.3878751f, vec3(0.9410756f, 0.04131f, 0.3356637f), vec2(0.8822629f, 0.4597787f)},
        {"cylinder", make_cylinder(cyl_world, vec3(0.2f, 0, 0.1f), vec3(0.5f, 2, 0.3f), 0.5f, false), vec3(0.2f, 1.2f, 3),
         vec3(0, 0, -1), 2.3521399f, vec3(0.1562076f, -0.0767907f, 0.9847346f), vec2(0.7109252f, 0.588131f)},
        {"cylinder along y", make_cylinder(mat4(1.f), vec3(0.f), vec3(0, 2, 0), 0.5f, false), vec3(3, 1, 0.1f),
         vec3(-1, 0, 0), 2.510102f, vec3(0.9797959f, 0, 0.2f), vec2(0.9679529f, 0.5f)},
    };
    for (const Case& c : cases) {
        Ray r;
        r.o = c.o;
        r.d = glm::normalize(c.d);
        Hit hit;
        ASSERT_TRUE(intersect_analytic(c.s, r, hit)) << c.name;
        hit.prim = 0;
        SurfaceInteraction si = analytic_interaction(c.s, hit);
        EXPECT_NEAR(hit.t, c.t, 2e-6f) << c.name;
        EXPECT_NEAR(glm::length(si.ng - c.n), 0.f, 2e-6f) << c.name;
        EXPECT_NEAR(glm::length(si.ns - c.n), 0.f, 2e-6f) << c.name;
        EXPECT_NEAR(si.uv.x, c.uv.x, 2e-6f) << c.name;
        EXPECT_NEAR(si.uv.y, c.uv.y, 2e-6f) << c.name;
    }
}

// Through the scene: triangles and analytic shapes in one accelerator, the nearest wins.
TEST(AnalyticShapes, SceneAcceleratorMixesTrianglesAndShapes) {
    SceneDescription d;
    d.source = "<mix>";
    d.materials.push_back(Material{"white", DiffuseBsdf{vec3(0.5f)}, false});
    d.settings.width = d.settings.height = 4;
    d.add_shape("quad", {vec3(-5, -5, 0), vec3(5, -5, 0), vec3(5, 5, 0), vec3(-5, 5, 0)}, {},
                {uvec3(0, 1, 2), uvec3(0, 2, 3)}, 0, -1);
    d.add_analytic_shape("ball", make_sphere(mat4(1.f), vec3(0, 0, 2), 1.f, false), 0, -1);
    auto sc = build_scene(std::move(d), "kdtree");
    Ray r;
    r.o = vec3(0, 0, 10);
    r.d = vec3(0, 0, -1);
    Hit h;
    ASSERT_TRUE(sc->accel->intersect(r, h));
    EXPECT_EQ(h.kind, PrimKind::Sphere);
    EXPECT_NEAR(h.t, 7.f, 1e-6f);
    SurfaceInteraction si = sc->interaction(h);
    EXPECT_EQ(si.shape, 1u);
    Ray r2;
    r2.o = vec3(3, 0, 10);
    r2.d = vec3(0, 0, -1);
    Hit h2;
    ASSERT_TRUE(sc->accel->intersect(r2, h2));
    EXPECT_EQ(h2.kind, PrimKind::Triangle);
    EXPECT_EQ(sc->interaction(h2).shape, 0u);
    // A shadow ray from the quad to above the ball is blocked by it.
    Ray s;
    s.o = vec3(0, 0, 0.001f);
    s.d = vec3(0, 0, 5);
    s.tmax = 1.f;
    EXPECT_TRUE(sc->accel->occluded(s));
    EXPECT_TRUE(sc->geometry->bounds.contains(vec3(0, 0, 2.99f)));
}

// ---- sampling: chi-square against the claimed densities ------------------------------------------

namespace {

// Directions from ref_p inside a cone about `axis` a little wider than the sphere's (so that a
// direction outside the true cone is caught), g = ((1 - cos) / (1 - cos_dom), phi / 2pi).
Domain cone_domain(vec3 axis, double omc_dom) {
    Frame f(axis);
    Domain d;
    d.name = "cone";
    d.to_point = [f, omc_dom](dvec2 g) {
        double x = g.x * omc_dom, cos_t = 1 - x, sin_t = std::sqrt(std::max(0.0, x * (2 - x))), phi = 2 * kPiD * g.y;
        vec3 w = f.to_world(vec3(float(sin_t * std::cos(phi)), float(sin_t * std::sin(phi)), float(cos_t)));
        return dvec3(w);
    };
    d.to_grid = [f, omc_dom](const dvec3& p, dvec2& g) {
        vec3 l = f.to_local(vec3(p));
        double x = 1.0 - double(l.z);
        // 1 - cos from sin^2 for accuracy near the axis.
        double s2 = double(l.x) * l.x + double(l.y) * l.y;
        if (l.z > 0.5f) x = s2 / (1.0 + double(l.z));
        if (x > omc_dom) return false;
        double phi = std::atan2(double(l.y), double(l.x));
        if (phi < 0) phi += 2 * kPiD;
        g = dvec2(std::min(x / omc_dom, 1.0 - 1e-12), std::min(phi / (2 * kPiD), 1.0 - 1e-12));
        return true;
    };
    d.jacobian = [omc_dom](dvec2) { return 2 * kPiD * omc_dom; };
    return d;
}

// The sphere light's directional density from ref_p as the path tracer sees it: pdf_analytic at
// the first hit of the ray in that direction, 0 where the ray misses.
double sphere_direction_pdf(const AnalyticShape& s, vec3 ref, vec3 w, double radius_scale = 1.0) {
    AnalyticShape t = s;
    t.radius = float(s.radius * radius_scale);
    Ray r;
    r.o = ref;
    r.d = w;
    Hit h;
    if (!intersect_analytic(t, r, h)) return 0.0;
    h.prim = 0;
    SurfaceInteraction si = analytic_interaction(t, h);
    return pdf_analytic(t, ref, si.p, si.ng);
}

ChiSquareResult sphere_cone_test(double dist, double radius_scale, uint64_t seed) {
    AnalyticShape s = make_sphere(mat4(1.f), vec3(0.3f, -0.2f, 0.1f), 1.f, false);
    vec3 ref = s.center + float(dist) * glm::normalize(vec3(0.2f, 1.f, -0.4f));
    vec3 axis = glm::normalize(s.center - ref);
    double omc = 1.0 / (dist * dist) / (1.0 + std::sqrt(1.0 - 1.0 / (dist * dist)));
    ChiSquareSetup cs;
    // 1.23: the rim falls inside a row of cells, not on a boundary between rows (a sample
    // within rounding of the rim must land in a cell that expects samples).
    cs.domain = cone_domain(axis, std::min(2.0, 1.23 * omc));
    cs.res_x = 20;
    cs.res_y = 20;
    cs.samples = 400000;
    cs.seed = seed;
    cs.sample = [&](PCG32& rng) {
        DomainSample ds;
        AnalyticSample as;
        if (!sample_analytic(s, ref, vec2(rng.next_float(), rng.next_float()), as)) return ds;
        ds.kind = DomainSample::Smooth;
        ds.p = dvec3(glm::normalize(as.p - ref));
        return ds;
    };
    cs.pdf = [&](const dvec3& w) { return sphere_direction_pdf(s, ref, vec3(w), radius_scale); };
    return chi_square_2d(cs);
}

}  // namespace

TEST(AnalyticShapes, SphereConeSamplingMatchesPdf) {
    // Near (a wide cone), middle, far (a cone of 0.6 degrees, where 1 - cos theta_max cancels).
    const double dists[] = {1.05, 3.0, 100.0};
    const double level = sidak_level(kAlpha, 3);
    for (int i = 0; i < 3; ++i) {
        ChiSquareResult r = sphere_cone_test(dists[i], 1.0, 10 + i);
        std::printf("  sphere light at distance %g r: %s\n", dists[i], r.describe().c_str());
        EXPECT_GE(r.p_value, level) << dists[i];
        EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << dists[i];
    }
}

TEST(AnalyticShapes, SphereConeTestDetectsWrongPdf) {
    // Control: the density of a sphere 3% larger (its cone is wider) must be rejected.
    ChiSquareResult r = sphere_cone_test(3.0, 1.03, 20);
    std::printf("  claimed pdf of a 3%% larger sphere: %s\n", r.describe().c_str());
    EXPECT_LT(r.p_value, 1e-6);
}

namespace {

// Area sampling of a shape, in area measure over the shape's own parameterisation: the claimed
// area density is the solid-angle pdf converted back (pdf_sa |cos| / dist^2), so the test checks
// both the points and the conversion. grid g in [0,1]^2 -> object point; jacobian = dA/dg.
struct AreaParam {
    std::function<vec3(dvec2)> point;                    // world point
    std::function<bool(vec3, dvec2&)> grid;              // world point -> g
    std::function<double(dvec2)> jacobian;
};

ChiSquareResult area_test(const AnalyticShape& s, const AreaParam& ap, vec3 ref, uint64_t seed, double pdf_scale = 1.0) {
    ChiSquareSetup cs;
    cs.domain.name = "shape";
    cs.domain.to_point = [&](dvec2 g) { return dvec3(ap.point(g)); };
    cs.domain.to_grid = [&](const dvec3& p, dvec2& g) { return ap.grid(vec3(p), g); };
    cs.domain.jacobian = ap.jacobian;
    cs.res_x = cs.res_y = 16;
    cs.samples = 300000;
    cs.seed = seed;
    cs.sample = [&](PCG32& rng) {
        DomainSample ds;
        AnalyticSample as;
        if (!sample_analytic(s, ref, vec2(rng.next_float(), rng.next_float()), as)) return ds;
        ds.kind = DomainSample::Smooth;
        ds.p = dvec3(as.p);
        return ds;
    };
    cs.pdf = [&](const dvec3& pw) {
        vec3 p(pw);
        // The normal at p, as the sampler reports it.
        vec3 n;
        if (s.kind == PrimKind::Disk) n = s.normal;
        else if (s.kind == PrimKind::Sphere) n = glm::normalize(p - s.center);
        else {
            vec3 l = vec3(s.to_object * glm::dvec4(dvec3(p), 1.0));
            n = glm::normalize(glm::mat3(s.to_world) * vec3(l.x, l.y, 0.f));
        }
        vec3 d = p - ref;
        double dist2 = glm::dot(d, d), cos_l = std::abs(glm::dot(n, d)) / std::sqrt(dist2);
        return pdf_scale * double(pdf_analytic(s, ref, p, n)) * cos_l / dist2;
    };
    return chi_square_2d(cs);
}

AreaParam disk_param(const AnalyticShape& s) {
    AreaParam a;
    a.point = [&s](dvec2 g) {
        double r = std::sqrt(g.x), phi = 2 * kPiD * g.y;
        return vec3(s.to_world * glm::vec4(float(r * std::cos(phi)), float(r * std::sin(phi)), 0.f, 1.f));
    };
    a.grid = [&s](vec3 p, dvec2& g) {
        dvec3 l = dvec3(s.to_object * glm::dvec4(dvec3(p), 1.0));
        double r2 = l.x * l.x + l.y * l.y;
        if (r2 > 1.0 + 1e-5 || std::abs(l.z) > 1e-4) return false;
        double phi = std::atan2(l.y, l.x);
        if (phi < 0) phi += 2 * kPiD;
        g = dvec2(std::min(r2, 1.0 - 1e-12), std::min(phi / (2 * kPiD), 1.0 - 1e-12));
        return true;
    };
    a.jacobian = [&s](dvec2) { return double(s.area); };  // dA = (area / pi) r dr dphi = area dg
    return a;
}

AreaParam cylinder_param(const AnalyticShape& s) {
    AreaParam a;
    a.point = [&s](dvec2 g) {
        double phi = 2 * kPiD * g.y;
        return vec3(s.to_world * glm::vec4(float(s.radius * std::cos(phi)), float(s.radius * std::sin(phi)),
                                           float(g.x * s.length), 1.f));
    };
    a.grid = [&s](vec3 p, dvec2& g) {
        dvec3 l = dvec3(s.to_object * glm::dvec4(dvec3(p), 1.0));
        if (std::abs(std::hypot(l.x, l.y) - s.radius) > 1e-4 * s.radius) return false;
        if (l.z < -1e-5 || l.z > s.length * (1 + 1e-5)) return false;
        double phi = std::atan2(l.y, l.x);
        if (phi < 0) phi += 2 * kPiD;
        g = dvec2(std::clamp(l.z / s.length, 0.0, 1.0 - 1e-12), std::min(phi / (2 * kPiD), 1.0 - 1e-12));
        return true;
    };
    a.jacobian = [&s](dvec2) { return double(s.area); };
    return a;
}

AreaParam sphere_param(const AnalyticShape& s) {
    AreaParam a;
    a.point = [&s](dvec2 g) {
        double z = 1 - 2 * g.x, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPiD * g.y;
        return s.center + s.radius * vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
    };
    a.grid = [&s](vec3 p, dvec2& g) {
        dvec3 l = (dvec3(p) - dvec3(s.center)) / double(s.radius);
        if (std::abs(glm::length(l) - 1.0) > 1e-4) return false;
        double phi = std::atan2(l.y, l.x);
        if (phi < 0) phi += 2 * kPiD;
        g = dvec2(std::clamp((1 - l.z) / 2, 0.0, 1.0 - 1e-12), std::min(phi / (2 * kPiD), 1.0 - 1e-12));
        return true;
    };
    a.jacobian = [&s](dvec2) { return double(s.area); };
    return a;
}

}  // namespace

TEST(AnalyticShapes, AreaSamplingMatchesPdf) {
    AnalyticShape disk = make_disk(translation(vec3(0.2f, 0, 0)) * rotation(35.f, vec3(1, 1, 0)) * scaling(vec3(1.5f, 0.7f, 1)), false);
    AnalyticShape cyl = make_cylinder(rotation(20.f, vec3(0, 1, 1)), vec3(0, 0, -1), vec3(0.3f, 0.2f, 1.5f), 0.6f, false);
    AnalyticShape sph = make_sphere(mat4(1.f), vec3(1, 2, 3), 2.f, false);  // sampled by area from inside
    struct Case {
        const char* name;
        const AnalyticShape* s;
        AreaParam ap;
        vec3 ref;
    } cases[] = {
        {"disk", &disk, disk_param(disk), vec3(0.5f, 1.5f, -1.f)},
        {"cylinder, outside", &cyl, cylinder_param(cyl), vec3(2.f, 0.5f, 0.3f)},
        {"cylinder, inside", &cyl, cylinder_param(cyl), vec3(0.05f, 0.02f, 0.2f)},
        {"sphere, inside", &sph, sphere_param(sph), vec3(1.5f, 2.2f, 2.f)},
    };
    const double level = sidak_level(kAlpha, 4);
    uint64_t seed = 30;
    for (Case& c : cases) {
        ChiSquareResult r = area_test(*c.s, c.ap, c.ref, seed++);
        std::printf("  %s: %s\n", c.name, r.describe().c_str());
        EXPECT_GE(r.p_value, level) << c.name;
        EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << c.name;
    }
    // Control: a density 3% too high everywhere is rejected.
    ChiSquareResult bad = area_test(disk, cases[0].ap, cases[0].ref, 40, 1.03);
    std::printf("  disk with a 3%% wrong pdf: %s\n", bad.describe().c_str());
    EXPECT_LT(bad.p_value, 1e-6);
}

// ---- the light set: irradiance of a spherical light ----------------------------------------------

namespace {

// Irradiance at ref (normal towards the sphere's centre) by light sampling, BSDF (cosine) sampling
// and their MIS combination, with the path tracer's own rules (emission one-sided, pdf_li for the
// weights). Exact: E = pi L (r / d)^2.
struct IrradianceRun {
    RunningStats light, bsdf, mis;
};
IrradianceRun irradiance(const Scene& sc, vec3 ref, vec3 n, int samples, uint64_t seed) {
    IrradianceRun out;
    PCG32 rng(seed, 3);
    Frame f(n);
    SurfaceInteraction at;
    at.p = ref;
    at.ng = at.ns = n;
    for (int i = 0; i < samples; ++i) {
        double el = 0, eb = 0, wl = 0, wb = 0;
        LightSample ls;
        if (sc.lights.sample_li(ref, rng.next_float(), vec2(rng.next_float(), rng.next_float()), ls)) {
            float cos_t = glm::dot(ls.wi, n);
            if (cos_t > 0.f && !sc.accel->occluded(spawn_ray_to(at, ls.p, ls.p_error, ls.n))) {
                el = double(ls.Le.x) * cos_t / ls.pdf;
                float bpdf = cos_t / kPi;
                wl = el * double(ls.pdf * ls.pdf / (ls.pdf * ls.pdf + bpdf * bpdf));
            }
        }
        vec3 w = f.to_world(square_to_cosine_hemisphere(vec2(rng.next_float(), rng.next_float())));
        Ray r = spawn_ray(at, w);
        Hit h;
        if (sc.accel->intersect(r, h)) {
            SurfaceInteraction si = sc.interaction(h);
            vec3 Le = sc.lights.emitted(si, -w);
            float cos_t = glm::dot(w, n), bpdf = cos_t / kPi;
            if (cos_t > 0.f && Le.x > 0.f) {
                eb = double(Le.x) * cos_t / bpdf;
                float lpdf = sc.lights.pdf_li(ref, si);
                wb = eb * double(bpdf * bpdf / (bpdf * bpdf + lpdf * lpdf));
            }
        }
        out.light.add(el);
        out.bsdf.add(eb);
        out.mis.add(wl + wb);
    }
    return out;
}

}  // namespace

TEST(AnalyticShapes, SphericalLightIrradianceIsPiLRSquaredOverDSquared) {
    const float L = 2.5f, radius = 0.5f;
    const double level = sidak_level(kAlpha, 9);
    int k = 0;
    for (float d : {0.8f, 3.f, 40.f}) {
        auto sc = make_scene({make_sphere(mat4(1.f), vec3(0.f), radius, false)}, {true}, vec3(L));
        vec3 n = glm::normalize(vec3(-1.f, 0.3f, 0.2f));
        vec3 ref = -d * n;  // the normal faces the centre
        double exact = kPiD * L * (radius / d) * (radius / d);
        IrradianceRun run = irradiance(*sc, ref, n, 200000, 50 + k);
        for (auto [name, st] : {std::pair<const char*, RunningStats*>{"light", &run.light}, {"bsdf", &run.bsdf},
                                {"mis", &run.mis}}) {
            MeanTest t = z_test(*st, exact, 1e-6 * exact);
            std::printf("  d = %g r: %-5s %s\n", d / radius, name, t.describe().c_str());
            // BSDF sampling hardly ever finds the far light: it is tested where it can be.
            if (std::string(name) == "bsdf" && d > 10.f) continue;
            EXPECT_GE(t.p_value, level) << name << " d " << d;
        }
        // Cone sampling is exact up to the cosine at the receiver: a tiny variance far away.
        EXPECT_LT(run.light.std_error() / exact, d > 10.f ? 1e-4 : 5e-3);
        ++k;
    }
    // Control: the same estimate against a 1% larger radius is rejected.
    auto sc = make_scene({make_sphere(mat4(1.f), vec3(0.f), radius, false)}, {true}, vec3(L));
    IrradianceRun run = irradiance(*sc, vec3(-3.f, 0.f, 0.f), vec3(1.f, 0.f, 0.f), 200000, 99);
    MeanTest wrong = z_test(run.light, kPiD * L * std::pow(radius * 1.01 / 3.0, 2));
    std::printf("  control (1%% larger radius): %s\n", wrong.describe().c_str());
    EXPECT_LT(wrong.p_value, 1e-6);
}

TEST(AnalyticShapes, OneSidedEmissionFollowsFlipNormals) {
    auto outward = make_scene({make_sphere(mat4(1.f), vec3(0.f), 1.f, false)}, {true});
    auto inward = make_scene({make_sphere(mat4(1.f), vec3(0.f), 1.f, true)}, {true});
    LightSample ls;
    int lit_out = 0, lit_in = 0, lit_in_inside = 0;
    PCG32 rng(5, 5);
    for (int i = 0; i < 1000; ++i) {
        vec2 u(rng.next_float(), rng.next_float());
        lit_out += outward->lights.sample_li(vec3(0, 0, 4), 0.5f, u, ls);
        lit_in += inward->lights.sample_li(vec3(0, 0, 4), 0.5f, u, ls);
        lit_in_inside += inward->lights.sample_li(vec3(0, 0.2f, 0.1f), 0.5f, u, ls);
    }
    EXPECT_EQ(lit_out, 1000);
    EXPECT_EQ(lit_in, 0);          // an inward-facing light is dark from outside
    EXPECT_EQ(lit_in_inside, 1000);  // and lights its inside
}

// ---- scene file ------------------------------------------------------------------------------------

namespace {

std::string write_xml(const std::string& name, const std::string& shapes) {
    std::string path = std::string(::testing::TempDir()) + "/" + name;
    std::ofstream(path) << "<scene version=\"3.0.0\">\n" << shapes << "</scene>\n";
    return path;
}

std::string load_error(const std::string& path) {
    try {
        load_scene(path);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(AnalyticShapes, XmlReadsSphereDiskCylinderWithMitsubaDefaults) {
    std::string path = write_xml("analytic_ok.xml",
                                 "  <shape type=\"sphere\" id=\"ball\">\n"
                                 "    <point name=\"center\" x=\"1\" y=\"0\" z=\"0\"/>\n"
                                 "    <float name=\"radius\" value=\"2\"/>\n"
                                 "    <emitter type=\"area\"><rgb name=\"radiance\" value=\"3\"/></emitter>\n"
                                 "  </shape>\n"
                                 "  <shape type=\"sphere\">\n"
                                 "    <transform name=\"to_world\"><scale value=\"2\"/><translate x=\"1\"/></transform>\n"
                                 "    <boolean name=\"flip_normals\" value=\"true\"/>\n"
                                 "  </shape>\n"
                                 "  <shape type=\"disk\"/>\n"
                                 "  <shape type=\"cylinder\"><point name=\"p1\" x=\"0\" y=\"3\" z=\"0\"/></shape>\n");
    SceneDescription d = load_scene(path);
    ASSERT_EQ(d.analytic.size(), 4u);
    EXPECT_EQ(d.shapes[0].name, "ball");
    EXPECT_EQ(d.shapes[0].emitter, 0);
    EXPECT_NEAR(d.analytic[0].center.x, 1.f, 1e-6f);
    EXPECT_NEAR(d.analytic[0].radius, 2.f, 1e-6f);
    EXPECT_NEAR(d.analytic[1].center.x, 1.f, 1e-6f);  // scale, then translate (Mitsuba's order)
    EXPECT_NEAR(d.analytic[1].radius, 2.f, 1e-6f);
    EXPECT_TRUE(d.analytic[1].flip);
    EXPECT_NEAR(d.analytic[2].area, kPi, 1e-6f);  // unit disk
    EXPECT_NEAR(d.analytic[3].radius, 1.f, 1e-6f);
    EXPECT_NEAR(d.analytic[3].length, 3.f, 1e-6f);
    auto sc = build_scene(std::move(d));
    EXPECT_FALSE(sc->lights.empty());
}

TEST(AnalyticShapes, XmlBadInputIsOneLineWithFileAndLine) {
    struct Case {
        const char* name;
        const char* xml;
        const char* line;
        const char* what;
    } cases[] = {
        {"neg_radius.xml", "  <shape type=\"sphere\">\n    <float name=\"radius\" value=\"-1\"/>\n  </shape>\n", ":3:", "radius"},
        {"nan_radius.xml", "  <shape type=\"cylinder\">\n    <float name=\"radius\" value=\"nan\"/>\n  </shape>\n", ":3:", "radius"},
        {"zero_radius.xml", "  <shape type=\"sphere\">\n    <float name=\"radius\" value=\"0\"/>\n  </shape>\n", ":3:", "radius"},
        {"singular.xml",
         "  <shape type=\"disk\">\n    <transform name=\"to_world\"><scale x=\"1\" y=\"0\" z=\"1\"/></transform>\n  </shape>\n",
         ":3:", "singular"},
        {"nonuniform.xml",
         "  <shape type=\"sphere\">\n    <transform name=\"to_world\"><scale x=\"1\" y=\"2\" z=\"1\"/></transform>\n  </shape>\n",
         ":3:", "uniformly"},
        {"same_ends.xml", "  <shape type=\"cylinder\">\n    <point name=\"p1\" x=\"0\" y=\"0\" z=\"0\"/>\n  </shape>\n", ":3:",
         "p0 and p1"},
        {"typo.xml", "  <shape type=\"sphere\">\n    <float name=\"raduis\" value=\"1\"/>\n  </shape>\n", ":3:", "raduis"},
    };
    for (const Case& c : cases) {
        std::string path = write_xml(c.name, c.xml);
        std::string e = load_error(path);
        std::printf("  %s\n", e.c_str());
        EXPECT_NE(e.find(path + c.line), std::string::npos) << c.name << ": " << e;
        EXPECT_NE(e.find(c.what), std::string::npos) << c.name << ": " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << c.name;
    }
}

// ---- agreement with Mitsuba 3 ----------------------------------------------------------------------
//
// tests/data/scenes/analytic.xml (diffuse, glass and mirrored spheres, a spherical light, an
// elliptical disk light, a diffuse disk, an open two-sided cylinder, a floor) against the mean of 16
// Mitsuba 3.9.1 llvm_ad_rgb renders of 2048 spp at 48 x 48 and the variance of that mean, made by
//   $PY tests/data/make_reference.py tests/data/scenes/analytic.xml --res 48 --batches 16 --spp 2048
//       --out tests/data/analytic48
// candela renders 8 batches of 128 spp; block z-test on 8 x 8 blocks (Sidak over blocks and
// channels) plus a whole-image z-test per channel. Control: the spherical light 3% dimmer must fail.

namespace {

ImageEstimate load_analytic_reference() { return ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/analytic48"); }

ImageEstimate render_analytic(float sphere_light_scale) {
    auto built = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/analytic.xml", {{"res", "48"}}));
    SceneParams p = built->params();
    for (const Shape& s : built->shapes)
        if (s.name == "sphere_light") p.emitters[size_t(s.emitter)].radiance *= sphere_light_scale;
    return candela::test::render_batch_estimate(*built, p, 8, 128);
}

}  // namespace

TEST(AnalyticShapes, MitsubaAgreementRender) {
    ImageEstimate ref = load_analytic_reference();
    ASSERT_EQ(ref.width, 48);
    ImageEstimate test = render_analytic(1.f);
    BlockTestResult r = block_z_test(test, ref, 8, kAlpha);
    dvec3 rel;
    double p = whole_image_p(test, ref, &rel);
    std::printf("  blocks: %s\n  whole image: p = %.3g, relative difference (%.4f, %.4f, %.4f)\n", r.describe().c_str(), p,
                rel.x, rel.y, rel.z);
    EXPECT_TRUE(r.passed(kAlpha)) << r.describe();
    EXPECT_GE(p, kAlpha);
}

TEST(AnalyticShapes, MitsubaAgreementDetectsDimmerSphereLight) {
    ImageEstimate ref = load_analytic_reference();
    ImageEstimate test = render_analytic(0.97f);
    BlockTestResult r = block_z_test(test, ref, 8, kAlpha);
    double p = whole_image_p(test, ref, nullptr);
    std::printf("  sphere light 3%% dimmer: blocks %s, whole image p = %.3g\n", r.describe().c_str(), p);
    EXPECT_TRUE(!r.passed(kAlpha) || p < kAlpha);
}

// The analytic shapes sit in a BVH over their boxes: for thousands of overlapping spheres, disks and
// cylinders, closest hits and shadow tests must be exactly those of testing every shape in turn.
TEST(AnalyticShapes, BvhOverShapesEqualsTestingEachShape) {
    PCG32 rng(7, 11);
    auto u = [&] { return rng.next_float(); };
    std::vector<AnalyticShape> shapes;
    for (int i = 0; i < 3000; ++i) {
        vec3 c(20.f * u() - 10.f, 20.f * u() - 10.f, 20.f * u() - 10.f);
        if (i % 3 == 0) shapes.push_back(make_sphere(mat4(1.f), c, 0.05f + 0.5f * u(), false));
        else if (i % 3 == 1)
            shapes.push_back(make_disk(translation(c) * rotation(360.f * u(), glm::normalize(vec3(u(), u(), u()) + 0.1f)) *
                                           scaling(vec3(0.1f + 0.4f * u())),
                                       false));
        else
            shapes.push_back(make_cylinder(mat4(1.f), c, c + vec3(u() - 0.5f, u() - 0.5f, u() - 0.5f), 0.05f + 0.2f * u(), false));
    }
    Mesh empty;
    WithAnalyticAccel accel(make_accel("kdtree", empty), shapes);
    int hits = 0, blocked = 0;
    for (int r = 0; r < 4000; ++r) {
        Ray ray;
        ray.o = vec3(30.f * u() - 15.f, 30.f * u() - 15.f, 30.f * u() - 15.f);
        ray.d = glm::normalize(vec3(u() - 0.5f, u() - 0.5f, u() - 0.5f));
        ray.tmax = r % 2 ? kInfinity : 5.f + 10.f * u();
        // Reference: every shape in index order, the nearest wins.
        Ray ref_ray = ray;
        Hit ref;
        bool ref_found = false;
        for (uint32_t i = 0; i < shapes.size(); ++i)
            if (intersect_analytic(shapes[i], ref_ray, ref)) {
                ref.prim = i;
                ref_found = true;
            }
        bool ref_blocked = false;
        for (const AnalyticShape& s : shapes) ref_blocked = ref_blocked || occluded_analytic(s, ray);
        Ray bvh_ray = ray;
        Hit h;
        const bool found = accel.intersect(bvh_ray, h);
        ASSERT_EQ(found, ref_found) << r;
        ASSERT_EQ(accel.occluded(ray), ref_blocked) << r;
        if (found) {
            ASSERT_EQ(h.t, ref.t) << r;
            ASSERT_EQ(h.prim, ref.prim) << r;
            ++hits;
        }
        blocked += ref_blocked;
    }
    // Both outcomes occur often enough for the comparison to mean something.
    EXPECT_GT(hits, 400);
    EXPECT_LT(hits, 3600);
    EXPECT_GT(blocked, 400);
}
