#include "support/agreement.h"
#include <gtest/gtest.h>
#include <cmath>
#include <cstdio>
#include <map>
#include "film/film.h"
#include "render/launch.h"

namespace candela::test {

using namespace candela::stats;

ImageEstimate render_batches(const Scene& scene, const SceneParams& p, int K, int spp, uint64_t base) {
    std::vector<std::unique_ptr<Film>> films;
    std::vector<const Film*> ptrs;
    for (int b = 0; b < K; ++b) {
        SceneParams q = p;
        q.settings.seed = base + uint64_t(b) + 1;
        q.settings.spp = spp;
        films.push_back(std::make_unique<Film>(p.settings.width, p.settings.height));
        Renderer::render_pass(*scene.with_params(q), *films.back(), 0, uint32_t(spp), 2);
        ptrs.push_back(films.back().get());
    }
    return ImageEstimate::from_batches(ptrs);
}

ImageEstimate scaled(ImageEstimate e, double s) {
    for (dvec3& m : e.mean) m *= s;
    for (dvec3& v : e.var_of_mean) v *= s * s;
    return e;
}

void expect_agreement(const ImageEstimate& a, const ImageEstimate& b, const std::string& what, int tests, bool control,
                      double alpha) {
    const double level = sidak_level(alpha, tests);
    BlockTestResult r = block_z_test(a, b, 4, level);
    dvec3 rel;
    const double p_whole = whole_image_p(a, b, &rel);
    std::printf("  %-26s block %s\n  %-26s whole-image p = %.3g (rel %+.4f %+.4f %+.4f)\n", what.c_str(),
                r.describe().c_str(), what.c_str(), p_whole, rel.x, rel.y, rel.z);
    EXPECT_TRUE(r.passed(level)) << what << ": " << r.describe();
    EXPECT_GE(p_whole, level) << what;
    if (control) {
        const double p_ctl = whole_image_p(scaled(a, 1.03), b);
        std::printf("  %-26s control (3%% brighter): whole-image p = %.3g\n", what.c_str(), p_ctl);
        EXPECT_LT(p_ctl, level) << what << ": the 3% brighter control is not rejected";
    }
}

void icosphere(int subdiv, std::vector<dvec3>& v, std::vector<glm::uvec3>& f) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (dvec3& p : v) p = glm::normalize(p);
    f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
         {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (int s = 0; s < subdiv; ++s) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            return mid[key] = uint32_t(v.size() - 1);
        };
        std::vector<glm::uvec3> g;
        for (const glm::uvec3& tri : f) {
            uint32_t ab = midpoint(tri.x, tri.y), bc = midpoint(tri.y, tri.z), ca = midpoint(tri.z, tri.x);
            g.insert(g.end(), {{tri.x, ab, ca}, {tri.y, bc, ab}, {tri.z, ca, bc}, {ab, bc, ca}});
        }
        f = g;
    }
    for (glm::uvec3& tri : f) {
        dvec3 a = v[tri.x], b = v[tri.y], c = v[tri.z];
        if (glm::dot(glm::cross(b - a, c - a), a + b + c) > 0) std::swap(tri.y, tri.z);  // was outward
    }
}

double furnace_exact(double a, double Le, int depth) {
    if (depth < 0) return Le / (1.0 - a);
    return Le * (1.0 - std::pow(a, depth + 1)) / (1.0 - a);
}

std::unique_ptr<SceneDescription> furnace_description(const FurnaceConfig& c) {
    auto sc = std::make_unique<SceneDescription>();
    sc->source = "<furnace>";
    std::vector<dvec3> v;
    std::vector<glm::uvec3> f;
    icosphere(1, v, f);
    std::vector<vec3> pos;
    for (const dvec3& p : v) pos.push_back(vec3(c.center + c.radius * p));  // rounded once, to float
    sc->materials.push_back(Material{"inside", DiffuseBsdf{kFurnaceAlbedo}, false});
    sc->emitters.push_back(AreaEmitter{vec3(1.f)});
    sc->add_shape("sphere", pos, {}, f, 0, 0);
    sc->settings.width = sc->settings.height = c.res;
    sc->settings.max_depth = c.max_depth;
    sc->settings.sampling = c.mode;
    sc->settings.integrator.type = c.integrator;
    sc->settings.seed = c.seed;
    vec3 o(c.center);
    sc->camera.to_world = look_at(o, o + vec3(0.f, 0.f, float(c.radius)), vec3(0.f, 1.f, 0.f));
    sc->camera.fov_deg = 90.f;
    sc->camera.near_clip = float(1e-3 * c.radius);
    sc->camera.far_clip = float(10.0 * c.radius);
    return sc;
}

