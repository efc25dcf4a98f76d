#include "app/headless_run.h"
#include <omp.h>
#include <unistd.h>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include "core/error.h"
#include "film/film.h"
#include "film/image_io.h"
#include "headless/headless.h"
#include "render/renderer.h"

namespace candela {

namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void on_signal(int) { g_interrupted.store(true); }

void progress_bar(int done, int total, double secs, double msps) {
    const int width = 30;
    int filled = total > 0 ? int(double(width) * done / total) : 0;
    char bar[width + 1];
    for (int i = 0; i < width; ++i) bar[i] = i < filled ? '=' : (i == filled ? '>' : ' ');
    bar[width] = 0;
    double eta = done > 0 ? secs * (total - done) / done : 0.0;
    std::fprintf(stderr, "\r[%s] %d/%d passes  %.2f Msamples/s  %.1fs  ETA %.1fs ", bar, done, total, msps, secs, eta);
    std::fflush(stderr);
}

}  // namespace

int run_headless(const HeadlessOptions& opt) {
    std::string ext = file_extension(opt.out);
    if (ext != ".png" && ext != ".exr" && ext != ".pfm")
        throw Error(opt.out, 0, "unknown output format '" + ext + "' (expected .png, .exr or .pfm)");

    std::shared_ptr<Scene> scene_ptr = prepare_scene(opt.scene, opt.overrides);
    const Scene& scene = *scene_ptr;
    const RenderSettings& st = scene.settings;
    if (!opt.quiet)
        for (const std::string& w : scene.warnings) std::fprintf(stderr, "candela: warning: %s\n", w.c_str());
    int frames = opt.frames > 0 ? opt.frames : std::max(1, st.spp / std::max(1, opt.spp_per_frame));
    Film film(st.width, st.height);
    int threads = opt.threads > 0 ? opt.threads : omp_get_max_threads();

    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    const bool tty = isatty(fileno(stderr)) && !opt.quiet;
    using clock = std::chrono::steady_clock;
    auto t0 = clock::now();
    uint64_t samples = 0, rays = 0;
    int done = 0;
    for (int f = 0; f < frames; ++f) {
        if (g_interrupted) break;
        double elapsed = std::chrono::duration<double>(clock::now() - t0).count();
        if (opt.time_limit > 0 && elapsed >= opt.time_limit) break;
        PassStats ps = Renderer::render_pass(scene, film, uint32_t(f) * uint32_t(opt.spp_per_frame), opt.spp_per_frame,
                                             threads, &g_interrupted);
        samples += ps.samples;
        rays += ps.rays;
        if (!ps.completed) break;
        ++done;
        if (tty) {
            double s = std::chrono::duration<double>(clock::now() - t0).count();
            progress_bar(done, frames, s, s > 0 ? samples / s * 1e-6 : 0.0);
        }
    }
    double secs = std::chrono::duration<double>(clock::now() - t0).count();
    if (tty) std::fprintf(stderr, "\n");

    Image img{film.width(), film.height(), film.resolve()};
    if (ext == ".png") write_png_headless(opt.out, img, opt.display);
    else write_linear_image(opt.out, img);

    if (!opt.quiet) {
        double spp = double(film.total_samples()) / (double(film.width()) * film.height());
        std::fprintf(stderr,
                     "candela: %s%s %dx%d, %.6g spp in %.2f s, %.3f Msamples/s, %.3f Mrays/s, %d threads, "
                     "accel %s, %llu non-finite samples -> %s\n",
                     g_interrupted ? "interrupted: " : "", scene.source.c_str(), film.width(), film.height(), spp, secs,
                     secs > 0 ? samples / secs * 1e-6 : 0.0, secs > 0 ? rays / secs * 1e-6 : 0.0, threads,
                     scene.accel->name().c_str(), (unsigned long long)film.nonfinite_count(), opt.out.c_str());
    }
    return g_interrupted ? 130 : 0;
}

}  // namespace candela
