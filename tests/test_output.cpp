// Output that must not be lost or wrong: the time limit cuts the pass in flight and the image
// still has what was finished; PNG output of images wider than the GL limit, and the EXR written
// when GL fails; the viewer's fallback to headless when DISPLAY is unusable; scripts/run.sh.
#include <gtest/gtest.h>
#include <chrono>
#include <sys/stat.h>
#include <sys/wait.h>
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

namespace {
bool file_exists_plain(const std::string& path) {
    struct stat st;
    return stat(path.c_str(), &st) == 0;
}

// An X display number with no server behind it (no socket in /tmp/.X11-unix).
int unused_display() {
    for (int n = 87; n < 200; ++n)
        if (!file_exists_plain("/tmp/.X11-unix/X" + std::to_string(n))) return n;
    return -1;
}
}  // namespace

// DISPLAY set but unusable, no --out: the viewer cannot start, candela says why and renders
// headless to candela.png in the working directory, exit 0 (as with no DISPLAY at all).
TEST(DisplayFallback, UnusableDisplayRendersHeadless) {
    const int n = unused_display();
    ASSERT_GT(n, 0);
    // No server on a local socket; a refused TCP connection (port 6000 + n).
    for (const std::string& display : {":" + std::to_string(n), "127.0.0.1:" + std::to_string(n)}) {
        std::string d = temp_dir("display-fallback");
        RunResult r = run_shell("cd '" + d + "' && env -u WAYLAND_DISPLAY DISPLAY=" + display + " " + CANDELA_BIN +
                                " --width 12 --height 8 --frames 1");
        EXPECT_EQ(r.exit_code, 0) << display << ": " << r.output;
        EXPECT_NE(r.output.find("candela: cannot use the display (viewer: cannot initialise GLFW"), std::string::npos)
            << r.output;
        EXPECT_NE(r.output.find("; rendering headless to candela.png"), std::string::npos) << r.output;
        EXPECT_GT(read_bytes(d + "/candela.png").size(), 50u) << r.output;
    }
}

// scripts/run.sh, with stubs for setup.sh, build.sh and the program (which prints its arguments).
TEST(RunScript, AddsOutOnlyWhenThereIsNone) {
    std::string d = temp_dir("run-sh");
    ASSERT_EQ(std::system(("mkdir -p '" + d + "/scripts' '" + d + "/build/bin' && cp '" + std::string(CANDELA_SOURCE_DIR) +
                           "/scripts/run.sh' '" + d + "/scripts/'").c_str()),
              0);
    write_text(d + "/scripts/setup.sh", "exit 0\n");
    write_text(d + "/scripts/build.sh", "exit 0\n");
    write_text(d + "/build/bin/candela", "#!/bin/sh\nfor a in \"$@\"; do echo \"arg[$a]\"; done\n");
    ASSERT_EQ(std::system(("chmod +x '" + d + "/build/bin/candela'").c_str()), 0);
    auto run = [&](const std::string& env, const std::string& args) {
        return run_shell("env -u DISPLAY -u WAYLAND_DISPLAY " + env + " bash '" + d + "/scripts/run.sh' " + args);
    };
    RunResult r = run("", "s.xml --out x.exr");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output, "arg[s.xml]\narg[--out]\narg[x.exr]\n");
    r = run("", "--out=x.exr --frames 4");
    EXPECT_EQ(r.output, "arg[--out=x.exr]\narg[--frames]\narg[4]\n");
    r = run("", "s.xml --frames 4");
    EXPECT_EQ(r.output,
              "run.sh: no display: rendering headless to out/candela.png\narg[s.xml]\narg[--frames]\narg[4]\narg[--"
              "out]\narg[out/candela.png]\n");
    r = run("DISPLAY=:0", "s.xml");
    EXPECT_EQ(r.output, "arg[s.xml]\n");
}
