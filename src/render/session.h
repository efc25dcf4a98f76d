#pragma once
// A render session: one worker thread that runs passes of the Renderer until told otherwise, for an
// interactive front end that must never wait for a pass.
//
// Threads and ownership. Scenes are immutable (scene/scene.h) and shared as shared_ptr<const Scene>:
// the front end and the worker never write to the same object. The front end keeps its own copy of
// the parameters (SceneParams), edits it and hands it over with update(); the worker is cancelled
// (Renderer::render_pass checks the flag per tile, so it stops within one tile per thread), builds
// the new scene from the old one (Scene::with_params, which shares the geometry and accelerator and
// prepares materials off the window's thread), swaps it in under the lock, clears the films and
// starts again. The front end reads the scene through snapshots (scene()), for picking and names,
// and only ever takes the mutex for a swap of pointers or a few scalars.
//
// What the worker renders after a restart: one preview pass at 1/preview_scale of the resolution,
// shown at once, then full-resolution passes. While the front end says the user is interacting
// (set_interactive, e.g. during a camera drag) it keeps rendering previews only, so each camera
// change costs 1/16 of a pass (less when preview_budget asks for it). Full passes accumulate; each
// completed pass is resolved to RGB and published. A cancelled pass is discarded (its film is
// cleared by the restart), so the film never holds a pixel with the same sample index twice.
#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>
#include "denoise/denoiser.h"
#include "film/film.h"
#include "film/pass_halves.h"
#include "scene/scene.h"

namespace candela {

// How the render threads share the CPU with the rest of the machine (Linux; elsewhere Normal).
//   Normal  the default priority of the process
//   Low     nice 19: every normal-priority thread is scheduled first, the render gets what is left
//           (about 1.5% of a core against each busy normal thread)
//   Idle    SCHED_IDLE: the render runs only on CPU time nothing else wants. On 2 cores with a
//           software GL this is what keeps the window's frames on time (docs/viewer.md), but a
//           busy machine can stall the render entirely.
enum class RenderPriority { Normal, Low, Idle };
RenderPriority parse_render_priority(const std::string& s);  // normal | low | idle; throws Error
const char* render_priority_name(RenderPriority p);

struct SessionOptions {
    int threads = 0;        // render threads; <= 0: all cores
    int spp_per_pass = 1;   // samples per pixel in each full-resolution pass
    int preview_scale = 4;  // preview passes render (width / scale) x (height / scale) pixels
    double preview_budget = 0;  // > 0: seconds a preview pass should take; the scale grows (up
                                // to 16) when the measured speed says preview_scale is too slow
    int max_passes = 0;     // idle after this many full passes (0: never), e.g. for screenshots
    RenderPriority priority = RenderPriority::Normal;  // of the worker and its OpenMP threads
};

// A resolved image, as published to the front end.
struct SessionImage {
    int width = 0, height = 0;
    std::vector<float> rgb;   // linear RGB, row-major from the top-left
    bool preview = false;     // reduced resolution: scale it up to the full image's size
    uint64_t generation = 0;  // which restart it belongs to (see SessionStats::generation)
    uint64_t sequence = 0;    // increases with every publish, across restarts
    int passes = 0;           // full passes in it (preview: preview passes)
};

struct SessionStats {
    uint64_t generation = 0;  // restarts so far (0: the first render)
    int passes = 0;           // completed full-resolution passes since the restart
    double spp = 0;           // samples per pixel in the full film
    double elapsed = 0;       // seconds of rendering since the restart (paused time excluded)
    double msamples_per_s = 0, mrays_per_s = 0;  // over the full passes of this generation
    uint64_t splats = 0;        // light-path contributions splatted (ptracer), this generation
    double msplats_per_s = 0;
    uint64_t nonfinite = 0;   // NaN/Inf samples dropped by the film (Film::nonfinite_count)
    bool paused = false, idle = false, preview = false;
    std::string error;        // why the last update() was refused (the render goes on without it)
    // Convergence: after every full pass k >= 2, the mean over pixels of |L_k - L_{k-1}| / (L_{k-1} + eps)
    // on luminance, with the time it was measured (seconds since the restart).
    std::vector<float> change, change_time;
    // The estimated error of the image (film/pass_halves.h: RMS over pixels of the relative
    // standard error, from the even and odd passes) after every full pass k >= 2, its history
    // (estimate_time: seconds since the restart), and whether it fell below the target error
    // (set_target_error), which stops the full passes.
    double estimate = -1;  // -1: not yet (fewer than 2 passes)
    std::vector<float> estimates, estimate_time;
    bool target_reached = false;
};

class RenderSession {
public:
    // Starts the worker at once.
    RenderSession(std::shared_ptr<const Scene> scene, const SessionOptions& opt);
    // Cancels the pass in flight and joins the worker (at most one tile per thread of waiting).
    ~RenderSession();
    RenderSession(const RenderSession&) = delete;
    RenderSession& operator=(const RenderSession&) = delete;

