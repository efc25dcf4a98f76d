#include "render/denoise_worker.h"
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <chrono>

namespace candela {

DenoiseWorker::DenoiseWorker(DenoiseQuality q, bool low_priority, std::function<void()> on_done)
    : quality_(q), on_done_(std::move(on_done)), thread_([this, low_priority] { run(low_priority); }) {}

DenoiseWorker::~DenoiseWorker() {
    {
        std::lock_guard<std::mutex> lock(mu_);
        quit_ = true;
    }
    cv_.notify_all();
    thread_.join();
}

void DenoiseWorker::submit(DenoiseImages in, uint64_t generation, int passes) {
    {
        std::lock_guard<std::mutex> lock(mu_);
        input_ = std::move(in);
        input_gen_ = generation;
        input_passes_ = passes;
    }
    cv_.notify_all();
}

void DenoiseWorker::set_quality(DenoiseQuality q) {
    std::lock_guard<std::mutex> lock(mu_);
    quality_ = q;
}

bool DenoiseWorker::take(SessionImage& img) {
    std::lock_guard<std::mutex> lock(mu_);
    if (out_.sequence <= img.sequence || out_.rgb.empty()) return false;
    img = out_;  // a copy: the worker keeps its own for the next take
    return true;
}

std::string DenoiseWorker::error() const {
    std::lock_guard<std::mutex> lock(mu_);
    return error_;
}

double DenoiseWorker::last_seconds() const {
    std::lock_guard<std::mutex> lock(mu_);
    return seconds_;
}

bool DenoiseWorker::wait_for(uint64_t gen, int passes, double timeout_seconds) {
    std::unique_lock<std::mutex> lock(mu_);
    return done_cv_.wait_for(lock, std::chrono::duration<double>(timeout_seconds), [&] {
        return !error_.empty() || (!out_.rgb.empty() && out_.generation >= gen && out_.passes >= passes);
    }) && error_.empty();
}

void DenoiseWorker::run(bool low_priority) {
    // Linux schedules threads: this lowers this thread only (and the library's pool threads it
    // starts, which inherit it).
    if (low_priority) setpriority(PRIO_PROCESS, id_t(syscall(SYS_gettid)), 19);
    Denoiser denoiser;
    std::vector<float> result;
    for (;;) {
        DenoiseImages in;
        uint64_t gen;
        int passes;
        {
            std::unique_lock<std::mutex> lock(mu_);
            cv_.wait(lock, [&] { return quit_ || input_.has_value(); });
            if (quit_) return;
            in = std::move(*input_);
            input_.reset();
            gen = input_gen_;
            passes = input_passes_;
            denoiser.set_quality(quality_);
        }
        const auto t0 = std::chrono::steady_clock::now();
        std::string error;
        try {
            denoiser.denoise(in, result);
        } catch (const DenoiseError& e) {
            error = e.what();
        }
        const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        {
            std::lock_guard<std::mutex> lock(mu_);
            error_ = error;
            if (error.empty()) {
                out_.width = in.width;
                out_.height = in.height;
                std::swap(out_.rgb, result);
                out_.preview = false;
                out_.generation = gen;
                out_.passes = passes;
                out_.sequence = ++sequence_;
                seconds_ = dt;
            }
        }
        done_cv_.notify_all();
        if (on_done_) on_done_();
    }
}

}  // namespace candela
