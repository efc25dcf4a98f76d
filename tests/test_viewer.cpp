// The viewer: camera controls and picking (no window needed), and the real window under Xvfb:
// `candela --screenshot-after N FILE` on the Cornell box must show the panel, and its render region
// must match headless renders of the same scene within noise.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#include "render/launch.h"
#include "support/stats.h"
#include "viewer/camera_control.h"
#include "viewer/pick.h"

extern char** environ;

using namespace candela;

namespace {

void expect_near(vec3 a, vec3 b, float tol, const char* what) {
    EXPECT_LT(glm::length(a - b), tol) << what << ": (" << a.x << ", " << a.y << ", " << a.z << ") vs (" << b.x
                                       << ", " << b.y << ", " << b.z << ")";
}

}  // namespace

// ---- camera controller ------------------------------------------------------------------------

TEST(CameraControl, ResetRestoresTheSceneCameraExactly) {
    auto sp = prepare_scene("", {});
    const Scene& s = *sp;
    CameraController c(s.camera, s.mesh.bounds());
    c.orbit(0.3f, 0.2f);
    c.pan(0.1f, -0.2f);
    c.dolly(3);
    c.set_fov(70);
    c.reset(c.initial(), s.mesh.bounds());
    Camera cam = s.camera;
    c.apply(cam);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) EXPECT_EQ(cam.to_world[i][j], s.camera.to_world[i][j]);
    EXPECT_EQ(cam.fov_deg, s.camera.fov_deg);
}

TEST(CameraControl, OrbitKeepsTheTargetInViewAtTheSameDistance) {
    auto sp = prepare_scene("", {});
    const Scene& s = *sp;
    CameraController c(s.camera, s.mesh.bounds());
    const vec3 target = c.target();
    const float d = c.distance();
    // The Cornell box's camera looks at the middle of the box: the target is near its centre.
    EXPECT_LT(glm::length(vec3(target.x, target.y, 0.f) - vec3(278.f, 273.f, 0.f)), 5.f);
    c.orbit(0.7f, 0.3f);
    EXPECT_NEAR(c.distance(), d, 1e-3f * d);
    expect_near(c.target(), target, 1e-3f, "target");
    expect_near(glm::normalize(vec3(c.to_world()[2])), glm::normalize(target - c.origin()), 1e-5f, "forward");
    // The horizon does not roll: the camera's left axis stays horizontal (the scene's up is +y).
    EXPECT_NEAR(vec3(c.to_world()[0]).y, 0.f, 1e-5f);
    // A full turn in 8 steps comes back.
    CameraController r(s.camera, s.mesh.bounds());
    vec3 o = r.origin();
    for (int i = 0; i < 8; ++i) r.orbit(2.f * kPi / 8.f, 0.f);
    expect_near(r.origin(), o, 1e-2f, "origin after a full turn");
    // Pitch stops before the pole.
    r.orbit(0.f, 10.f);
    EXPECT_LT(glm::dot(r.forward(), vec3(0, -1, 0)), 1.f - 1e-5f);
    EXPECT_TRUE(all_finite(vec3(r.to_world()[0])));
}

TEST(CameraControl, PanDollyAndFly) {
    auto sp = prepare_scene("", {});
    const Scene& s = *sp;
    CameraController c(s.camera, s.mesh.bounds());
    vec3 o = c.origin(), t = c.target(), fwd = c.forward();
    c.pan(0.5f, 0.f);  // half the visible extent to the right: both move together
    vec3 moved = c.origin() - o;
    expect_near(c.target() - t, moved, 1e-3f, "target follows");
    const float extent = 2.f * c.distance() * std::tan(glm::radians(c.fov()) * 0.5f);
    EXPECT_NEAR(glm::length(moved), 0.5f * extent, 1e-3f * extent);
    // "Right" in the image: Mitsuba camera space has +x to the image's left.
    EXPECT_LT(glm::dot(moved, vec3(s.camera.to_world[0])), 0.f);

    float d = c.distance();
    c.dolly(2.f);
    EXPECT_NEAR(c.distance(), d * 0.85f * 0.85f, 1e-3f * d);
    expect_near(c.forward(), fwd, 1e-5f, "dolly keeps the direction");

    vec3 before = c.origin();
    c.fly(vec3(0.f, 0.f, 0.1f));  // W: a tenth of the scene forward
    expect_near(c.origin() - before, 0.1f * c.scene_scale() * fwd, 1e-2f, "fly forward");
}

