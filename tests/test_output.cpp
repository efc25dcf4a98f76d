// Output that must not be lost or wrong: the time limit cuts the pass in flight and the image
// still has what was finished; PNG output of images wider than the GL limit, and the EXR written
// when GL fails; the viewer's fallback to headless when DISPLAY is unusable; scripts/run.sh.
#include <gtest/gtest.h>
#include <chrono>
#include <cstdlib>
#include "film/image_io.h"
#include "support/run.h"

using namespace candela;
using namespace candela::test;

namespace {

double reported_spp(const std::string& log) {
    size_t at = log.find(" spp in ");
    if (at == std::string::npos) return -1;
    size_t start = log.rfind(' ', at - 1);
    return std::atof(log.substr(start + 1, at - start - 1).c_str());
}

}  // namespace

// One pass of 512 x 512 x 256 samples takes about a minute; a tile of it (16 x 16 pixels) a
// fraction of a second. The limit cuts the pass, and the image keeps the tiles that finished.
TEST(TimeLimit, CutsThePassInFlight) {
    std::string d = temp_dir("time-limit");
    auto t0 = std::chrono::steady_clock::now();
    RunResult r = run_candela("--width 512 --height 512 --spp-per-frame 256 --frames 1 --time-limit 1 --threads 2 --out " +
                              d + "/t.exr");
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_LT(secs, 4.0) << "the time limit did not cut the pass: " << r.output;
    std::printf("--time-limit 1: ended after %.2f s\n", secs);
    EXPECT_NE(r.output.find("candela: time limit: <built-in Cornell box> 512x512, "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("the time limit cut the last pass short: "), std::string::npos) << r.output;
    double spp = reported_spp(r.output);
    EXPECT_GT(spp, 0.0) << r.output;
    EXPECT_LT(spp, 256.0) << r.output;
    // The finished tiles have all 256 samples (the box is lit: not black), the others none.
    Image img = read_linear_image(d + "/t.exr");
    ASSERT_EQ(img.width, 512);
    ASSERT_EQ(img.height, 512);
    size_t lit = 0;
    for (size_t p = 0; p < size_t(512 * 512); ++p) lit += img.rgb[3 * p] + img.rgb[3 * p + 1] + img.rgb[3 * p + 2] > 0.f;
    EXPECT_GT(lit, 0u);
    EXPECT_LT(lit, size_t(512 * 512));
}

// Passes shorter than the limit: the render stops between passes, the image has whole passes.
TEST(TimeLimit, StopsBetweenShortPasses) {
    std::string d = temp_dir("time-limit-passes");
    RunResult r = run_candela("--width 16 --height 16 --frames 100000000 --time-limit 0.5 --out " + d + "/t.exr");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("candela: time limit: "), std::string::npos) << r.output;
    EXPECT_GT(reported_spp(r.output), 0.0) << r.output;
}
