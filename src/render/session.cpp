#include "render/session.h"
#include <omp.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <chrono>
#include <cerrno>
#include <cmath>
#include "core/error.h"
#include "render/denoise_worker.h"
#include "render/renderer.h"

namespace candela {

namespace {

// While the user keeps interacting without changing anything (a held mouse button), previews
// accumulate up to this many passes, then the worker rests.
constexpr int kMaxPreviewPasses = 64;
// The convergence history is halved (every other point dropped) when it reaches this length, so a
// long session plots its whole history at a bounded cost.
constexpr size_t kMaxHistory = 1024;

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

template <class T>
void decimate(std::vector<T>& v) {
    size_t n = 0;
    for (size_t i = 0; i < v.size(); i += 2) v[n++] = v[i];
    v.resize(n);
}

}  // namespace

double mean_relative_change(const std::vector<float>& a, const std::vector<float>& b, float eps) {
    if (a.size() != b.size() || a.empty()) return 0.0;
    double sum = 0.0;
    size_t n = 0;
    for (size_t i = 0; i + 2 < a.size(); i += 3) {
        float la = luminance(vec3(a[i], a[i + 1], a[i + 2]));
        float lb = luminance(vec3(b[i], b[i + 1], b[i + 2]));
        if (!(la > 0.f || lb > 0.f)) continue;  // black in both (also skips NaN)
        sum += std::fabs(double(la) - double(lb)) / (double(std::fabs(lb)) + eps);
        ++n;
    }
    return n > 0 ? sum / double(n) : 0.0;
}

// Edits the front end has handed over and the worker has not yet applied.
struct RenderSession::Pending {
    std::shared_ptr<const Scene> scene;  // non-null: switch to this scene (with its own parameters)
    bool has_params = false;
    SceneParams params;
};

RenderSession::RenderSession(std::shared_ptr<const Scene> scene, const SessionOptions& opt) : opt_(opt) {
    opt_.spp_per_pass = std::max(1, opt_.spp_per_pass);
    opt_.preview_scale = std::max(1, opt_.preview_scale);
    threads_ = opt.threads;
    // The first generation is a replacement of "no scene" by this one: the worker sets up films.
    pending_ = std::make_unique<Pending>();
    pending_->scene = std::move(scene);
    thread_ = std::thread([this] { worker(); });
}

RenderSession::~RenderSession() {
    {
        std::lock_guard<std::mutex> lock(mu_);
        quit_ = true;
        cancel_ = true;
    }
    cv_.notify_all();
    thread_.join();
}

std::shared_ptr<const Scene> RenderSession::scene() const {
    std::lock_guard<std::mutex> lock(mu_);
    if (pending_ && pending_->scene) return pending_->scene;
    return scene_;
}

uint64_t RenderSession::request_restart_locked() {
    if (!pending_) pending_ = std::make_unique<Pending>();
    cancel_ = true;
    return ++generation_;
}

uint64_t RenderSession::update(const SceneParams& p) {
    uint64_t gen;
    {
        std::lock_guard<std::mutex> lock(mu_);
        gen = request_restart_locked();
        pending_->has_params = true;
        pending_->params = p;
    }
    cv_.notify_all();
    return gen;
}

uint64_t RenderSession::replace_scene(std::shared_ptr<const Scene> scene) {
    uint64_t gen;
    {
        std::lock_guard<std::mutex> lock(mu_);
        gen = request_restart_locked();
        pending_->scene = std::move(scene);
        pending_->has_params = false;  // edits made for the old scene do not apply to the new one
    }
    cv_.notify_all();
    return gen;
}

uint64_t RenderSession::reset() {
    uint64_t gen;
    {
        std::lock_guard<std::mutex> lock(mu_);
        gen = request_restart_locked();
    }
    cv_.notify_all();
    return gen;
}

void RenderSession::set_interactive(bool on) {
    {
        std::lock_guard<std::mutex> lock(mu_);
        if (interactive_ == on) return;
        interactive_ = on;
    }
    cv_.notify_all();
}

void RenderSession::set_paused(bool on) {
    {
        std::lock_guard<std::mutex> lock(mu_);
        paused_ = on;
    }
    cv_.notify_all();
}

void RenderSession::set_target_error(double e) {
    {
        std::lock_guard<std::mutex> lock(mu_);
        target_error_ = e;
        stats_.target_reached = e > 0 && stats_.estimate >= 0 && stats_.estimate < e;
    }
    cv_.notify_all();
}

int RenderSession::threads() const {
    int n = threads_.load();
    return n > 0 ? n : omp_get_max_threads();
}

bool RenderSession::take_image(SessionImage& img) {
    std::lock_guard<std::mutex> lock(mu_);
    if (front_.sequence <= img.sequence || front_.rgb.empty()) return false;
    std::swap(img, front_);
    return true;
}

SessionImage RenderSession::latest_full_image() const {
    std::lock_guard<std::mutex> lock(mu_);
    return full_;
}

SessionStats RenderSession::stats() const {
    std::lock_guard<std::mutex> lock(mu_);
    SessionStats s = stats_;
    s.paused = paused_.load();
    return s;
}

void RenderSession::set_on_publish(std::function<void()> f) {
    std::lock_guard<std::mutex> lock(mu_);
    on_publish_ = std::move(f);
}

bool RenderSession::wait_for(uint64_t gen, int passes, double timeout_seconds) {
    std::unique_lock<std::mutex> lock(mu_);
    auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_seconds));
    return published_cv_.wait_until(lock, deadline, [&] {
        if (passes > 0) return !full_.rgb.empty() && full_.generation >= gen && full_.passes >= passes;
        return sequence_ > 0 && published_generation_ >= gen;
    });
}

