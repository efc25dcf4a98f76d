#include "app/headless_run.h"
#include <omp.h>
#include <unistd.h>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>
#include "app/checkpoint.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/progress.h"
#include "film/adaptive.h"
#include "film/exr_layers.h"
#include "film/film.h"
#include "film/image_io.h"
#include "integrator/bdpt/bdpt.h"
#include "integrator/mlt/pssmlt.h"
#include "film/image_io.h"
#include "headless/headless.h"
#include "render/renderer.h"

namespace candela {

namespace {

// Set by the signal handler; lock-free atomics are the only shared state a handler may touch.
std::atomic<int> g_signal{0};         // the first SIGINT/SIGTERM received, 0 if none
std::atomic<bool> g_stop_now{false};  // the render stops within a tile
std::atomic<bool> g_finish_pass{false};  // checkpointing: the first signal waits for the pass
std::atomic<bool> g_rendering{false};    // the scene is ready and passes run
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free);

extern "C" void on_signal(int sig) {
    int none = 0;
    const bool first = g_signal.compare_exchange_strong(none, sig);
    request_interrupt();  // stops a scene load or accelerator build: they have no pass to finish
    if (first && g_finish_pass.load() && g_rendering.load()) {
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

// Cuts the pass in flight at the deadline: sets `stop` (the pass's cancel flag, polled per tile)
// and `fired`. Between passes the loop checks the clock itself.
class Deadline {
public:
    Deadline(std::chrono::steady_clock::time_point when, std::atomic<bool>& stop, std::atomic<bool>& fired)
        : thread_([this, when, &stop, &fired] {
              std::unique_lock<std::mutex> lock(mutex_);
              if (!cv_.wait_until(lock, when, [this] { return done_; })) {
                  fired = true;
                  stop = true;
              }
          }) {}
    ~Deadline() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            done_ = true;
        }
        cv_.notify_all();
        thread_.join();
    }
    Deadline(const Deadline&) = delete;
    Deadline& operator=(const Deadline&) = delete;

private:
    std::mutex mutex_;
    std::condition_variable cv_;
    bool done_ = false;  // guarded by mutex_; declared before thread_, which reads it
    std::thread thread_;
};

}  // namespace

// Refuses an output whose directory is missing or not writable before rendering, not hours later.
void check_writable(const std::string& path) {
    std::string dir = std::filesystem::path(path).parent_path().string();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) throw Error(path, 0, "directory '" + dir + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0) throw Error(path, 0, "cannot write in directory '" + dir + "'");
}

WrittenImage write_headless_image(const HeadlessOptions& opt, const Scene& scene, const Film& film) {
    const std::string ext = file_extension(opt.out);
    const std::vector<AovSpec>& aovs = scene.settings.integrator.aovs;
    WrittenImage out{opt.out, false};
    Image img{film.width(), film.height(), film.resolve(), {}};
    if (film.has_alpha() && ext == ".exr") img.alpha = film.resolve_alpha();  // PNG and PFM: RGB only
    if (opt.target_error > 0 && ext == ".exr") {
        // Adaptive sampling: the samples each pixel took (both halves), as the channel `spp`.
        std::vector<float> spp_plane(size_t(film.width()) * size_t(film.height()));
        for (int y = 0; y < film.height(); ++y)
            for (int x = 0; x < film.width(); ++x)
                spp_plane[size_t(y) * size_t(film.width()) + size_t(x)] = float(film.samples_taken(x, y));
        write_exr_layers(opt.out, img, {{"spp", std::move(spp_plane)}});
    } else if (!aovs.empty() && ext == ".exr") {
        std::vector<std::string> names = aov_channel_names(aovs);
        std::vector<std::vector<float>> planes = film.resolve_aovs();
        std::vector<ExrLayer> layers;
        for (size_t k = 0; k < names.size(); ++k) layers.push_back({names[k], std::move(planes[k])});
        write_exr_layers(opt.out, img, layers);
    } else if (ext == ".png") {
        if (!aovs.empty() && !opt.quiet)
            std::fprintf(stderr, "candela: warning: the AOV layers are written to .exr output only; %s gets the image\n",
                         opt.out.c_str());
        // The PNG goes through GL; if that fails the samples must not go with it.
        try {
            write_png_headless(opt.out, img, opt.display);
        } catch (const std::exception& e) {
            out.png_failed = true;
            out.path = std::filesystem::path(opt.out).replace_extension(".exr").string();
            std::fprintf(stderr, "candela: %s\n", e.what());
            if (film.has_alpha()) img.alpha = film.resolve_alpha();
            write_linear_image(out.path, img);
            std::fprintf(stderr, "candela: %s not written; the image is in %s (linear EXR) instead\n",
                         opt.out.c_str(), out.path.c_str());
        }
    } else {
        if (!aovs.empty() && !opt.quiet)
            std::fprintf(stderr, "candela: warning: the AOV layers are written to .exr output only; %s gets the image\n",
                         opt.out.c_str());
        write_linear_image(opt.out, img);
    }
    return out;
}

