#include "app/headless_run.h"
#include <omp.h>
#include <unistd.h>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <limits>
#include "app/checkpoint.h"
#include "core/error.h"
#include "film/exr_layers.h"
#include "film/film.h"
#include "film/image_io.h"
#include "headless/headless.h"
#include "render/renderer.h"

namespace candela {

namespace {

// Set by the signal handler; lock-free atomics are the only shared state a handler may touch.
std::atomic<int> g_signal{0};         // the first SIGINT/SIGTERM received, 0 if none
std::atomic<bool> g_stop_now{false};  // the render stops within a tile
std::atomic<bool> g_finish_pass{false};  // checkpointing: the first signal waits for the pass
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free);

extern "C" void on_signal(int sig) {
    int none = 0;
    if (g_signal.compare_exchange_strong(none, sig) && g_finish_pass.load()) {
        static const char msg[] = "\ncandela: finishing the current pass for the checkpoint (signal again to stop now)\n";
        ssize_t n = ::write(STDERR_FILENO, msg, sizeof msg - 1);  // async-signal-safe, unlike stdio
        (void)n;
        return;
    }
    g_stop_now.store(true);
}

void install_signal_handlers() {
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

// Refuses an output whose directory is missing or not writable before rendering, not hours later.
void check_writable(const std::string& path) {
    std::string dir = std::filesystem::path(path).parent_path().string();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) throw Error(path, 0, "directory '" + dir + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0) throw Error(path, 0, "cannot write in directory '" + dir + "'");
}

void progress_bar(uint64_t done, uint64_t total, double secs, double msps) {
    const int width = 30;
    int filled = total > 0 ? int(double(width) * double(done) / double(total)) : 0;
    char bar[width + 1];
    for (int i = 0; i < width; ++i) bar[i] = i < filled ? '=' : (i == filled ? '>' : ' ');
    bar[width] = 0;
    std::fprintf(stderr, "\r[%s] %llu/%llu spp  %.2f Msamples/s  %.1fs ", bar, (unsigned long long)done,
                 (unsigned long long)total, msps, secs);
    std::fflush(stderr);
}

}  // namespace

