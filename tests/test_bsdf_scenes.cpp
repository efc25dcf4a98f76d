// Lossless BSDFs in a white furnace: every path ends on an emitting enclosure of radiance 1, and a
// smooth dielectric or a perfect mirror loses nothing, so each pixel's expected value is known
// exactly, whatever the sampling strategy:
//   * camera in air, looking at glass, diamond and a mirror: 1. Each refraction scales radiance by
//     (n_from / n_to)^2 in Radiance mode, and a path that ends where it started crosses every
//     interface as often inwards as outwards, so the factors cancel -- under any convention.
//   * camera inside a glass sphere (eta 1.5): 1.5^2. A lossless dielectric in equilibrium with an
//     enclosure of radiance L holds radiance eta^2 L; the camera path makes one more outward
//     crossing than inward ones, whose weight T_s / eta_r^2 = 1.5^2 is the one left over.
//   * camera inside an air bubble in glass (the enclosure's radiance given in the glass): 1 / 1.5^2.
// The last two fail under a dropped or inverted eta^2 scaling (controls below), and every case
// fails when a Fresnel branch's weight is off (a perturbed reflectance, also a control). Together
// they check the dielectric's Fresnel split, its radiance scaling, Russian roulette with eta, and
// MIS through delta lobes, end to end.
#include <gtest/gtest.h>
#include <cstdio>
#include <memory>
#include "film/film.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

