// The camera's importance (scene/camera.h, "Importance"): We, pdf_We and sample_wi of the
// perspective, thin lens and orthographic cameras, on a film with a crop window, a principal
// point offset and a non-square aspect so that every term of the normalisation is exercised.
//
//  * Normalisation: the integral of We |cos theta| over directions (and the lens, or the film
//    plane) is 1, and the integral of pdf_We's densities is 1: Monte Carlo z-tests, Sidak-corrected
//    over the file's tests. Controls: We with a cosine dropped (1 / (A cos^3)) and a 3% larger We
//    are both rejected (their p-values are printed; below 1e-10 here).
//  * sample_wi against the camera's own rays: camera rays drawn uniformly over the image (and the
//    lens) through generate_ray hit a small tilted disk around a point with the probability
//    integral over the disk of (Wi / pdf) |cos theta_disk| dA (the light tracer's connection
//    weight as a density over the scene's area); binomial z-test, with 3% more importance as the
//    control that must be rejected.
//  * Geometry: the raster position sample_wi reports is the pixel whose camera ray (with the same
//    lens sample) passes through the point.
#include <gtest/gtest.h>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include "core/frame.h"
#include "sampling/pcg32.h"
#include "sampling/warp.h"
#include "scene/camera.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;
constexpr int kTests = 3 * 2 + 3;  // (We, pdf_We) x 3 cameras + the disk test x 3 cameras
const char* kNames[] = {"perspective", "thinlens", "orthographic"};

Camera make_camera(CameraType type) {
    Camera c;
    c.type = type;
    c.to_world = look_at(vec3(1.f, 2.f, -3.f), vec3(0.2f, 0.5f, 1.f), vec3(0.1f, 1.f, 0.f));
    if (type == CameraType::Orthographic) c.to_world = c.to_world * glm::scale(mat4(1.f), vec3(1.5f, 1.5f, 1.f));
    c.fov_deg = 50.f;
    c.fov_axis = FovAxis::X;
    c.near_clip = 0.1f;
    c.far_clip = 100.f;
    c.principal_point_offset = type == CameraType::Perspective ? vec2(0.05f, -0.03f) : vec2(0.f);
    if (type == CameraType::ThinLens) {
        c.aperture_radius = 0.2f;
        c.focus_distance = 4.f;
    }
    // A 40 x 30 window of a 64 x 40 film, rendered at its own size.
    c.film_size = ivec2(64, 40);
    c.crop_offset = ivec2(16, 6);
    c.crop_size = ivec2(40, 30);
    c.set_film_size(40, 30);
    return c;
}

// A point in front of the camera that projects inside the image.
vec3 scene_point(const Camera& c, PCG32& r) {
    for (;;) {
        vec2 raster(r.next_float() * 40.f, r.next_float() * 30.f);
        Ray ray = c.generate_ray(raster + vec2(16.f, 6.f), vec2(r.next_float(), r.next_float()));
        float t = 2.f + 6.f * r.next_float();
        vec3 p = ray.o + ray.d * t;
        CameraWiSample s;
        if (c.sample_wi(p, vec2(0.5f), s)) return p;
    }
}

struct Integrals {
    RunningStats we, we_cos3, pdf;
};

// Integral over the camera's directions (uniform sphere), its lens (uniform disk) or its film plane
// (a square around the image) of We cos, of the cosine-dropped variant, and of pdf_pos pdf_dir.
Integrals integrate(const Camera& c, int n, uint64_t seed) {
    PCG32 r(seed, 7);
    Integrals out;
    const vec3 o = vec3(c.to_world[3]), fwd = c.forward();
    for (int i = 0; i < n; ++i) {
        Ray ray;
        double inv_pdf;
        vec2 u(r.next_float(), r.next_float()), v(r.next_float(), r.next_float());
        if (c.type == CameraType::Orthographic) {
            // Uniform on the local square [-1.2, 1.2]^2 at z = near: area 5.76 x |X x Y|.
            vec2 l = 2.4f * u - 1.2f;
            ray.o = vec3(c.to_world * glm::vec4(l, c.near_clip, 1.f));
            ray.d = fwd;
            inv_pdf = 5.76 * double(glm::length(glm::cross(vec3(c.to_world[0]), vec3(c.to_world[1]))));
        } else {
            // Uniform in a cone of half-angle 40 degrees about the view axis, which holds the
            // image's directions from every lens point (We is 0 outside: the integral is unchanged).
            const float cos_max = std::cos(glm::radians(40.f));
            ray.d = Frame(fwd).to_world(square_to_uniform_cone(u, cos_max));
            inv_pdf = 2.0 * M_PI * (1.0 - double(cos_max));
            ray.o = o;
            if (c.needs_lens_sample()) {
                vec2 a = c.aperture_radius * square_to_uniform_disk_concentric(v);
                ray.o = vec3(c.to_world * glm::vec4(a, 0.f, 1.f));
                inv_pdf *= M_PI * double(c.aperture_radius * c.aperture_radius);
            }
        }
        const double cos_t = c.type == CameraType::Orthographic ? 1.0 : double(glm::dot(ray.d, fwd));
        const double we = double(c.We(ray));
        float pp, pd;
        c.pdf_We(ray, pp, pd);
        out.we.add(we * cos_t * inv_pdf);
        out.we_cos3.add(c.type == CameraType::Orthographic ? we * 1.03 * inv_pdf : we * cos_t * cos_t * inv_pdf);
        // pdf_We's densities over the same measure (the orthographic direction is a delta: 1).
        out.pdf.add(double(pp) * double(pd) * inv_pdf);
    }
    return out;
}

}  // namespace