// ---- picking ----------------------------------------------------------------------------------

TEST(ViewerPick, NamesWhatIsUnderThePixel) {
    SceneOverrides ov;
    ov.width = ov.height = 64;
    auto sp = prepare_scene("", ov);
    const Scene& s = *sp;
    auto shape_at = [&](float x, float y) {
        PickResult r = pick(s, s.camera, vec2(x, y));
        return r.hit ? s.shapes[r.shape].name : std::string("-");
    };
    EXPECT_EQ(shape_at(32.f, 9.f), "light") << "top middle";  // the light is seen from below
    PickResult light = pick(s, s.camera, vec2(32.f, 9.f));
    EXPECT_EQ(light.emitter, 0);
    EXPECT_EQ(shape_at(2.f, 32.f), "red") << "left wall (Mitsuba's Cornell box has red on the left)";
    EXPECT_EQ(shape_at(62.f, 32.f), "green");
    EXPECT_EQ(shape_at(32.f, 4.f), "ceiling");
    EXPECT_EQ(shape_at(10.f, 58.f), "floor");
    EXPECT_EQ(shape_at(40.f, 58.f), "short_block");
    EXPECT_EQ(shape_at(32.f, 66.f), "-") << "outside the film: nothing";
    PickResult back = pick(s, s.camera, vec2(20.f, 20.f));
    ASSERT_TRUE(back.hit);
    EXPECT_EQ(s.shapes[back.shape].name, "back");
    EXPECT_EQ(s.materials[back.material].name, "white");
    EXPECT_NEAR(back.position.z, 559.2f, 1.f);
    EXPECT_NEAR(back.distance, glm::length(back.position - s.camera.origin()), 1e-3f);
}

// ---- the real window under Xvfb ---------------------------------------------------------------