// An icosphere, subdivided `subdiv` times, wound outwards (inwards when `inward`).
void add_sphere(SceneDescription& s, const char* name, vec3 c, float r, int subdiv, bool inward, uint32_t mat, int32_t emitter) {
    const float t = (1.f + std::sqrt(5.f)) / 2.f;
    std::vector<vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (vec3& p : v) p = glm::normalize(p);
    std::vector<uvec3> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                            {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (int k = 0; k < subdiv; ++k) {
        std::vector<uvec3> nf;
        for (uvec3 tri : f) {
            uint32_t m[3];
            for (int e = 0; e < 3; ++e) {
                v.push_back(glm::normalize(v[tri[e]] + v[tri[(e + 1) % 3]]));
                m[e] = uint32_t(v.size() - 1);
            }
            nf.push_back({tri.x, m[0], m[2]});
            nf.push_back({tri.y, m[1], m[0]});
            nf.push_back({tri.z, m[2], m[1]});
            nf.push_back({m[0], m[1], m[2]});
        }
        f = nf;
    }
    std::vector<vec3> pos, nrm;
    for (vec3 p : v) {
        pos.push_back(c + r * p);
        nrm.push_back(inward ? -p : p);
    }
    for (uvec3& tri : f) {
        vec3 n = glm::cross(pos[tri.y] - pos[tri.x], pos[tri.z] - pos[tri.x]);
        vec3 mid = (pos[tri.x] + pos[tri.y] + pos[tri.z]) / 3.f - c;
        if ((glm::dot(n, mid) < 0.f) != inward) std::swap(tri.y, tri.z);
    }
    s.add_shape(name, pos, nrm, f, mat, emitter);
}

// Per sampling mode, the image mean of a render of `s` (all pixels share one expected value) with
// its standard error from the pixel spread: per pixel the samples are all equal unless Russian
// roulette reweighted them, so the pixel means are the independent, nearly normal samples.
struct FurnaceRun {
    const char* mode;
    RunningStats px;
    uint64_t nonfinite;
};
std::vector<FurnaceRun> render_modes(SceneDescription s, int spp) {
    std::vector<FurnaceRun> out;
    for (SamplingMode mode : {SamplingMode::Mis, SamplingMode::Light, SamplingMode::Bsdf}) {
        s.settings.sampling = mode;
        Film film(s.settings.width, s.settings.height);
        Renderer::render_pass(*build_scene(s), film, 0, spp, 0);
        FurnaceRun r{mode == SamplingMode::Mis ? "mis" : mode == SamplingMode::Light ? "light" : "bsdf", {},
                     film.nonfinite_count()};
        for (int y = 0; y < film.height(); ++y)
            for (int x = 0; x < film.width(); ++x) {
                vec3 p = film.pixel(x, y);
                r.px.add((p.x + p.y + p.z) / 3.0);
            }
        out.push_back(r);
    }
    return out;
}

SceneDescription furnace_base(const char* source) {
    SceneDescription s;
    s.source = source;
    s.camera.fov_deg = 60.f;
    s.settings.width = 32;
    s.settings.height = 24;
    s.settings.rr_depth = 3;
    s.emitters.push_back({vec3(1.f)});
    return s;
}

DielectricBsdf dielectric(float int_ior, float ext_ior) {
    DielectricBsdf d;
    d.int_ior = int_ior;
    d.ext_ior = ext_ior;
    return d;
}

// The camera at the centre of a glass sphere (radius 3, eta 1.5 against the enclosure's vacuum)
// that holds a diamond (2.42 in glass) and a mirror. In a sphere a ray keeps its distance b from
// the centre between bounces, and a ray out of the diamond or off the mirror has b <= 1.64, below
// the 3 / 1.5 = 2 where total internal reflection at the glass wall starts: no path is trapped in
// a whispering-gallery mode (which would hold no radiance from the enclosure, and whose Russian
// roulette weights would have unbounded variance).
SceneDescription camera_in_glass(float glass_reflectance = 1.f, float glass_transmittance = 1.f) {
    SceneDescription s = furnace_base("<furnace: camera in glass>");
    DielectricBsdf glass = dielectric(1.5f, 1.f);
    glass.specular_reflectance = vec3(glass_reflectance);
    glass.specular_transmittance = vec3(glass_transmittance);
    s.materials = {{"emitter", DiffuseBsdf{vec3(0.f)}, false},
                   {"glass", glass, false},
                   {"diamond", dielectric(2.42f, 1.5f), false},
                   {"mirror", ConductorBsdf{}, true}};
    add_sphere(s, "furnace", vec3(0.f), 10.f, 2, true, 0, 0);
    add_sphere(s, "glass", vec3(0.f), 3.f, 3, false, 1, -1);
    add_sphere(s, "diamond", vec3(0.f, 0.f, -1.2f), 0.5f, 2, false, 2, -1);
    add_sphere(s, "mirror", vec3(0.8f, 0.3f, -0.9f), 0.4f, 2, false, 3, -1);
    s.camera.to_world = look_at(vec3(0.f), vec3(0.f, 0.f, -1.f), vec3(0.f, 1.f, 0.f));
    return s;
}

// The camera off-centre in an air bubble (radius 3) inside glass: the bubble's material has air
// inside and glass (1.5) outside, and the enclosure emits radiance 1 into the glass. From the less
// dense side there is no total internal reflection, so nothing can be trapped; a diamond (2.42 in
// air) and a mirror float in the bubble.
SceneDescription camera_in_bubble() {
    SceneDescription s = furnace_base("<furnace: camera in an air bubble>");
    s.materials = {{"emitter", DiffuseBsdf{vec3(0.f)}, false},
                   {"bubble", dielectric(1.f, 1.5f), false},
                   {"diamond", dielectric(2.42f, 1.f), false},
                   {"mirror", ConductorBsdf{}, true}};
    add_sphere(s, "furnace", vec3(0.f), 10.f, 2, true, 0, 0);
    add_sphere(s, "bubble", vec3(0.f), 3.f, 3, false, 1, -1);
    add_sphere(s, "diamond", vec3(-0.6f, 0.f, 0.f), 0.7f, 1, false, 2, -1);
    add_sphere(s, "mirror", vec3(0.8f, 0.5f, -0.5f), 0.5f, 2, false, 3, -1);
    s.camera.to_world = look_at(vec3(0.4f, 0.3f, 2.f), vec3(0.f), vec3(0.f, 1.f, 0.f));
    return s;
}

}  // namespace