TEST(CameraImportance, WeAndPdfWeIntegrateToOne) {
    const double level = sidak_level(kAlpha, kTests);
    for (int k = 0; k < 3; ++k) {
        Camera c = make_camera(CameraType(k));
        Integrals in = integrate(c, k == 2 ? 200000 : 600000, 17 + uint64_t(k));
        MeanTest we = z_test(in.we, 1.0), pdf = z_test(in.pdf, 1.0);
        // Controls: a dropped cosine (perspective, thin lens) or 3% more importance (orthographic).
        MeanTest ctl = z_test(in.we_cos3, 1.0);
        std::printf("  %-12s We: %s\n  %-12s pdf_We: %s\n  %-12s control: %s\n", kNames[k], we.describe().c_str(),
                    kNames[k], pdf.describe().c_str(), kNames[k], ctl.describe().c_str());
        EXPECT_GE(we.p_value, level) << kNames[k] << ": " << we.describe();
        EXPECT_GE(pdf.p_value, level) << kNames[k] << ": " << pdf.describe();
        EXPECT_LT(we.std_error, 0.005) << kNames[k] << ": too noisy to reveal a 3% error";
        EXPECT_LT(ctl.p_value, 1e-6) << kNames[k] << " control not rejected: " << ctl.describe();
    }
}

// pdf_We is the density of the camera's own rays: for the perspective camera, rays sampled
// uniformly over the image have the direction density 1 / (A cos^3), so E[1 / pdf_dir] over them
// is the solid angle the image subtends; for the thin lens the lens density is 1 / (pi r^2).
TEST(CameraImportance, PdfWeIsTheDensityOfGeneratedRays) {
    for (int k = 0; k < 2; ++k) {
        Camera c = make_camera(CameraType(k));
        PCG32 r(5, 7);
        RunningStats inv;
        for (int i = 0; i < 100000; ++i) {
            Ray ray = c.generate_ray(vec2(16.f + 40.f * r.next_float(), 6.f + 30.f * r.next_float()),
                                     vec2(r.next_float(), r.next_float()));
            if (c.needs_lens_sample()) ray.o -= ray.d * (c.near_clip / glm::dot(ray.d, c.forward()));  // back to the lens
            float pp, pd;
            c.pdf_We(ray, pp, pd);
            ASSERT_GT(pd, 0.f);
            if (c.needs_lens_sample()) {
                EXPECT_NEAR(pp, 1.0 / (M_PI * 0.04), 1e-3);
            }
            inv.add(1.0 / double(pd));
        }
        // The solid angle of the image seen from a lens point, averaged over the lens: a quadrature
        // over the image of |d omega / d raster| = A cos^3 / (image area in raster units).
        double omega = 0;
        const int g = 200, gl = c.needs_lens_sample() ? 4 : 1;
        for (int a = 0; a < gl * gl; ++a)
            for (int j = 0; j < g; ++j)
                for (int i = 0; i < g; ++i) {
                    vec2 film(16.f + 40.f * (float(i) + 0.5f) / g, 6.f + 30.f * (float(j) + 0.5f) / g);
                    Ray ray = c.generate_ray(film, vec2((float(a % gl) + 0.5f) / gl, (float(a / gl) + 0.5f) / gl));
                    float cos_t = glm::dot(ray.d, c.forward());
                    omega += double(cos_t * cos_t * cos_t) * double(c.importance_area()) / (g * g * gl * gl);
                }
        MeanTest t = z_test(inv, omega);
        std::printf("  %-12s E[1/pdf_dir] %s\n", kNames[k], t.describe().c_str());
        EXPECT_GE(t.p_value, 1e-3) << kNames[k] << ": " << t.describe();
    }
}

