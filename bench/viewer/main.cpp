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
#include "viewer/viewer.h"

using namespace candela;

namespace {

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
    ViewerBenchmark b;
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
    CLI11_PARSE(app, argc, argv);
    vo.overrides.width = size;
    vo.overrides.height = size;
    vo.benchmark = &b;
    vo.render_priority = parse_render_priority(priority);
    try {
        run_viewer(vo);
    } catch (const Error& e) {
        std::fprintf(stderr, "candela-bench-viewer: %s\n", e.what());
        return 1;
    }
    int threads = vo.threads > 0 ? vo.threads : int(std::thread::hardware_concurrency());
    std::printf("viewer %dx%d, %d render threads (priority %s), %.0f s, %d frames, %zu camera changes measured\n",
                size, size, threads, priority.c_str(), b.duration, b.frames, b.update_ms.size());
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