    // A snapshot of the scene being rendered (or of the one replace_scene handed over). Immutable:
    // any thread may read all of it. Parameters sent by update() appear in it once the worker has
    // taken them.
    std::shared_ptr<const Scene> scene() const;

    // Every edit that changes the image goes through here: cancels the pass in flight and restarts
    // with `p`, which must fit the scene's geometry (Scene::with_params; when it does not, the worker
    // keeps the old parameters and SessionStats::error says why). Returns at once; the new
    // generation number is returned.
    uint64_t update(const SceneParams& p);
    // A new scene (e.g. a dropped file), with its own parameters. Restarts.
    uint64_t replace_scene(std::shared_ptr<const Scene> scene);
    // Clears the film and starts again with the same parameters.
    uint64_t reset();

    // While true, only preview passes are rendered. Does not restart: turning it off lets the
    // worker begin full passes on the (already cleared) film.
    void set_interactive(bool on);
    // Paused: no more full passes after the one in flight (which completes). Edits while paused
    // still restart and render one preview, so that the image shows them.
    void set_paused(bool on);
    bool paused() const { return paused_.load(); }
    // Full passes stop once the estimated error (SessionStats::estimate) is below `e` (<= 0: never).
    // Does not restart: a lower target resumes the render where it stopped.
    void set_target_error(double e);
    double target_error() const { return target_error_.load(); }
    // Thread count for the next pass; does not change the image (it does not depend on it).
    void set_threads(int n) { threads_.store(n); }
    int threads() const;

    // Moves the newest published image into `img` when it is newer than img.sequence (the old
    // buffer is recycled by the worker). Returns false, leaving img alone, when there is none.
    bool take_image(SessionImage& img);
    // The newest full-resolution image, copied (e.g. for saving). Empty before the first full pass.
    SessionImage latest_full_image() const;
    SessionStats stats() const;
    // Called on the worker thread after each publish (e.g. glfwPostEmptyEvent to wake the UI loop).
    // Set it before rendering matters; it must be cheap and thread-safe.
    void set_on_publish(std::function<void()> f);

    // Blocks until an image of generation >= gen with at least `passes` full passes (0: any
    // image, preview included) is published, or the timeout expires. For tests and tools only.
    bool wait_for(uint64_t gen, int passes, double timeout_seconds);

    // Denoising (docs/denoising.md). While on, every full pass's film is handed to a background
    // denoiser (render/denoise_worker.h, its own thread, started on the first call), which keeps
    // the newest; turning it on while the render rests hands over the film as it is. The scene's
    // denoiser layers (SceneOverrides::denoise_aux) feed it albedo and normal.
    void set_denoise(bool on, DenoiseQuality q);
    bool denoise_on() const;
    // Moves the newest denoised image into `img` when newer than img.sequence.
    bool take_denoised(SessionImage& img);
    // Why the last denoise failed (empty: it did not or none ran) and how long the last one took.
    std::string denoise_error() const;
    double denoise_seconds() const;
    // As wait_for, for the denoised image; false too when a denoise failed.
    bool wait_for_denoised(uint64_t gen, int passes, double timeout_seconds);

private:
    struct Pending;
    void worker();
    // Resolves the film and publishes it. update_stats runs under the same lock, with the
    // convergence measure of a full pass against the previous one (-1 when there is none).
    void publish(const Film& film, bool preview, uint64_t gen, int passes,
                 const std::function<void(SessionStats&, double)>& update_stats);
    uint64_t request_restart_locked();

    SessionOptions opt_;
    std::thread thread_;
    std::atomic<bool> cancel_{false};
    std::atomic<bool> paused_{false};
    std::atomic<int> threads_{0};
    std::atomic<double> target_error_{0.0};

    mutable std::mutex mu_;  // guards everything below
    std::condition_variable cv_;
    std::condition_variable published_cv_;
    bool quit_ = false;
    bool interactive_ = false;
    std::unique_ptr<Pending> pending_;  // edits not yet seen by the worker
    uint64_t generation_ = 0;           // latest requested generation
    std::shared_ptr<const Scene> scene_;  // the snapshot the worker renders
    SessionImage front_;                // newest published image (swapped out by take_image)
    SessionImage full_;                 // newest full-resolution image
    uint64_t sequence_ = 0;
    SessionStats stats_;
    std::function<void()> on_publish_;
    uint64_t published_generation_ = 0;
    bool denoise_on_ = false, denoise_request_ = false;
    std::unique_ptr<class DenoiseWorker> denoiser_;  // created by the first set_denoise(true)

    // The worker's own buffers (no lock): the next image to publish, the previous full pass.
    SessionImage back_;
    std::vector<float> last_full_;
    PassHalvesError halves_;
};

// Mean relative change of luminance between two RGB images of the same size, over pixels where
// either is non-zero: mean(|a - b| / (b + eps)). The convergence measure the session plots.
double mean_relative_change(const std::vector<float>& a, const std::vector<float>& b, float eps = 1e-3f);

}  // namespace candela
