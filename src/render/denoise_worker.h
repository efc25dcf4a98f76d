#pragma once
// Denoising in the background for the viewer (docs/denoising.md): a thread of its own takes the
// newest film handed to it and denoises it; a film handed over while it works replaces the one
// waiting (never queued), so it always works on the newest passes and the render never waits for
// it, nor the window. The denoised images are published like the session's (SessionImage, with
// the generation and passes of the film they came from), for the front end to take.
#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include "denoise/denoiser.h"
#include "render/session.h"

namespace candela {

class DenoiseWorker {
public:
    // Starts the thread, at nice 19 when `low_priority` (above an idle-priority render, below the
    // window). `on_done` runs on its thread after each denoise (e.g. to wake the window).
    DenoiseWorker(DenoiseQuality q, bool low_priority, std::function<void()> on_done = {});
    ~DenoiseWorker();  // waits for the denoise in flight (one image's worth)
    DenoiseWorker(const DenoiseWorker&) = delete;
    DenoiseWorker& operator=(const DenoiseWorker&) = delete;

    // Hands over a film's images; replaces any not yet started.
    void submit(DenoiseImages in, uint64_t generation, int passes);
    void set_quality(DenoiseQuality q);
    // Moves the newest denoised image into `img` when newer than img.sequence.
    bool take(SessionImage& img);
    // Why the last denoise failed (empty: it did not), and how long the last success took.
    std::string error() const;
    double last_seconds() const;
    // Blocks until an image of generation >= gen with >= passes is published, or a denoise fails,
    // or the timeout expires. For tests and tools.
    bool wait_for(uint64_t gen, int passes, double timeout_seconds);

private:
    void run(bool low_priority);

    mutable std::mutex mu_;
    std::condition_variable cv_, done_cv_;
    bool quit_ = false;
    std::optional<DenoiseImages> input_;  // waiting to be denoised
    uint64_t input_gen_ = 0;
    int input_passes_ = 0;
    DenoiseQuality quality_;
    SessionImage out_;
    uint64_t sequence_ = 0;
    std::string error_;
    double seconds_ = 0;
    std::function<void()> on_done_;
    std::thread thread_;  // last: starts once the members above exist
};

}  // namespace candela