void print_memory_summary(const Scene& scene) {
    const Scene::Memory mem = scene.memory();
    const double per_tri = mem.triangles ? 1.0 / double(mem.triangles) : 0.0;
    std::fprintf(stderr, "candela: %zu triangles, %.1f MB (%.1f B/triangle: mesh %.1f, accel %.1f, lights %.1f)\n",
                 mem.triangles, double(mem.total()) / 1e6, double(mem.total()) * per_tri, double(mem.mesh) * per_tri,
                 double(mem.accel) * per_tri, double(mem.lights) * per_tri);
}

namespace {

// pbrt's visualizestrategies: bdpt_s<S>_t<T>_{weighted,unweighted}.exr for every path length up to
// max_depth (5 when unbounded), over as many samples per pixel as the render took.
void write_bdpt_strategies(const HeadlessOptions& opt, const Scene& scene, const Film& film, int threads) {
    std::filesystem::create_directories(opt.bdpt_strategies);
    const uint32_t spp = film.sample_count(0, 0);
    const int max_length = scene.settings.max_depth >= 0 ? scene.settings.max_depth : 5;
    const std::vector<StrategyImage> imgs =
        render_bdpt_strategies(scene, film.width(), film.height(), int(std::max(1u, spp)), threads, max_length);
    for (const StrategyImage& s : imgs) {
        Image im;
        im.width = film.width();
        im.height = film.height();
        const std::string base = opt.bdpt_strategies + "/bdpt_s" + std::to_string(s.s) + "_t" + std::to_string(s.t);
        im.rgb = s.weighted;
        write_linear_image(base + "_weighted.exr", im);
        im.rgb = s.unweighted;
        write_linear_image(base + "_unweighted.exr", im);
    }
    if (!opt.quiet)
        std::fprintf(stderr, "candela: %zu BDPT strategy images (weighted and unweighted) -> %s\n", imgs.size() * 2,
                     opt.bdpt_strategies.c_str());
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
    g_rendering = false;
    clear_interrupt();
    install_signal_handlers();
    auto nothing_written = [&](const char* when) {
        const int sig = g_signal.load();
        std::string kept = opt.checkpoint.empty() ? opt.out + " left as it was"
                                                   : opt.out + " and " + opt.checkpoint + " left as they were";
        std::fprintf(stderr, "candela: %s %s: nothing written (%s)\n", sig == SIGTERM ? "terminated" : "interrupted",
                     when, kept.c_str());
        return 128 + (sig ? sig : SIGINT);
    };

    std::shared_ptr<const Scene> scene_ptr;
    try {
        scene_ptr = prepare_scene(opt.scene, opt.overrides);
    } catch (const Interrupted&) {
        return nothing_written("while loading the scene");
    }
    const Scene& scene = *scene_ptr;
    const RenderSettings& st = scene.settings;
    if (!opt.quiet)
        for (const std::string& w : scene.warnings) std::fprintf(stderr, "candela: warning: %s\n", w.c_str());
    const bool mlt = st.integrator.type == IntegratorType::Pssmlt || st.integrator.type == IntegratorType::Mmlt;
    if (!opt.quiet && st.integrator.type == IntegratorType::Mmlt && !mmlt_depth_note(st.max_depth).empty())
        std::fprintf(stderr, "candela: %s\n", mmlt_depth_note(st.max_depth).c_str());
    const int spp_per_pass = std::max(1, opt.spp_per_frame);
    const uint64_t frames = opt.frames > 0 ? uint64_t(opt.frames) : uint64_t(std::max(1, st.spp / spp_per_pass));
    // Sample indices and per-pixel counts are 32-bit.
    const uint64_t target = frames * uint64_t(spp_per_pass);
    if (target > std::numeric_limits<uint32_t>::max())
        throw Error("--frames x --spp-per-frame is " + std::to_string(target) + " samples per pixel, more than 2^32 - 1");
    check_run_features(st, {false, opt.target_error > 0, !opt.checkpoint.empty() || !opt.resume.empty(),
                            opt.time_limit > 0});
    const std::vector<AovSpec>& aovs = st.integrator.aovs;
    if (!aovs.empty() && !opt.checkpoint.empty())
        throw Error(opt.checkpoint, 0, "checkpoints do not hold the aov integrator's layers; render it without --checkpoint");
    if (!aovs.empty() && !opt.resume.empty())
        throw Error(opt.resume, 0, "checkpoints do not hold the aov integrator's layers; render it without --resume");
    Film film(st.width, st.height);
    configure_film(film, st);
    if (st.alpha) film.enable_alpha();
    const bool adaptive = opt.target_error > 0;
    AdaptiveSettings adapt;
    if (adaptive) {
        // What the unbiased two-half rule is shown for (docs/adaptive.md); the rest is refused.
        const std::string src = scene.source.empty() ? "--target-error" : scene.source;
        if (st.sampler.type != SamplerType::Independent)
            throw Error(src, 0, std::string("--target-error needs the independent sampler (the halves must be "
                                            "independent), not ") + sampler_type_name(st.sampler.type));
        if (film.weighted()) throw Error(src, 0, "--target-error needs the box reconstruction filter");
        if (!aovs.empty()) throw Error(src, 0, "--target-error does not render the aov integrator's layers");
        if (st.alpha) throw Error(src, 0, "--target-error does not render an alpha channel (rgba film)");
        if (!opt.checkpoint.empty() || !opt.resume.empty())
            throw Error("--target-error renders do not checkpoint or resume");
        if (opt.adaptive_min_spp < 4) throw Error("--adaptive-min-spp must be at least 4");
        adapt.target_error = opt.target_error;
        adapt.min_spp = uint32_t(opt.adaptive_min_spp);
        film.enable_adaptive();
    }
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

    g_rendering = true;
    const bool tty = isatty(fileno(stderr)) && !opt.quiet;
    uint64_t samples = 0, rays = 0;
    bool converged = false;  // adaptive: every pixel reached the target error
    bool whole_passes = true;  // false once a pass was cut short: the film is no longer checkpointable
    // The time limit cuts the pass in flight (within a tile per thread), not only between passes.
    std::atomic<bool> time_up{false};
    std::optional<Deadline> deadline;
    if (opt.time_limit > 0)
        deadline.emplace(t0 + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(opt.time_limit)),
                         g_stop_now, time_up);
    while (spp_done < target && g_signal == 0 && !time_up) {
        double elapsed = std::chrono::duration<double>(clock::now() - t0).count();
        if (opt.time_limit > 0 && elapsed >= opt.time_limit) {
            time_up = true;
            break;
        }
        int n = int(std::min<uint64_t>(uint64_t(spp_per_pass), target - spp_done));
        PassStats ps = Renderer::render_pass(scene, film, spp_done, n, threads, &g_stop_now);
        samples += ps.samples;
        rays += ps.rays;
        if (!ps.completed) {
            whole_passes = false;
            break;
        }
        spp_done += uint32_t(n);
        if (adaptive && update_adaptive(film, adapt) == 0) {
            converged = true;
            break;
        }
        if (checkpointing && spp_done < target &&
            std::chrono::duration<double>(clock::now() - last_save).count() >= opt.checkpoint_every)
            save("periodic");
        if (tty) {
            double s = std::chrono::duration<double>(clock::now() - t0).count();
            std::string line = progress_line(spp_done, target, uint64_t(film.width()) * uint64_t(film.height()), s,
                                             s > 0 ? double(samples) / s : 0.0, opt.time_limit);
            std::fprintf(stderr, "\r%s ", line.c_str());
            std::fflush(stderr);
        }
    }
    deadline.reset();
    double secs = std::chrono::duration<double>(clock::now() - t0).count();
    if (tty) std::fprintf(stderr, "\n");
    // A stopped render without one whole pass must not replace an earlier good image with a
    // black or patchy one (nor a checkpoint with an empty one).
    if (g_signal != 0 && spp_done == 0) return nothing_written("before the first pass finished");
    // A cut pass leaves each pixel the plain mean of the samples it has: those it reached have one
    // pass more than the rest. Still an unbiased estimate per pixel, only noisier in places.
    const bool stopped_by_limit = time_up && spp_done < target;
    uint64_t reached = 0;  // pixels with samples of the cut pass
    uint32_t most = spp_done;
    if (!whole_passes && !adaptive) {
        for (uint32_t c : film.counts()) {
            reached += c > spp_done;
            most = std::max(most, c);
        }
        if (reached == 0) whole_passes = true;  // cut before its first tile: the film holds whole passes
    }
    if (stopped_by_limit && reached > 0 && !opt.quiet) {
        std::fprintf(stderr, "candela: the time limit cut the last pass short: %.1f%% of the pixels have %u spp, the others %u\n",
                     100.0 * double(reached) / (double(film.width()) * film.height()), most, spp_done);
    }
    if (stopped_by_limit && film.total_samples() == 0) {
        std::fprintf(stderr, "candela: the time limit ended the render before any tile finished: nothing written (%s "
                             "left as it was)\n", opt.out.c_str());
        return 1;
    }
    if (checkpointing && whole_passes) save("final");