TEST(BsdfScenes, LosslessFurnace) {
    SceneDescription s = furnace_base("<furnace>");
    s.materials = {{"emitter", DiffuseBsdf{vec3(0.f)}, false},
                   {"glass", dielectric(1.5f, 1.000277f), false},
                   {"diamond", dielectric(2.42f, 1.000277f), false},
                   {"mirror", ConductorBsdf{}, true}};
    add_sphere(s, "furnace", vec3(0.f), 10.f, 2, true, 0, 0);
    add_sphere(s, "glass", vec3(-1.2f, 0.f, 0.f), 1.f, 3, false, 1, -1);   // smooth normals
    add_sphere(s, "diamond", vec3(1.2f, 0.f, 0.f), 1.f, 1, false, 2, -1);  // coarse: many facets
    add_sphere(s, "mirror", vec3(0.f, 1.3f, -1.f), 0.5f, 2, false, 3, -1);
    s.camera.to_world = look_at(vec3(0.f, 0.f, 5.f), vec3(0.f), vec3(0.f, 1.f, 0.f));

    const double level = sidak_level(0.01, 3);
    for (const FurnaceRun& r : render_modes(s, 64)) {
        MeanTest t = z_test(r.px, 1.0, 1e-6);
        EXPECT_GE(t.p_value, level) << r.mode << ": " << t.describe();
        EXPECT_EQ(r.nonfinite, 0u);
        std::printf("  furnace (%s): mean %.5f (se %.5f)\n", r.mode, r.px.mean(), r.px.std_error());
    }
}

// Radiance inside a lossless dielectric in equilibrium with the enclosure: eta^2 L in glass,
// L / eta^2 in a bubble. Controls: the values that a dropped eta^2 (or one that cancels: 1) and an
// inverted one (1 / eta^2 in glass, eta^2 in the bubble) would give must be rejected.
TEST(BsdfScenes, LosslessFurnaceInsideDielectrics) {
    struct Case {
        const char* name;
        SceneDescription scene;
        double expected, wrong_inverted;
    };
    const double eta2 = 1.5 * 1.5;
    Case cases[] = {{"camera in glass", camera_in_glass(), eta2, 1.0 / eta2},
                    {"camera in bubble", camera_in_bubble(), 1.0 / eta2, eta2}};
    const double level = sidak_level(0.01, 6);
    for (Case& c : cases) {
        for (const FurnaceRun& r : render_modes(c.scene, 256)) {
            MeanTest t = z_test(r.px, c.expected, 1e-6);
            EXPECT_GE(t.p_value, level) << c.name << ", " << r.mode << ": " << t.describe();
            EXPECT_EQ(r.nonfinite, 0u) << c.name << ", " << r.mode;
            MeanTest dropped = z_test(r.px, 1.0, 1e-6), inverted = z_test(r.px, c.wrong_inverted, 1e-6);
            EXPECT_LT(dropped.p_value, 1e-9) << c.name << ", " << r.mode << ": " << dropped.describe();
            EXPECT_LT(inverted.p_value, 1e-9) << c.name << ", " << r.mode << ": " << inverted.describe();
            std::printf("  %s (%s): mean %.5f (se %.5f, expected %.5f), p = %.3g; without eta^2 p = %.3g\n", c.name,
                        r.mode, r.px.mean(), r.px.std_error(), c.expected, t.p_value, dropped.p_value);
        }
    }
}

// Controls: the glass's Fresnel branch weights perturbed, through its reflectance and
// transmittance (f / pdf = 0.9 for reflection, 0.99 for refraction, where the Fresnel split must
// give 1 and T_s / eta_r^2), are rejected: the camera-in-glass case is sensitive to the branch
// weights, not only to the eta^2 factors. Reflection is the weaker signal (at most a few percent of
// the wall hits reflect here), hence the larger perturbation.
TEST(BsdfScenes, LosslessFurnaceRejectsWrongFresnelWeights) {
    struct Perturbed {
        const char* name;
        float reflectance, transmittance;
    };
    for (const Perturbed& p : {Perturbed{"reflectance 0.9", 0.9f, 1.f}, Perturbed{"transmittance 0.99", 1.f, 0.99f}}) {
        SceneDescription s = camera_in_glass(p.reflectance, p.transmittance);
        for (const FurnaceRun& r : render_modes(s, 256)) {
            MeanTest t = z_test(r.px, 1.5 * 1.5, 1e-6);
            EXPECT_LT(t.p_value, 1e-6) << p.name << ", " << r.mode << ": " << t.describe();
            std::printf("  %s (%s): mean %.5f (se %.5f), p = %.3g\n", p.name, r.mode, r.px.mean(), r.px.std_error(),
                        t.p_value);
        }
    }
}