namespace {

bool file_exists(const std::string& p) {
    struct stat st;
    return stat(p.c_str(), &st) == 0;
}

std::string find_program(const std::string& name) {
    for (const char* dir : {"/usr/bin", "/usr/local/bin", "/bin"}) {
        std::string p = std::string(dir) + "/" + name;
        if (access(p.c_str(), X_OK) == 0) return p;
    }
    return "";
}

// An Xvfb server on a free display number, stopped (by its pid) when this goes out of scope.
class Xvfb {
public:
    bool start(std::string& why) {
        std::string bin = find_program("Xvfb");
        if (bin.empty()) {
            why = "Xvfb is not installed (Debian package xvfb)";
            return false;
        }
        for (int n = 99; n < 140; ++n) {
            if (file_exists("/tmp/.X" + std::to_string(n) + "-lock") ||
                file_exists("/tmp/.X11-unix/X" + std::to_string(n)))
                continue;
            display_ = ":" + std::to_string(n);
            std::vector<std::string> args = {bin, display_, "-screen", "0", "1280x800x24", "-nolisten", "tcp"};
            std::vector<char*> argv;
            for (auto& a : args) argv.push_back(a.data());
            argv.push_back(nullptr);
            posix_spawn_file_actions_t fa;
            posix_spawn_file_actions_init(&fa);
            posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
            posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
            int rc = posix_spawn(&pid_, bin.c_str(), &fa, nullptr, argv.data(), environ);
            posix_spawn_file_actions_destroy(&fa);
            if (rc != 0) {
                why = "cannot run " + bin;
                return false;
            }
            // Ready when its socket appears; gone if it exited (display taken, no permission, ...).
            for (int i = 0; i < 100; ++i) {
                if (file_exists("/tmp/.X11-unix/X" + std::to_string(n))) return true;
                int status;
                if (waitpid(pid_, &status, WNOHANG) == pid_) {
                    pid_ = -1;
                    break;
                }
                std::this_thread::sleep_for(std::chrono::milliseconds(50));
            }
            stop();
        }
        why = "Xvfb did not start on any display from :99 to :139";
        return false;
    }
    void stop() {
        if (pid_ > 0) {
            kill(pid_, SIGTERM);
            waitpid(pid_, nullptr, 0);
        }
        pid_ = -1;
    }
    ~Xvfb() { stop(); }
    const std::string& display() const { return display_; }

private:
    pid_t pid_ = -1;
    std::string display_;
};

struct CmdResult {
    int code = -1;
    std::string out;
};
CmdResult run_cmd(const std::string& cmd) {
    CmdResult r;
    FILE* p = popen((cmd + " 2>&1").c_str(), "r");
    if (!p) return r;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
    int status = pclose(p);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return r;
}

struct Picture {
    int w = 0, h = 0;
    std::vector<unsigned char> rgb;
    bool load(const std::string& path) {
        int n;
        unsigned char* d = stbi_load(path.c_str(), &w, &h, &n, 3);
        if (!d) return false;
        rgb.assign(d, d + size_t(w) * size_t(h) * 3);
        stbi_image_free(d);
        return true;
    }
    const unsigned char* at(int x, int y) const { return &rgb[(size_t(y) * size_t(w) + size_t(x)) * 3]; }
};

// Per-block, per-channel means of the bytes in a sub-rectangle of a picture.
std::vector<double> block_means(const Picture& p, int x0, int y0, int w, int h, int block) {
    std::vector<double> out;
    for (int by = 0; by < h; by += block)
        for (int bx = 0; bx < w; bx += block)
            for (int c = 0; c < 3; ++c) {
                double s = 0;
                int n = 0;
                for (int y = by; y < std::min(by + block, h); ++y)
                    for (int x = bx; x < std::min(bx + block, w); ++x, ++n) s += p.at(x0 + x, y0 + y)[c];
                out.push_back(s / n);
            }
    return out;
}

// Is the viewer's picture a draw from the same distribution as the K reference renders? Two kinds
// of t-test, each (v - mean_k) / (s sqrt(1 + 1/K)) with K - 1 degrees of freedom: one per block and
// channel (a local error), and one per channel on the mean of the whole region (a global bias,
// which blocks alone cannot see through the noise of K samples). Returns the smallest p, Sidak-
// adjusted over all tests. `floor` (bytes) is added to s in quadrature: blocks saturated in every
// render (the light) have s = 0.
double family_p(const std::vector<double>& viewer, const std::vector<std::vector<double>>& refs, double floor) {
    const int K = int(refs.size());
    double p_min = 1;
    int tests = 0;
    auto test = [&](double v, const std::vector<double>& r, double fl) {
        double m = 0, s2 = 0;
        for (double x : r) m += x;
        m /= K;
        for (double x : r) s2 += (x - m) * (x - m);
        s2 /= (K - 1);
        double t = (v - m) / std::sqrt((s2 + fl * fl) * (1.0 + 1.0 / K));
        p_min = std::min(p_min, stats::student_t_two_sided_p(t, K - 1));
        ++tests;
    };
    std::vector<double> r(K);
    for (size_t i = 0; i < viewer.size(); ++i) {
        for (int k = 0; k < K; ++k) r[k] = refs[k][i];
        test(viewer[i], r, floor);
    }
    const size_t blocks = viewer.size() / 3;
    for (size_t c = 0; c < 3; ++c) {
        double v = 0;
        std::fill(r.begin(), r.end(), 0.0);
        for (size_t i = c; i < viewer.size(); i += 3) {
            v += viewer[i] / double(blocks);
            for (int k = 0; k < K; ++k) r[k] += refs[k][i] / double(blocks);
        }
        test(v, r, floor / std::sqrt(double(blocks)));
    }
    return stats::sidak_adjust(p_min, tests);
}

}  // namespace