namespace {

// The diffuse box of smooth_ball_description, the lamp's material and an emitter of radiance L,
// and the camera.
SceneDescription open_box(int res, float L) {
    SceneDescription d;
    d.source = "<open box>";
    d.materials.push_back(Material{"white", DiffuseBsdf{vec3(0.6f)}, false});
    d.materials.push_back(Material{"red", DiffuseBsdf{vec3(0.6f, 0.15f, 0.1f)}, false});
    d.materials.push_back(Material{"green", DiffuseBsdf{vec3(0.1f, 0.5f, 0.15f)}, false});
    d.materials.push_back(Material{"lamp", DiffuseBsdf{vec3(0.f)}, false});
    d.emitters.push_back(AreaEmitter{vec3(L)});
    // A quad from corner o along a and b, facing cross(a, b) (into the box).
    auto quad = [&](const char* name, vec3 o, vec3 a, vec3 b, uint32_t material) {
        d.add_shape(name, {o, o + a, o + a + b, o + b}, {}, {uvec3(0, 1, 2), uvec3(0, 2, 3)}, material, -1);
    };
    quad("floor", vec3(-3, 0, -3), vec3(0, 0, 6), vec3(6, 0, 0), 0);
    quad("back", vec3(-3, 0, -3), vec3(6, 0, 0), vec3(0, 5, 0), 0);
    quad("left", vec3(-3, 0, -3), vec3(0, 5, 0), vec3(0, 0, 6), 1);
    quad("right", vec3(3, 0, -3), vec3(0, 0, 6), vec3(0, 5, 0), 2);
    d.settings.width = d.settings.height = res;
    d.camera.to_world = look_at(vec3(0.f, 2.2f, 6.5f), vec3(0.f, 1.4f, -1.f), vec3(0.f, 1.f, 0.f));
    d.camera.fov_deg = 60.f;
    return d;
}

}  // namespace

SceneDescription smooth_ball_description(int res) {
    SceneDescription d = open_box(res, 4.f);
    d.source = "<smooth ball light>";
    std::vector<dvec3> v;
    std::vector<glm::uvec3> f;
    icosphere(0, v, f);
    for (glm::uvec3& t : f) std::swap(t.y, t.z);  // icosphere() winds inwards: outwards here
    const vec3 centre(0.6f, 2.f, -0.8f);
    std::vector<vec3> pos, nrm;
    for (const dvec3& p : v) {
        pos.push_back(centre + 0.7f * vec3(p));
        nrm.push_back(vec3(p));  // the sphere's normal: smooth shading over the 20 flat faces
    }
    d.add_shape("ball", pos, nrm, f, 3, 0);
    return d;
}

SceneDescription tilted_lamp_description(int res) {
    SceneDescription d = open_box(res, 8.f);
    d.source = "<tilted-normal lamp>";
    const float a = glm::radians(40.f);
    const vec3 n(std::sin(a), -std::cos(a), 0.f);
    const vec3 o(-0.6f, 4.f, -1.6f);
    d.add_shape("lamp", {o, o + vec3(1.2f, 0, 0), o + vec3(1.2f, 0, 1.2f), o + vec3(0, 0, 1.2f)}, {n, n, n, n},
                {uvec3(0, 1, 2), uvec3(0, 2, 3)}, 3, 0);
    return d;
}

SceneDescription lit_edge_description(int res) {
    SceneDescription d;
    d.source = "<lit edge>";
    d.materials.push_back({"wall", DiffuseBsdf{vec3(0.7f, 0.5f, 0.3f)}, false});
    d.materials.push_back({"lamp", DiffuseBsdf{vec3(0.f)}, false});
    d.emitters.push_back({vec3(6.f)});
    d.add_shape("wall", {vec3(-3, -3, 0), vec3(0, -3, 0), vec3(0, 3, 0), vec3(-3, 3, 0)}, {},
                {uvec3(0, 1, 2), uvec3(0, 2, 3)}, 0, -1);
    // A 0.4 x 0.4 lamp centred at (-1, 0, 0.7), facing the wall's edge at the origin.
    const vec3 c(-1.f, 0.f, 0.7f), n = glm::normalize(-c), t = glm::normalize(glm::cross(n, vec3(0, 1, 0))),
               b = glm::cross(t, n);
    const vec3 q[4] = {c - 0.2f * t - 0.2f * b, c + 0.2f * t - 0.2f * b, c + 0.2f * t + 0.2f * b, c - 0.2f * t + 0.2f * b};
    const bool faces = glm::dot(glm::cross(q[1] - q[0], q[2] - q[0]), n) > 0.f;
    d.add_shape("lamp", {q[0], q[1], q[2], q[3]}, {}, faces ? std::vector<uvec3>{uvec3(0, 1, 2), uvec3(0, 2, 3)}
                                                           : std::vector<uvec3>{uvec3(0, 2, 1), uvec3(0, 3, 2)}, 1, 0);
    d.camera.to_world = look_at(vec3(0.f, 0.f, 4.f), vec3(0.f), vec3(0.f, 1.f, 0.f));
    d.camera.fov_deg = 40.f;
    d.settings.width = d.settings.height = res;
    return d;
}

