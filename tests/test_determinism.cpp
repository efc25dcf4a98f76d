// Same scene, seed and sample count: the same image bit for bit, whatever the thread count.
#include <gtest/gtest.h>
#include <cstring>
#include "film/image_io.h"
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
    std::shared_ptr<Scene> scene = prepare_scene("", ov);
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