int run_headless(const HeadlessOptions& opt) {
    std::string ext = file_extension(opt.out);
    if (ext != ".png" && ext != ".exr" && ext != ".pfm")
        throw Error(opt.out, 0, "unknown output format '" + ext + "' (expected .png, .exr or .pfm)");
    check_writable(opt.out);
    if (!opt.checkpoint.empty()) check_writable(opt.checkpoint);

    // Handlers go in before the (possibly long) scene load, so that no signal finds the default
    // action (death without an image) once candela has started.
    g_signal = 0;
    g_stop_now = false;
    g_finish_pass = !opt.checkpoint.empty();
    install_signal_handlers();

    std::shared_ptr<const Scene> scene_ptr = prepare_scene(opt.scene, opt.overrides);
    const Scene& scene = *scene_ptr;
    const RenderSettings& st = scene.settings;
    if (!opt.quiet)
        for (const std::string& w : scene.warnings) std::fprintf(stderr, "candela: warning: %s\n", w.c_str());
    const int spp_per_pass = std::max(1, opt.spp_per_frame);
    const uint64_t frames = opt.frames > 0 ? uint64_t(opt.frames) : uint64_t(std::max(1, st.spp / spp_per_pass));
    // Sample indices and per-pixel counts are 32-bit.
    const uint64_t target = frames * uint64_t(spp_per_pass);
    if (target > std::numeric_limits<uint32_t>::max())
        throw Error("--frames x --spp-per-frame is " + std::to_string(target) + " samples per pixel, more than 2^32 - 1");
    const std::vector<AovSpec>& aovs = st.integrator.aovs;
    if (!aovs.empty() && !opt.checkpoint.empty())
        throw Error(opt.checkpoint, 0, "checkpoints do not hold the aov integrator's layers; render it without --checkpoint");
    if (!aovs.empty() && !opt.resume.empty())
        throw Error(opt.resume, 0, "checkpoints do not hold the aov integrator's layers; render it without --resume");
    Film film(st.width, st.height);
    configure_film(film, st);
    int threads = opt.threads > 0 ? opt.threads : omp_get_max_threads();

    const bool checkpointing = !opt.checkpoint.empty();
    uint64_t fingerprint = 0;
    if (checkpointing || !opt.resume.empty()) fingerprint = scene_fingerprint(scene);
    uint32_t spp_done = 0;
    if (!opt.resume.empty()) {
        spp_done = load_checkpoint(opt.resume, film, fingerprint).spp;
        if (spp_done > target)
            throw Error(opt.resume, 0, "checkpoint has " + std::to_string(spp_done) + " spp, more than the " +
                                           std::to_string(target) + " this render asks for");
        if (!opt.quiet) std::fprintf(stderr, "candela: resuming %s at %u spp\n", opt.resume.c_str(), spp_done);
    }

    using clock = std::chrono::steady_clock;
    auto t0 = clock::now();
    auto last_save = t0;
    // A failed save (a full disk) costs protection, not the render: warn and carry on.
    auto save = [&](const char* when) {
        try {
            save_checkpoint(opt.checkpoint, film, spp_done, fingerprint);
            last_save = clock::now();
        } catch (const Error& e) {
            std::fprintf(stderr, "candela: warning: %s checkpoint not saved: %s\n", when, e.what());
        }
    };

    const bool tty = isatty(fileno(stderr)) && !opt.quiet;
    uint64_t samples = 0, rays = 0;
    bool whole_passes = true;  // false once a pass was cut short: the film is no longer checkpointable
    while (spp_done < target && g_signal == 0) {
        double elapsed = std::chrono::duration<double>(clock::now() - t0).count();
        if (opt.time_limit > 0 && elapsed >= opt.time_limit) break;
        int n = int(std::min<uint64_t>(uint64_t(spp_per_pass), target - spp_done));
        PassStats ps = Renderer::render_pass(scene, film, spp_done, n, threads, &g_stop_now);
        samples += ps.samples;
        rays += ps.rays;
        if (!ps.completed) {
            whole_passes = false;
            break;
        }
        spp_done += uint32_t(n);
        if (checkpointing && spp_done < target &&
            std::chrono::duration<double>(clock::now() - last_save).count() >= opt.checkpoint_every)
            save("periodic");
        if (tty) {
            double s = std::chrono::duration<double>(clock::now() - t0).count();
            progress_bar(spp_done, target, s, s > 0 ? double(samples) / s * 1e-6 : 0.0);
        }
    }
    double secs = std::chrono::duration<double>(clock::now() - t0).count();
    if (tty) std::fprintf(stderr, "\n");
    if (checkpointing && whole_passes) save("final");

    Image img{film.width(), film.height(), film.resolve()};
    if (!aovs.empty() && ext == ".exr") {
        std::vector<std::string> names = aov_channel_names(aovs);
        std::vector<std::vector<float>> planes = film.resolve_aovs();
        std::vector<ExrLayer> layers;
        for (size_t k = 0; k < names.size(); ++k) layers.push_back({names[k], std::move(planes[k])});
        write_exr_layers(opt.out, img, layers);
    } else {
        if (!aovs.empty() && !opt.quiet)
            std::fprintf(stderr, "candela: warning: the AOV layers are written to .exr output only; %s gets the image\n",
                         opt.out.c_str());
        if (ext == ".png") write_png_headless(opt.out, img, opt.display);
        else write_linear_image(opt.out, img);
    }

    const int sig = g_signal.load();
    if (!opt.quiet) {
        double spp = double(film.total_samples()) / (double(film.width()) * film.height());
        // Memory first: scripts read the summary from the last line.
        const Scene::Memory mem = scene.memory();
        const double per_tri = mem.triangles ? 1.0 / double(mem.triangles) : 0.0;
        std::fprintf(stderr,
                     "candela: %zu triangles, %.1f MB (%.1f B/triangle: mesh %.1f, accel %.1f, lights %.1f)\n",
                     mem.triangles, double(mem.total()) / 1e6, double(mem.total()) * per_tri,
                     double(mem.mesh) * per_tri, double(mem.accel) * per_tri, double(mem.lights) * per_tri);
        std::fprintf(stderr,
                     "candela: %s%s %dx%d, %.6g spp in %.2f s, %.3f Msamples/s, %.3f Mrays/s, %d threads, "
                     "accel %s, %llu non-finite samples -> %s\n",
                     sig ? (sig == SIGTERM ? "terminated: " : "interrupted: ") : "", scene.source.c_str(), film.width(),
                     film.height(), spp, secs, secs > 0 ? samples / secs * 1e-6 : 0.0,
                     secs > 0 ? rays / secs * 1e-6 : 0.0, threads, scene.accel->name().c_str(),
                     (unsigned long long)film.nonfinite_count(), opt.out.c_str());
        if (checkpointing && whole_passes)
            std::fprintf(stderr, "candela: checkpoint %s at %u spp\n", opt.checkpoint.c_str(), spp_done);
        else if (checkpointing)
            std::fprintf(stderr, "candela: checkpoint %s not updated (stopped inside a pass; it keeps the last save)\n",
                         opt.checkpoint.c_str());
    }
    return sig ? 128 + sig : 0;
}

}  // namespace candela
