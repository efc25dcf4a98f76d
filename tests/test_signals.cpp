// SIGINT and SIGTERM during a headless render: the image so far is written (atomically), the
// summary says how many spp it has, and the exit is clean (128 + the signal). With a checkpoint,
// the first signal finishes the pass and saves, a second one stops at once.
#include <gtest/gtest.h>
#include <cstdlib>
#include <cstring>
#include <thread>
#include "film/image_io.h"
#include "support/run.h"
#include "support/spawn.h"

using namespace candela;
using namespace candela::test;

namespace {

// The "N spp" of the summary line, or -1.
double reported_spp(const std::string& log) {
    size_t at = log.find(" spp in ");
    if (at == std::string::npos) return -1;
    size_t start = log.rfind(' ', at - 1);
    return std::atof(log.substr(start + 1, at - start - 1).c_str());
}

long checkpoint_spp(const std::string& path) {
    std::string b = read_bytes(path);
    if (b.size() < 64) return -1;
    uint32_t spp;
    std::memcpy(&spp, b.data() + 24, 4);
    return long(spp);
}

// A bumpy n x n grid of 2 (n - 1)^2 triangles, written fast: n = 1000 is a 61 MB OBJ that takes
// candela seconds to load and seconds more to build its k-d tree.
void write_big_obj(const std::string& path, int n) {
    FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) std::fprintf(f, "v %d %d %.3f\n", i, j, double((i * 7919 + j * 104729) % 1000) * 1e-3);
    for (int j = 0; j + 1 < n; ++j)
        for (int i = 0; i + 1 < n; ++i) {
            int a = j * n + i + 1;
            std::fprintf(f, "f %d %d %d\nf %d %d %d\n", a, a + 1, a + n, a + 1, a + n + 1, a + n);
        }
    std::fclose(f);
}

// A stop takes milliseconds on an idle machine; the bound leaves room for a loaded one (ctest -j2
// beside the k-d tree tests) and for the sanitizer build.
#ifdef CANDELA_SANITIZE
constexpr double kMaxStopSeconds = 6.0;
#else
constexpr double kMaxStopSeconds = 1.5;
#endif

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Signals a long render once it has been running for a while; checks the image and the summary.
void stop_render_with(int sig, const char* word) {
    std::string d = temp_dir(std::string("signal-") + word);
    Child c("--width 40 --height 30 --frames 1000000 --out " + d + "/x.exr", d + "/log");
    // The handlers are in place before the scene loads; the wait lets some passes finish.
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    ASSERT_TRUE(c.running()) << read_bytes(d + "/log");
    c.signal(sig);
    EXPECT_EQ(c.wait(120), 128 + sig);
    std::string log = read_bytes(d + "/log");
    EXPECT_NE(log.find(std::string(word) + ": <built-in Cornell box> 40x30, "), std::string::npos) << log;
    double spp = reported_spp(log);
    EXPECT_GT(spp, 0.0) << log;
    EXPECT_LT(spp, 1000000.0) << log;
    Image img = read_linear_image(d + "/x.exr");
    EXPECT_EQ(img.width, 40);
    EXPECT_EQ(img.height, 30);
    double sum = 0;
    for (float v : img.rgb) sum += v;
    EXPECT_GT(sum, 0.0);  // the samples so far, not a black image
}

}  // namespace

TEST(Signals, SigintWritesTheImageSoFar) { stop_render_with(SIGINT, "interrupted"); }

TEST(Signals, SigtermWritesTheImageSoFar) { stop_render_with(SIGTERM, "terminated"); }