    // MLT: the image is the film with its splats scaled to the latest b (the film, which a
    // checkpoint keeps, is the sum of per-index layers, each at the b of its time).
    const MltStats ms = mlt ? pssmlt_stats() : MltStats{};
    Film shown;
    if (mlt) mlt_output(film, ms, shown);
    const WrittenImage wi = write_headless_image(opt, scene, mlt ? shown : film);
    if (!opt.bdpt_strategies.empty() && !g_signal.load()) write_bdpt_strategies(opt, scene, film, threads);
    const std::string& written = wi.path;
    const bool png_failed = wi.png_failed;

    const int sig = g_signal.load();
    if (!opt.quiet) {
        double spp = double(film.total_samples()) / (double(film.width()) * film.height());
        // Memory first: scripts read the summary from the last line.
        print_memory_summary(scene);
        // MLT: the throughput is that of the mutations, the bootstrap's time apart; b (the image's
        // mean luminance, which scales it) with its standard error.
        std::string rate;
        char buf[256];
        if (mlt && ms.valid) {
            const double start = ms.bootstrap_seconds + ms.replay_seconds, t = secs - start;
            const double rel = ms.b > 0 ? ms.b_std_error / ms.b : 0.0;
            if (rel > 0.01)
                std::fprintf(stderr, "candela: warning: b (the image's brightness) has a relative standard error of %.1f%% "
                                     "(above 1%%): raise bootstrap_samples or render longer\n", 100 * rel);
            char replay[64] = "";
            if (ms.replay_seconds > 0) std::snprintf(replay, sizeof replay, " and a %.2f s replay", ms.replay_seconds);
            std::snprintf(buf, sizeof buf, "%.3f Mmutations/s after a %.2f s bootstrap (%llu paths)%s, b %.5g +- %.2g (%.2f%%)",
                          t > 0 ? samples / t * 1e-6 : 0.0, ms.bootstrap_seconds, (unsigned long long)ms.bootstrap_paths,
                          replay, ms.b, ms.b_std_error, 100 * rel);
            rate = buf;
        } else {
            std::snprintf(buf, sizeof buf, "%.3f Msamples/s", secs > 0 ? samples / secs * 1e-6 : 0.0);
            rate = buf;
        }
        std::fprintf(stderr,
                     "candela: %s%s %dx%d, %s, %.6g spp in %.2f s, %s, %.3f Mrays/s, %d threads, "
                     "accel %s, %llu non-finite samples -> %s\n",
                     sig ? (sig == SIGTERM ? "terminated: " : "interrupted: ") : stopped_by_limit ? "time limit: " : "",
                     scene.source.c_str(), film.width(),
                     film.height(), integrator_summary(st).c_str(), spp, secs, rate.c_str(),
                     secs > 0 ? rays / secs * 1e-6 : 0.0, threads, scene.accel->name().c_str(),
                     (unsigned long long)film.nonfinite_count(), written.c_str());
        if (adaptive) {
            uint64_t active = 0;
            double max_err = 0;
            for (int y = 0; y < film.height(); ++y)
                for (int x = 0; x < film.width(); ++x) {
                    active += film.active(x, y);
                    max_err = std::max(max_err, adaptive_pixel_error(film, x, y));
                }
            std::fprintf(stderr,
                         "candela: adaptive: target error %g %s; %.1f%% of the pixels still active, largest "
                         "estimated error %.4g; the image averages the odd-index half (%.6g spp)\n",
                         opt.target_error, converged ? "reached" : "not reached",
                         100.0 * double(active) / (double(film.width()) * film.height()), max_err,
                         spp / 2);
        }
        if (checkpointing && whole_passes)
            std::fprintf(stderr, "candela: checkpoint %s at %u spp\n", opt.checkpoint.c_str(), spp_done);
        else if (checkpointing)
            std::fprintf(stderr, "candela: checkpoint %s not updated (stopped inside a pass; it keeps the last save)\n",
                         opt.checkpoint.c_str());
    }
    if (png_failed) return 1;  // the file asked for is missing: a failure, even with the EXR beside it
    return sig ? 128 + sig : 0;
}

}  // namespace candela