void RenderSession::publish(const Film& film, bool preview, uint64_t gen, int passes,
                            const std::function<void(SessionStats&, double)>& update_stats) {
    // Resolve and copy outside the lock, into recycled buffers; the lock covers swaps only.
    film.resolve_into(back_.rgb);
    back_.width = film.width();
    back_.height = film.height();
    back_.preview = preview;
    back_.generation = gen;
    back_.passes = passes;
    double change = -1;
    SessionImage full_copy;
    if (!preview) {
        if (last_full_.size() == back_.rgb.size()) change = mean_relative_change(back_.rgb, last_full_);
        last_full_ = back_.rgb;
        full_copy = back_;  // kept apart from the recycled buffers, for saving
    }
    std::function<void()> notify;
    {
        std::lock_guard<std::mutex> lock(mu_);
        back_.sequence = full_copy.sequence = ++sequence_;
        published_generation_ = gen;
        if (!preview) std::swap(full_, full_copy);
        std::swap(back_, front_);
        update_stats(stats_, change);  // in the same lock: stats always describe the newest image
        notify = on_publish_;
    }
    published_cv_.notify_all();
    if (notify) notify();
}

void RenderSession::set_denoise(bool on, DenoiseQuality q) {
    {
        std::lock_guard<std::mutex> lock(mu_);
        if (on && !denoiser_)
            denoiser_ = std::make_unique<DenoiseWorker>(q, opt_.priority != RenderPriority::Normal, [this] {
                std::function<void()> notify;
                {
                    std::lock_guard<std::mutex> l(mu_);
                    notify = on_publish_;
                }
                if (notify) notify();  // a denoised image is news for the front end too
            });
        if (denoiser_) denoiser_->set_quality(q);
        denoise_request_ = on;  // the worker hands over the film it has
        denoise_on_ = on;
    }
    cv_.notify_all();
}

bool RenderSession::denoise_on() const {
    std::lock_guard<std::mutex> lock(mu_);
    return denoise_on_;
}

bool RenderSession::take_denoised(SessionImage& img) {
    DenoiseWorker* dw;
    {
        std::lock_guard<std::mutex> lock(mu_);
        dw = denoiser_.get();  // never destroyed before the session
    }
    return dw && dw->take(img);
}

std::string RenderSession::denoise_error() const {
    std::lock_guard<std::mutex> lock(mu_);
    return denoiser_ ? denoiser_->error() : std::string();
}