TEST(ViewerWindow, ScreenshotShowsThePanelAndTheRender) {
    Xvfb x;
    std::string why;
    if (!x.start(why)) GTEST_SKIP() << "no X server for the viewer test: " << why;

    const std::string dir = "/tmp/candela-viewer-test-" + std::to_string(getpid());
    ASSERT_EQ(run_cmd("rm -rf " + dir + " && mkdir -p " + dir).code, 0);
    const int size = 128, passes = 16, batches = 8;
    const std::string common = " --width " + std::to_string(size) + " --height " + std::to_string(size) + " --threads 2";
    const std::string shot = dir + "/viewer.png";
    CmdResult v = run_cmd("env DISPLAY=" + x.display() + " LIBGL_ALWAYS_SOFTWARE=1 " + CANDELA_BIN + common +
                " --screenshot-after " + std::to_string(passes) + " " + shot);
    if (v.out.find("without the viewer") != std::string::npos) GTEST_SKIP() << "candela was built without the viewer";
    ASSERT_EQ(v.code, 0) << v.out;

    // The layout the program reports: "image X,Y WxH, panel X,Y WxH" (top-left origin).
    int wx = 0, wy = 0, ix, iy, iw, ih, px, py, pw, ph;
    size_t at = v.out.find("window ");
    ASSERT_NE(at, std::string::npos) << v.out;
    ASSERT_EQ(std::sscanf(v.out.c_str() + at, "window %dx%d, image %d,%d %dx%d, panel %d,%d %dx%d", &wx, &wy, &ix, &iy,
                          &iw, &ih, &px, &py, &pw, &ph),
              10)
        << v.out;
    Picture pic;
    ASSERT_TRUE(pic.load(shot));
    ASSERT_EQ(pic.w, wx);
    ASSERT_EQ(pic.h, wy);
    ASSERT_EQ(iw, size) << "the image is drawn pixel for pixel when it fits";
    ASSERT_EQ(ih, size);
    ASSERT_GE(pw, 300);

    // The panel: mostly ImGui's window background (dark style, made opaque: 0.06 -> 15), with text.
    int bg = 0, bright = 0, n = 0;
    for (int y = py; y < py + ph; ++y)
        for (int xx = px; xx < px + pw; ++xx, ++n) {
            const unsigned char* c = pic.at(xx, y);
            if (std::abs(c[0] - 15) <= 1 && std::abs(c[1] - 15) <= 1 && std::abs(c[2] - 15) <= 1) ++bg;
            if (c[0] > 200 && c[1] > 200 && c[2] > 200) ++bright;
        }
    EXPECT_GT(double(bg) / n, 0.3) << "the panel's background colour is missing";
    EXPECT_GT(double(bright) / n, 0.005) << "no text in the panel";
    // Outside the image, the render area is the clear colour, not the panel's.
    if (iy > 0) {
        EXPECT_LT(pic.at(ix + iw / 2, iy / 2)[0], 10);
    }

    // The render region against K headless renders (other seeds) of the same scene, through the
    // same display shaders: per 8 x 8 block and channel, a t-test with a Sidak correction.
    const int block = 8;
    std::vector<double> viewer = block_means(pic, ix, iy, iw, ih, block);
    std::vector<std::vector<double>> refs;
    for (int k = 1; k <= batches; ++k) {
        std::string out = dir + "/ref" + std::to_string(k) + ".png";
        CmdResult r = run_cmd(std::string("env -u DISPLAY ") + CANDELA_BIN + common + " --frames " + std::to_string(passes) +
                    " --seed " + std::to_string(k) + " -q --out " + out);
        ASSERT_EQ(r.code, 0) << r.out;
        Picture ref;
        ASSERT_TRUE(ref.load(out));
        ASSERT_EQ(ref.w, size);
        refs.push_back(block_means(ref, 0, 0, size, size, block));
    }
    // With the same seed the film is the same, sample for sample, so the window must show exactly
    // the headless PNG: no flip, no shift, no resampling, no second tonemap.
    {
        std::string out = dir + "/same_seed.png";
        CmdResult r = run_cmd(std::string("env -u DISPLAY ") + CANDELA_BIN + common + " --frames " +
                              std::to_string(passes) + " -q --out " + out);
        ASSERT_EQ(r.code, 0) << r.out;
        Picture same;
        ASSERT_TRUE(same.load(out));
        ASSERT_EQ(same.w, size);
        int differ = 0;
        for (int y = 0; y < size; ++y)
            for (int xx = 0; xx < size; ++xx)
                for (int c = 0; c < 3; ++c) differ += pic.at(ix + xx, iy + y)[c] != same.at(xx, y)[c];
        EXPECT_EQ(differ, 0) << "the window does not show the headless image of the same samples";
    }

    const double floor = 0.5;  // bytes: rounding to 8 bits
    double p = family_p(viewer, refs, floor);
    EXPECT_GE(p, 0.01) << "the viewer's render differs from headless renders beyond noise";
    // The test has power: a 5% brighter image is rejected.
    std::vector<double> brighter = viewer;
    for (double& b : brighter) b *= 1.05;
    EXPECT_LT(family_p(brighter, refs, floor), 0.01) << "the comparison cannot see a 5% error";
    std::printf("viewer vs %d headless renders: family-wise p = %.3f\n", batches, p);
    run_cmd("rm -rf " + dir);
}