TEST(CameraImportance, SampleWiRasterIsThePixelWhoseRaySeesThePoint) {
    for (int k = 0; k < 3; ++k) {
        Camera c = make_camera(CameraType(k));
        PCG32 r(23, 7);
        int misses = 0;
        for (int i = 0; i < 2000; ++i) {
            vec3 p = scene_point(c, r);
            vec2 u(r.next_float(), r.next_float());
            CameraWiSample s;
            // Through another point of the lens, a point near the image's edge may fall outside it.
            if (!c.sample_wi(p, u, s)) {
                ++misses;
                continue;
            }
            EXPECT_GT(s.pdf, 0.f);
            EXPECT_NEAR(glm::distance(s.p - s.wi * s.dist, p), 0.f, 1e-4f * s.dist) << kNames[k];
            // The camera ray through that raster position (image pixels -> film pixels: + crop offset).
            Ray ray = c.generate_ray(s.raster + vec2(16.f, 6.f), u);
            vec3 q = p - ray.o;
            float off = glm::length(q - ray.d * glm::dot(q, ray.d));
            EXPECT_LT(off, 2e-4f * s.dist) << kNames[k] << " point " << i;
            EXPECT_NEAR(glm::dot(ray.d, -s.wi), 1.f, 1e-4f) << kNames[k];
        }
        EXPECT_LT(misses, c.needs_lens_sample() ? 100 : 1) << kNames[k];
        // Points behind the camera or off the image are not connected.
        CameraWiSample s;
        EXPECT_FALSE(c.sample_wi(vec3(c.to_world[3]) - 3.f * c.forward(), vec2(0.5f), s));
        EXPECT_EQ(s.pdf, 0.f);
    }
}

// The connection weight Wi / pdf as a density: a camera ray drawn uniformly over the image (and
// the lens) hits a small disk with probability integral_disk (Wi / pdf) |cos theta_disk| dA; with
// N rays, the hit count is binomial.
TEST(CameraImportance, SampleWiWeightIsTheDensityOfCameraRaysOverArea) {
    const double level = sidak_level(kAlpha, kTests);
    for (int k = 0; k < 3; ++k) {
        Camera c = make_camera(CameraType(k));
        PCG32 r(41 + uint64_t(k), 7);
        const vec3 centre = c.generate_ray(vec2(16.f + 27.f, 6.f + 11.f), vec2(0.5f)).o +
                            c.generate_ray(vec2(16.f + 27.f, 6.f + 11.f), vec2(0.5f)).d * 5.f;
        const vec3 n = glm::normalize(-c.forward() + vec3(0.4f, 0.3f, 0.f));  // tilted towards the camera
        const Frame fr(n);
        const float radius = k == 2 ? 0.25f : 0.35f;
        // Expected probability: quadrature over the disk (and the lens) of Wi / pdf |cos|.
        double expected = 0, expected_nocos = 0;
        const int gr = 24, ga = 48, gl = c.needs_lens_sample() ? 8 : 1;
        for (int i = 0; i < gr; ++i)
            for (int j = 0; j < ga; ++j) {
                const float rr = radius * std::sqrt((float(i) + 0.5f) / gr), phi = 2.f * kPi * (float(j) + 0.5f) / ga;
                const vec3 p = centre + fr.to_world(vec3(rr * std::cos(phi), rr * std::sin(phi), 0.f));
                for (int a = 0; a < gl; ++a)
                    for (int b = 0; b < gl; ++b) {
                        CameraWiSample s;
                        if (!c.sample_wi(p, vec2((float(a) + 0.5f) / gl, (float(b) + 0.5f) / gl), s)) continue;
                        const double cos_d = std::abs(glm::dot(s.wi, n)), cos_c = std::abs(glm::dot(s.wi, c.forward()));
                        const double w = double(s.Wi) / double(s.pdf) / (gl * gl);
                        expected += w * cos_d;
                        (void)cos_c;
                        expected_nocos += w * cos_d * 1.03;
                    }
            }
        const double area = M_PI * radius * radius / (gr * ga);
        expected *= area;
        expected_nocos *= area;
        const int N = 1000000;
        int hits = 0;
        for (int i = 0; i < N; ++i) {
            Ray ray = c.generate_ray(vec2(16.f + 40.f * r.next_float(), 6.f + 30.f * r.next_float()),
                                     vec2(r.next_float(), r.next_float()));
            const float denom = glm::dot(ray.d, n);
            const float t = glm::dot(centre - ray.o, n) / denom;
            if (!(t > 0.f)) continue;
            if (glm::length(ray.o + ray.d * t - centre) < radius) ++hits;
        }
        const double p_hat = double(hits) / N;
        MeanTest t = z_test(p_hat, std::sqrt(p_hat * (1 - p_hat) / N), expected);
        MeanTest ctl = z_test(p_hat, std::sqrt(p_hat * (1 - p_hat) / N), expected_nocos);
        std::printf("  %-12s hits %d: %s\n  %-12s control: %s\n", kNames[k], hits, t.describe().c_str(), kNames[k],
                    ctl.describe().c_str());
        EXPECT_GE(t.p_value, level) << kNames[k] << ": " << t.describe();
        EXPECT_LT(t.std_error, 0.01 * expected) << kNames[k] << ": too noisy to reveal a 3% error";
        EXPECT_LT(ctl.p_value, 1e-6) << kNames[k] << " control not rejected: " << ctl.describe();
    }
}
