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

namespace {
// Width and height from a PNG's IHDR chunk.
bool png_size(const std::string& bytes, int& w, int& h) {
    if (bytes.size() < 24 || bytes.compare(1, 3, "PNG") != 0) return false;
    auto be32 = [&](size_t at) {
        return int((uint32_t(uint8_t(bytes[at])) << 24) | (uint32_t(uint8_t(bytes[at + 1])) << 16) |
                   (uint32_t(uint8_t(bytes[at + 2])) << 8) | uint32_t(uint8_t(bytes[at + 3])));
    };
    w = be32(16);
    h = be32(20);
    return true;
}
}  // namespace

// Asked for a 20000-pixel-wide PNG, the user gets it (the GL limit is 16384).
TEST(PngOutput, WiderThanTheGlLimit) {
    std::string d = temp_dir("png-wide");
    RunResult r = run_candela("--width 20000 --height 2 --frames 1 --out " + d + "/wide.png");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    int w = 0, h = 0;
    ASSERT_TRUE(png_size(read_bytes(d + "/wide.png"), w, h)) << r.output;
    EXPECT_EQ(w, 20000);
    EXPECT_EQ(h, 2);
}

// When GL fails, the render goes to an EXR beside the PNG, with a message and a non-zero exit.
TEST(PngOutput, GlFailureWritesTheExrInstead) {
    std::string d = temp_dir("png-fail");
    RunResult r = run_candela("--width 24 --height 16 --frames 2 --out " + d + "/x.png");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string earlier = read_bytes(d + "/x.png");
    r = run_candela("--width 24 --height 16 --frames 2 --out " + d + "/x.png", "CANDELA_TEST_FAIL_GL=1");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find(d + "/x.png: OSMesa: cannot create an OpenGL context"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(d + "/x.png not written; the image is in " + d + "/x.exr (linear EXR) instead"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("2 spp in "), std::string::npos) << r.output;
    EXPECT_EQ(read_bytes(d + "/x.png"), earlier);  // untouched
    Image img = read_linear_image(d + "/x.exr");
    EXPECT_EQ(img.width, 24);
    EXPECT_EQ(img.height, 16);
    double sum = 0;
    for (float v : img.rgb) sum += v;
    EXPECT_GT(sum, 0.0);
}