double RenderSession::denoise_seconds() const {
    std::lock_guard<std::mutex> lock(mu_);
    return denoiser_ ? denoiser_->last_seconds() : 0.0;
}

bool RenderSession::wait_for_denoised(uint64_t gen, int passes, double timeout_seconds) {
    DenoiseWorker* dw;
    {
        std::lock_guard<std::mutex> lock(mu_);
        dw = denoiser_.get();
    }
    return dw && dw->wait_for(gen, passes, timeout_seconds);
}

RenderPriority parse_render_priority(const std::string& s) {
    if (s == "normal") return RenderPriority::Normal;
    if (s == "low") return RenderPriority::Low;
    if (s == "idle") return RenderPriority::Idle;
    throw Error("unknown render priority '" + s + "' (expected normal, low or idle)");
}

const char* render_priority_name(RenderPriority p) {
    switch (p) {
        case RenderPriority::Normal: return "normal";
        case RenderPriority::Low: return "low";
        case RenderPriority::Idle: return "idle";
    }
    return "?";
}

void RenderSession::worker() {
    // Linux schedules threads, not processes: this lowers the worker's priority, and the OpenMP
    // threads it creates for its passes inherit it (libgomp keeps a thread pool per master thread).
    // Lowering a priority never needs privileges.
    if (opt_.priority != RenderPriority::Normal) {
        const id_t tid = id_t(syscall(SYS_gettid));
        setpriority(PRIO_PROCESS, tid, 19);
        if (opt_.priority == RenderPriority::Idle) {
            sched_param sp{};
            sp.sched_priority = 0;
            sched_setscheduler(0, SCHED_IDLE, &sp);  // 0: the calling thread
        }
    }
    Film full, preview;
    std::shared_ptr<const Scene> scene;
    uint64_t gen = 0;
    int passes = 0, preview_passes = 0;
    bool need_preview = false;
    int full_w = 0, full_h = 0, prev_w = 0, prev_h = 0;
    double render_time = 0, full_time = 0;
    double sec_per_sample = 0;  // measured, smoothed over passes: sizes the previews
    uint64_t full_samples = 0, full_rays = 0, full_splats = 0;  // splats: ptracer
    auto last_tick = Clock::now();

    enum class Job { None, Preview, Full };
    auto next_job = [&]() {  // called with mu_ held
        if (!scene) return Job::None;
        if (need_preview) return Job::Preview;
        if (interactive_) return preview_passes < kMaxPreviewPasses ? Job::Preview : Job::None;
        if (paused_.load()) return Job::None;
        if (opt_.max_passes > 0 && passes >= opt_.max_passes) return Job::None;
        if (stats_.target_reached) return Job::None;
        return Job::Full;
    };

    // Hands the full film to the denoiser when it is on (the film's images, resolved here).
    auto submit_denoise = [&]() {
        DenoiseWorker* dw = nullptr;
        {
            std::lock_guard<std::mutex> lock(mu_);
            denoise_request_ = false;
            if (denoise_on_) dw = denoiser_.get();
        }
        if (dw && passes > 0) dw->submit(denoise_inputs(full, scene->settings.integrator.aovs), gen, passes);
    };

    for (;;) {
        std::unique_ptr<Pending> pending;
        Job job;
        bool denoise_request = false;
        {
            std::unique_lock<std::mutex> lock(mu_);
            stats_.idle = true;
            cv_.wait(lock, [&] { return quit_ || pending_ || denoise_request_ || next_job() != Job::None; });
            if (quit_) return;
            denoise_request = denoise_request_ && !pending_;
            if (pending_) {
                pending = std::move(pending_);
                gen = generation_;
                cancel_ = false;  // reset together with taking the edits: no request is lost
                if (pending->scene) scene_ = pending->scene;
            }
            stats_.idle = false;
        }

        if (pending) {
            // Apply the edits: a new immutable scene, built here (materials may take time to
            // prepare), then published as the front end's snapshot.
            if (pending->scene) scene = pending->scene;
            std::string error;
            if (pending->has_params) {
                try {
                    scene = scene->with_params(pending->params);
                } catch (const std::exception& e) {
                    error = e.what();  // keep rendering the last good parameters
                }
                std::lock_guard<std::mutex> lock(mu_);
                scene_ = scene;
            }
            full_w = scene->settings.width;
            full_h = scene->settings.height;
            // The preview's scale: at least preview_scale, more when the last passes say that a
            // preview at that scale would take longer than the budget (a slow scene or machine).
            int scale = opt_.preview_scale;
            if (opt_.preview_budget > 0 && sec_per_sample > 0) {
                double samples = opt_.preview_budget / sec_per_sample;
                double need = std::ceil(std::sqrt(double(full_w) * double(full_h) / std::max(samples, 1.0)));
                scale = int(std::clamp(need, double(opt_.preview_scale), double(std::max(opt_.preview_scale, 16))));
            }
            prev_w = std::max(1, full_w / scale);
            prev_h = std::max(1, full_h / scale);
            full.resize(full_w, full_h);
            preview.resize(prev_w, prev_h);
            passes = preview_passes = 0;
            need_preview = true;
            last_full_.clear();
            halves_.reset();
            render_time = full_time = 0;
            full_samples = full_rays = full_splats = 0;
            std::lock_guard<std::mutex> lock(mu_);
            stats_ = SessionStats();
            stats_.generation = gen;
            stats_.preview = true;
            stats_.error = error;
            job = next_job();
        } else {
            std::lock_guard<std::mutex> lock(mu_);
            job = next_job();
        }
        if (denoise_request) submit_denoise();
        if (job == Job::None) continue;

        const bool is_preview = job == Job::Preview;
        Film& film = is_preview ? preview : full;
        const int spp = is_preview ? 1 : opt_.spp_per_pass;
        const int index = is_preview ? preview_passes : passes;
        last_tick = Clock::now();
        PassStats ps = Renderer::render_pass(*scene, film, uint32_t(index) * uint32_t(spp), spp, threads_.load(), &cancel_);
        double dt = seconds_since(last_tick);
        if (!ps.completed) continue;  // cancelled: a restart is pending and will clear the film

        render_time += dt;
        if (ps.samples > 0) {
            double s = dt / double(ps.samples);
            sec_per_sample = sec_per_sample > 0 ? 0.7 * sec_per_sample + 0.3 * s : s;
        }
        if (is_preview) {
            ++preview_passes;
            need_preview = false;
            publish(film, true, gen, preview_passes, [&](SessionStats& s, double) { s.elapsed = render_time; });
            continue;
        }
        halves_.add_pass(film, passes);
        const double estimate = halves_.relative_rms(film);
        ++passes;
        full_time += dt;
        full_samples += ps.samples;
        full_rays += ps.rays;
        full_splats += ps.splats;
        publish(film, false, gen, passes, [&](SessionStats& s, double change) {
            s.passes = passes;
            s.spp = double(passes) * spp;
            s.elapsed = render_time;
            s.msamples_per_s = full_time > 0 ? double(full_samples) / full_time * 1e-6 : 0;
            s.mrays_per_s = full_time > 0 ? double(full_rays) / full_time * 1e-6 : 0;
            s.splats = full_splats;
            s.msplats_per_s = full_time > 0 ? double(full_splats) / full_time * 1e-6 : 0;
            s.nonfinite = full.nonfinite_count();
            s.preview = false;
            if (estimate >= 0) {
                s.estimate = estimate;
                const double target = target_error_.load();
                s.target_reached = target > 0 && estimate < target;
                if (s.estimates.size() >= kMaxHistory) {
                    decimate(s.estimates);
                    decimate(s.estimate_time);
                }
                s.estimates.push_back(float(estimate));
                s.estimate_time.push_back(float(render_time));
            }
            if (change < 0) return;
            if (s.change.size() >= kMaxHistory) {
                decimate(s.change);
                decimate(s.change_time);
            }
            s.change.push_back(float(change));
            s.change_time.push_back(float(render_time));
        });
        submit_denoise();
    }
}

}  // namespace candela