void expect_splat_film_deterministic(const Scene& base, int res, IntegratorType type, int max_depth) {
    for (const FilterDesc& f : {box_filter(), gaussian_filter()}) {
        SCOPED_TRACE(filter_name(f.type));
        SceneParams p = base.params();
        p.settings.integrator.type = type;
        p.settings.max_depth = max_depth;
        p.settings.filter = f;
        auto sc = base.with_params(p);
        Film a(res, res), b(res, res), c(res, res), d(res, res);
        Renderer::render_pass(*sc, a, 0, 4, 1);
        Renderer::render_pass(*sc, b, 0, 4, 2);
        for (uint32_t s = 0; s < 4; ++s) Renderer::render_pass(*sc, c, s, 1, 2);
        Renderer::render_pass(*sc, d, 0, 4, 3);
        ASSERT_FALSE(a.splat_sums().empty());
        EXPECT_EQ(a.splat_paths(), uint64_t(res) * uint64_t(res) * 4u);
        for (const Film* o : {&b, &c, &d}) {
            EXPECT_EQ(std::memcmp(a.splat_sums().data(), o->splat_sums().data(), a.splat_sums().size() * sizeof(dvec3)), 0);
            EXPECT_EQ(a.resolve(), o->resolve());
        }
        EXPECT_EQ(a.sample_count(3, 5), 4u);
    }
}

void expect_filtered_splats_agree(IntegratorType type, int spp, uint64_t seed_base) {
    auto sc = build_scene(lit_edge_description(16), "auto");
    const FilterDesc filters[] = {gaussian_filter(), mitchell_filter()};
    const double level = sidak_level(0.01, 2);
    SceneParams box = sc->params();
    box.settings.integrator.type = type;
    box.settings.filter = box_filter();
    const ImageEstimate unfiltered = render_batches(*sc, box, 8, spp, seed_base);
    uint64_t seed = seed_base;
    for (const FilterDesc& f : filters) {
        SceneParams p = sc->params();
        p.settings.filter = f;
        p.settings.integrator.type = IntegratorType::Path;
        // 16 batches (the block test takes the batch spread for a normal variance: 8 give heavy
        // tails), the path tracer's of 128 spp: the camera samples' sum(w L) / sum(w) is a ratio,
        // biased by O(1 / spp) where w and L vary together (edges, borders), which the batch means
        // do not average away.
        const ImageEstimate pt = render_batches(*sc, p, 16, 128, seed += 100);
        p.settings.integrator.type = type;
        const ImageEstimate it = render_batches(*sc, p, 16, spp, seed += 100);
        const std::string what = std::string(integrator_type_name(type)) + " " + filter_name(f.type);
        expect_agreement(it, pt, what, 2, false);
        const BlockTestResult ctl = block_z_test(unfiltered, pt, 4, level);
        std::printf("  %-26s control (box splats): block %s\n", what.c_str(), ctl.describe().c_str());
        EXPECT_FALSE(ctl.passed(level)) << what << ": the box-filtered image is not rejected";
    }
}

dvec3 expect_furnace_exact(const FurnaceConfig& c, double level) {
    auto sc = build_scene(std::move(*furnace_description(c)), "brute");
    Film film(c.res, c.res);
    Renderer::render_pass(*sc, film, 0, uint32_t(c.spp), 2);
    EXPECT_EQ(film.nonfinite_count(), 0u);
    dvec3 z(0.0);
    for (int k = 0; k < 3; ++k) {
        RunningStats s;
        for (int y = 0; y < c.res; ++y)
            for (int x = 0; x < c.res; ++x) s.add(film.pixel(x, y)[k]);
        const double exact = furnace_exact(kFurnaceAlbedo[k], 1.0, c.max_depth);
        MeanTest t = z_test(s, exact, 1e-5 * exact);
        MeanTest ctl = z_test(s, 1.03 * exact, 1e-5 * exact);
        std::printf("  depth %2d a=%.1f  %s\n  control (3%% off): p = %.3g\n", c.max_depth, kFurnaceAlbedo[k],
                    t.describe().c_str(), ctl.p_value);
        EXPECT_GE(t.p_value, level) << "depth " << c.max_depth << " channel " << k << ": " << t.describe();
        EXPECT_LT(t.std_error, 0.01 * exact) << "too noisy to reveal a bias";
        EXPECT_LT(ctl.p_value, level) << "depth " << c.max_depth << " channel " << k << ": control not rejected";
        z[k] = t.statistic;
    }
    return z;
}

}  // namespace candela::test
