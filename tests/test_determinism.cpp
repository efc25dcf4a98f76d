// Same scene, seed and sample count: the same image bit for bit, whatever the thread count.
#include <gtest/gtest.h>
#include <cstring>
#include "film/image_io.h"
#include "integrator/path.h"
#include "sampling/sampler.h"
#include "render/launch.h"
#include "render/renderer.h"
#include "support/run.h"

using namespace candela;

TEST(Determinism, ProgramOneAndTwoThreadsBitwiseEqual) {
    std::string d = test::temp_dir("determinism");
    std::string common = "--width 48 --height 40 --frames 6 --spp-per-frame 2 --seed 7 --quiet";
    auto r1 = test::run_candela(common + " --threads 1 --out " + d + "/t1.exr");
    auto r2 = test::run_candela(common + " --threads 2 --out " + d + "/t2.exr");
    ASSERT_EQ(r1.exit_code, 0) << r1.output;
    ASSERT_EQ(r2.exit_code, 0) << r2.output;
    Image a = read_linear_image(d + "/t1.exr"), b = read_linear_image(d + "/t2.exr");
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    ASSERT_EQ(a.rgb.size(), size_t(48 * 40 * 3));
    EXPECT_EQ(std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)), 0);
    // A different seed must change the image (so the equality above is not vacuous).
    auto r3 = test::run_candela("--width 48 --height 40 --frames 6 --spp-per-frame 2 --seed 8 --quiet --threads 2 --out " +
                                d + "/t3.exr");
    ASSERT_EQ(r3.exit_code, 0) << r3.output;
    Image c = read_linear_image(d + "/t3.exr");
    EXPECT_NE(std::memcmp(a.rgb.data(), c.rgb.data(), a.rgb.size() * sizeof(float)), 0);
}

TEST(Determinism, PassSplitDoesNotMatter) {
    // 4 passes of 2 spp and 8 passes of 1 spp draw the same samples in the same order per pixel.
    SceneOverrides ov;
    ov.width = 24;
    ov.height = 24;
    std::shared_ptr<const Scene> scene = prepare_scene("", ov);
    const Scene& s = *scene;
    Film f1(24, 24), f2(24, 24);
    for (int p = 0; p < 4; ++p) Renderer::render_pass(s, f1, uint32_t(p * 2), 2, 2);
    for (int p = 0; p < 8; ++p) Renderer::render_pass(s, f2, uint32_t(p), 1, 1);
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
            ASSERT_EQ(f1.sample_count(x, y), 8u);
            dvec3 a = f1.pixel_sum(x, y), b = f2.pixel_sum(x, y);
            ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << x << "," << y;
        }
}

TEST(Determinism, DiffuseOnlySpecialisationDropsCodeNotSamples) {
    // The renderer instantiates the path tracer with DiffuseOnly = true when every material is
    // diffuse (issue 6). That instantiation must compute the very same radiance and ray count as the
    // general one, sample for sample, in every sampling mode.
    SceneOverrides ov;
    ov.width = 20;
    ov.height = 20;
    std::shared_ptr<const Scene> box = prepare_scene("", ov);  // the built-in Cornell box: all diffuse
    ASSERT_TRUE(scene_is_diffuse_only(*box));
    for (SamplingMode mode : {SamplingMode::Mis, SamplingMode::Light, SamplingMode::Bsdf}) {
        SceneParams p = box->params();
        p.settings.sampling = mode;
        std::shared_ptr<const Scene> scene = box->with_params(p);
        PathIntegrator integrator(*scene);
        PathStats ps_general, ps_special;
        int nonzero = 0;
        for (int y = 0; y < 20; ++y)
            for (int x = 0; x < 20; ++x)
                for (uint32_t s = 0; s < 4; ++s) {
                    IndependentSampler a(3), b(3);
                    a.start_pixel_sample(ivec2(x, y), s);
                    b.start_pixel_sample(ivec2(x, y), s);
                    Ray ra = scene->camera.generate_ray(vec2(float(x), float(y)) + a.next_2d());
                    Ray rb = scene->camera.generate_ray(vec2(float(x), float(y)) + b.next_2d());
                    vec3 La = integrator.Li<IndependentSampler, false>(ra, a, ps_general);
                    vec3 Lb = integrator.Li<IndependentSampler, true>(rb, b, ps_special);
                    ASSERT_EQ(std::memcmp(&La, &Lb, sizeof La), 0) << x << "," << y << " sample " << s;
                    nonzero += La != vec3(0.f);
                }
        EXPECT_EQ(ps_general.rays, ps_special.rays);
        // The comparison is not between black images. BSDF sampling alone sees light only on paths
        // that happen to hit the small emitter (~2% of them here); the other modes light every pixel.
        EXPECT_GT(nonzero, mode == SamplingMode::Bsdf ? 10 : 20 * 20 * 4 / 2) << "mode " << int(mode);
    }
    // A scene with a mirror and glass is not diffuse-only: it takes the general instantiation.
    auto glass = build_scene(load_scene(std::string(CANDELA_SOURCE_DIR) + "/scenes/cornell-materials/mirror-glass.xml"));
    EXPECT_FALSE(scene_is_diffuse_only(*glass));
}

TEST(SceneMemory, CountsWhatTheSceneHolds) {
    SceneOverrides ov;
    std::shared_ptr<const Scene> scene = prepare_scene("", ov);
    const Scene::Memory m = scene->memory();
    const Mesh& mesh = scene->mesh;
    EXPECT_EQ(m.triangles, 32u);
    EXPECT_TRUE(mesh.normals.empty());  // the box gives no normals: none are stored
    EXPECT_GE(m.mesh, mesh.positions.size() * sizeof(vec3) + 32 * (sizeof(uvec3) + sizeof(uint32_t)));
    EXPECT_EQ(m.accel, scene->accel->memory_bytes());
    EXPECT_GT(m.accel, 0u);
    EXPECT_GT(m.lights, 0u);
    EXPECT_EQ(m.total(), m.mesh + m.accel + m.lights);
}