TEST(Signals, SigintWithCheckpointFinishesThePassAndResumesExactly) {
    std::string d = temp_dir("signal-ckpt");
    const std::string opts = "--width 24 --height 20 --spp-per-frame 2";
    Child c(opts + " --frames 1000000 --checkpoint-every 0 --out " + d + "/x.exr --checkpoint " + d + "/c.ck",
            d + "/log");
    ASSERT_TRUE(c.wait_until([&] { return checkpoint_spp(d + "/c.ck") >= 2; })) << read_bytes(d + "/log");
    c.signal(SIGINT);
    EXPECT_EQ(c.wait(120), 130);
    std::string log = read_bytes(d + "/log");
    long k = checkpoint_spp(d + "/c.ck");
    ASSERT_GE(k, 2);
    EXPECT_EQ(k % 2, 0);  // whole passes
    // The image has exactly the checkpoint's samples, and the summary says so.
    EXPECT_EQ(reported_spp(log), double(k)) << log;
    EXPECT_NE(log.find("checkpoint " + d + "/c.ck at " + std::to_string(k) + " spp"), std::string::npos) << log;

    const std::string frames = " --quiet --frames " + std::to_string(k / 2 + 2);
    ASSERT_EQ(run_candela(opts + frames + " --out " + d + "/resumed.exr --resume " + d + "/c.ck").exit_code, 0);
    ASSERT_EQ(run_candela(opts + frames + " --out " + d + "/full.exr").exit_code, 0);
    Image a = read_linear_image(d + "/resumed.exr"), b = read_linear_image(d + "/full.exr");
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    EXPECT_EQ(std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)), 0);
}

TEST(Signals, SecondSignalStopsInsideAPass) {
    std::string d = temp_dir("signal-twice");
    // One pass of 1024 x 1024 x 64 samples takes many seconds, a tile of it (16 x 16 pixels)
    // milliseconds: only the second signal, which stops at the next tile, can end this run soon.
    Child c("--width 1024 --height 1024 --spp-per-frame 64 --frames 1 --out " + d + "/x.exr --checkpoint " + d +
                "/c.ck",
            d + "/log");
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    ASSERT_TRUE(c.running()) << read_bytes(d + "/log");
    c.signal(SIGINT);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_TRUE(c.running());  // still finishing the pass
    c.signal(SIGINT);
    EXPECT_EQ(c.wait(60), 130);
    std::string log = read_bytes(d + "/log");
    EXPECT_NE(log.find("finishing the current pass"), std::string::npos) << log;
    EXPECT_FALSE(file_exists(d + "/c.ck"));  // never saved: no whole pass was done
    EXPECT_FALSE(file_exists(d + "/x.exr"));  // nor an image without one whole pass
    EXPECT_NE(log.find("interrupted before the first pass finished: nothing written"), std::string::npos) << log;
}

// A signal while a big OBJ loads stops the load at once, and the earlier image at --out stays.
TEST(Signals, SignalDuringLoadStopsAndKeepsTheOutput) {
    std::string d = temp_dir("signal-load");
    write_big_obj(d + "/big.obj", 1000);
    const std::string before = "an earlier good render";
    write_text(d + "/x.exr", before);
    for (int sig : {SIGINT, SIGTERM}) {
        Child c(d + "/big.obj --width 8 --height 8 --frames 1 --out " + d + "/x.exr", d + "/log");
        std::this_thread::sleep_for(std::chrono::milliseconds(700));  // well inside the load
        ASSERT_TRUE(c.running()) << read_bytes(d + "/log");
        auto t = std::chrono::steady_clock::now();
        c.signal(sig);
        EXPECT_EQ(c.wait(60), 128 + sig);
        const double s = seconds_since(t);
        EXPECT_LT(s, kMaxStopSeconds) << "the load went on after the signal";  // it takes several seconds
        std::printf("signal %d: exit %.3f s after it\n", sig, s);
        std::string log = read_bytes(d + "/log");
        EXPECT_NE(log.find(std::string(sig == SIGINT ? "interrupted" : "terminated") +
                           " while loading the scene: nothing written (" + d + "/x.exr left as it was)"),
                  std::string::npos)
            << log;
        EXPECT_EQ(read_bytes(d + "/x.exr"), before);
    }
}

// A signal inside the first pass (no checkpoint) writes nothing either.
TEST(Signals, SignalInTheFirstPassKeepsTheOutput) {
    std::string d = temp_dir("signal-first-pass");
    const std::string before = "an earlier good render";
    write_text(d + "/x.png", before);
    Child c("--width 1024 --height 1024 --spp-per-frame 64 --frames 2 --out " + d + "/x.png", d + "/log");
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    ASSERT_TRUE(c.running()) << read_bytes(d + "/log");
    c.signal(SIGINT);
    EXPECT_EQ(c.wait(60), 130);
    std::string log = read_bytes(d + "/log");
    EXPECT_NE(log.find("interrupted before the first pass finished: nothing written"), std::string::npos) << log;
    EXPECT_EQ(read_bytes(d + "/x.png"), before);
}
