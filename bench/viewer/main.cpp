// candela-bench-viewer: opens the viewer on a scene, lets it move the camera by itself (a small
// orbit step every --move-every seconds, for --burst consecutive frames: a short drag) and reports
//   frame: the UI thread's work per frame (events, panel, texture upload, draw, swap), median/p99
//   update: camera change -> end of the first frame showing an image rendered with it
// Run it under Xvfb: bench/viewer/run.sh.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <thread>
#include "core/error.h"
#include "viewer/front_end.h"
#include "viewer/viewer.h"

using namespace candela;

namespace {

// The measurement, as viewer hooks: scripted camera moves and what each frame cost.
struct Benchmark : ViewerHooks {
    double duration = 10;       // seconds of measurement, after the first full-resolution pass
    double move_every = 0.25;   // seconds between scripted camera changes (a small orbit step)
    int moves_per_burst = 1;    // consecutive frames that each change the camera (a "drag")
    bool paused = false;        // full passes paused: the window's own cost, previews only
    // Results.
    std::vector<double> frame_ms;      // per frame, from the end of the event wait to the swap
    std::vector<double> frame_cpu_ms;  // the same, in CPU time of the window's thread: what the
                                       // frame costs on an idle core (with LP_NUM_THREADS=0 the
                                       // software rasteriser runs in this thread too)
    std::vector<double> update_ms;     // camera change -> end of the first frame showing its image
    std::vector<bool> frame_new_image;
    int frames = 0;

    double start = 0, next_move = 0, change_time = -1;
    uint64_t change_gen = 0;
    bool waiting_gen = false;
    int burst_left = 0;

    void started(ViewerFrontEnd& fe) override {
        if (paused) fe.session().set_paused(true);
    }
    void before_panel(ViewerFrontEnd& fe, double now) override {
        if (start == 0) return;
        if (burst_left == 0 && now >= next_move) {
            burst_left = moves_per_burst;
            next_move = now + move_every;
        }
        if (burst_left > 0) {
            --burst_left;
            fe.camera().orbit(0.01f, 0.f);
            fe.camera_changed(now);
            if (change_time < 0) {
                change_time = now;
                waiting_gen = true;
            }
        }
    }
    bool after_frame(ViewerFrontEnd& fe, const Frame& f) override {
        const SessionImage& img = fe.image();
        if (start == 0) {
            // Start once the first full pass is on screen: the steady state of a session.
            if (img.rgb.empty() || (img.preview && !paused)) return true;
            start = next_move = f.end;
        }
        if (f.end - start > duration) return false;
        frame_ms.push_back((f.end - f.start) * 1e3);
        frame_cpu_ms.push_back(f.cpu_ms);
        frame_new_image.push_back(f.new_image);
        ++frames;
        // The change was sent in this frame once nothing is left unsent.
        if (waiting_gen && !fe.dirty()) {
            change_gen = fe.sent_generation();
            waiting_gen = false;
        }
        // A change is "shown" at the end of the first frame whose image comes from it.
        if (change_time >= 0 && !waiting_gen && img.generation >= change_gen) {
            update_ms.push_back((f.end - change_time) * 1e3);
            change_time = -1;
        }
        return true;
    }
};

double percentile(std::vector<double> v, double q) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    size_t i = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
    return v[i];
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"candela-bench-viewer: viewer frame times and camera-change latency"};
    ViewerOptions vo;
    Benchmark b;
    int size = 512;
    app.add_option("scene", vo.scene, "Scene file (default: the built-in Cornell box)");
    app.add_option("--size", size, "Image width and height");
    app.add_option("--threads", vo.threads, "Render threads (default: all cores)");
    app.add_option("--duration", b.duration, "Seconds of measurement");
    app.add_option("--move-every", b.move_every, "Seconds between camera moves");
    app.add_option("--burst", b.moves_per_burst, "Frames per move that each change the camera");
    app.add_flag("--paused", b.paused, "No full passes (previews after each camera change only)");
    std::string priority = "idle";
    app.add_option("--render-priority", priority, "Render threads: normal, low (nice 19) or idle (SCHED_IDLE)")
        ->check(CLI::IsMember({"normal", "low", "idle"}));
    app.add_flag("--denoise", vo.denoise, "The denoised view on (docs/denoising.md; quality balanced)");
    CLI11_PARSE(app, argc, argv);
    vo.overrides.width = size;
    vo.overrides.height = size;
    vo.hooks = &b;
    vo.render_priority = parse_render_priority(priority);
    try {
        run_viewer(vo);
    } catch (const Error& e) {
        std::fprintf(stderr, "candela-bench-viewer: %s\n", e.what());
        return 1;
    }
    int threads = vo.threads > 0 ? vo.threads : int(std::thread::hardware_concurrency());
    std::printf("viewer %dx%d, %d render threads (priority %s)%s, %.0f s, %d frames, %zu camera changes measured\n",
                size, size, threads, priority.c_str(), vo.denoise ? ", denoised view" : "", b.duration, b.frames,
                b.update_ms.size());
    std::printf("frame  ms: median %.2f  p90 %.2f  p99 %.2f  max %.2f\n", percentile(b.frame_ms, 0.5),
                percentile(b.frame_ms, 0.9), percentile(b.frame_ms, 0.99), percentile(b.frame_ms, 1.0));
    std::printf("frame  CPU ms (window thread): median %.2f  p90 %.2f  p99 %.2f\n", percentile(b.frame_cpu_ms, 0.5),
                percentile(b.frame_cpu_ms, 0.9), percentile(b.frame_cpu_ms, 0.99));
    std::vector<double> with_image, without_image;
    for (size_t i = 0; i < b.frame_ms.size(); ++i)
        (b.frame_new_image[i] ? with_image : without_image).push_back(b.frame_ms[i]);
    std::printf("frame  ms, frames that upload a new image (%zu): median %.2f  p99 %.2f; other frames (%zu): "
                "median %.2f  p99 %.2f\n",
                with_image.size(), percentile(with_image, 0.5), percentile(with_image, 0.99), without_image.size(),
                percentile(without_image, 0.5), percentile(without_image, 0.99));
    std::printf("update ms: median %.2f  p90 %.2f  max %.2f\n", percentile(b.update_ms, 0.5),
                percentile(b.update_ms, 0.9), percentile(b.update_ms, 1.0));
    return 0;
}
