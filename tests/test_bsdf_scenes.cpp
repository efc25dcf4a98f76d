// Lossless BSDFs in a white furnace: a camera inside an emitting sphere (radiance 1 on the inside)
// looks at a glass sphere, a diamond-like sphere and a perfect mirror. Every path ends on the
// emitter, and a lossless interface changes radiance only by the eta^2 of each crossing, which
// cancels on the way out: every pixel must be exactly 1 (within Monte Carlo noise), whatever the
// sampling strategy. Checks the dielectric's Fresnel split, its radiance scaling, Russian roulette
// with eta, and MIS through delta lobes, end to end.
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

}  // namespace

TEST(BsdfScenes, LosslessFurnace) {
    SceneDescription s;
    s.source = "<furnace>";
    DielectricBsdf glass;
    glass.int_ior = 1.5f;
    DielectricBsdf diamond;
    diamond.int_ior = 2.42f;
    s.materials = {{"emitter", DiffuseBsdf{vec3(0.f)}, false},
                   {"glass", glass, false},
                   {"diamond", diamond, false},
                   {"mirror", ConductorBsdf{}, true}};
    s.emitters.push_back({vec3(1.f)});
    add_sphere(s, "furnace", vec3(0.f), 10.f, 2, true, 0, 0);
    add_sphere(s, "glass", vec3(-1.2f, 0.f, 0.f), 1.f, 3, false, 1, -1);   // smooth normals
    add_sphere(s, "diamond", vec3(1.2f, 0.f, 0.f), 1.f, 1, false, 2, -1);  // coarse: many facets
    add_sphere(s, "mirror", vec3(0.f, 1.3f, -1.f), 0.5f, 2, false, 3, -1);
    s.camera.to_world = look_at(vec3(0.f, 0.f, 5.f), vec3(0.f), vec3(0.f, 1.f, 0.f));
    s.camera.fov_deg = 60.f;
    s.settings.width = 32;
    s.settings.height = 24;
    s.settings.rr_depth = 3;

    const int spp = 64;
    const double level = sidak_level(0.01, 3);
    for (SamplingMode mode : {SamplingMode::Mis, SamplingMode::Light, SamplingMode::Bsdf}) {
        s.settings.sampling = mode;
        Film film(s.settings.width, s.settings.height);
        Renderer::render_pass(*build_scene(s), film, 0, spp, 0);
        // Per pixel the samples are all exactly 1 unless Russian roulette reweighted them, so the
        // test is on the mean over the image with its standard error from the pixel spread.
        RunningStats px;
        for (int y = 0; y < film.height(); ++y)
            for (int x = 0; x < film.width(); ++x) {
                vec3 p = film.pixel(x, y);
                px.add((p.x + p.y + p.z) / 3.0);
            }
        MeanTest t = z_test(px, 1.0, 1e-6);
        const char* name = mode == SamplingMode::Mis ? "mis" : mode == SamplingMode::Light ? "light" : "bsdf";
        EXPECT_GE(t.p_value, level) << name << ": " << t.describe();
        EXPECT_EQ(film.nonfinite_count(), 0u);
        std::printf("  furnace (%s): mean %.5f (se %.5f)\n", name, px.mean(), px.std_error());
    }
}
