#include "app/mpi_run.h"
#include <mpi.h>
#include <omp.h>
#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>
#include "app/checkpoint.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/progress.h"
#include "film/image_io.h"
#include "render/launch.h"
#include "render/renderer.h"

namespace candela {

bool launched_by_mpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
        if (std::getenv(v)) return true;
    return false;
}

namespace {

// Messages. A worker (rank > 0) sends kRequest (an int32: 0, or 1 | signal << 8 when it was
// signalled) and rank 0 answers kAssign (uint32 first sample index, count; count 0: finished).
// The worker then renders the chunk and sends one kLayer per sample index. kStop (empty, rank 0 to
// a busy worker) cuts the chunk in flight: the worker sends what it has and asks again.
enum Tag : int { kRequest = 1, kAssign = 2, kLayer = 3, kStop = 4 };

std::atomic<int> g_signal{0};  // the first SIGINT/SIGTERM this rank received
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void on_mpi_signal(int sig) {
    int none = 0;
    g_signal.compare_exchange_strong(none, sig);
    request_interrupt();  // stops a scene load or accelerator build
}

void install_handlers() {
    struct sigaction sa {};
    sa.sa_handler = on_mpi_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

// The fixed part of a layer message; the film's arrays follow (pack_layer).
struct LayerHeader {
    uint32_t index = 0;     // the sample index the layer holds
    uint32_t complete = 0;  // 1: every tile; 0: cut by a stop
    uint64_t samples = 0, rays = 0, nonfinite = 0;
    uint32_t has_splats = 0, pad = 0;
    uint64_t splat_paths = 0;  // light paths traced for the layer's splats (light tracing)
};

template <class T>
void put(std::vector<char>& b, const std::vector<T>& v) {
    const size_t at = b.size();
    b.resize(at + v.size() * sizeof(T));
    if (!v.empty()) std::memcpy(b.data() + at, v.data(), v.size() * sizeof(T));
}

// A layer is a whole film of the render's layout (doubles: 24 B of sums and 4 B of counts per
// pixel, plus weights, AOVs and alpha where the scene has them).
std::vector<char> pack_layer(const Film& f, uint32_t index, const PassStats& ps) {
    LayerHeader h;
    h.index = index;
    h.complete = ps.completed ? 1 : 0;
    h.samples = ps.samples;
    h.rays = ps.rays;
    h.nonfinite = f.nonfinite_count();
    h.has_splats = f.splat_sums().empty() ? 0 : 1;
    h.splat_paths = f.splat_paths();
    std::vector<char> b(sizeof h);
    std::memcpy(b.data(), &h, sizeof h);
    put(b, f.sums());  // the doubles first, so that they are aligned when read in place
    if (f.weighted()) put(b, f.weights());
    put(b, f.aov_sums());
    if (f.has_alpha()) put(b, f.alpha_sums());
    if (h.has_splats) put(b, f.splat_sums());
    put(b, f.counts());
    if (b.size() > size_t(INT_MAX)) throw Error("the image is too large for one MPI message (2 GB): render it in crops");
    return b;
}

// A received layer message, its arrays read in place (pack_layer's order; the buffer stays owned
// by the message).
struct LayerView {
    LayerHeader h;
    const dvec3* sums = nullptr;
    const double *weights = nullptr, *aov = nullptr, *alpha = nullptr;
    const dvec3* splats = nullptr;
    const uint32_t* counts = nullptr;
};

template <class T>
const T* take(const char*& p, const char* end, size_t n) {
    if (size_t(end - p) < n * sizeof(T)) throw Error("internal error: a short MPI layer message");
    const T* v = reinterpret_cast<const T*>(p);
    p += n * sizeof(T);
    return v;
}

LayerView view_layer(const std::vector<char>& b, const Film& like) {
    LayerView v;
    if (b.size() < sizeof v.h) throw Error("internal error: a short MPI layer message");
    std::memcpy(&v.h, b.data(), sizeof v.h);
    const char* p = b.data() + sizeof v.h;
    const char* end = b.data() + b.size();
    const size_t n = size_t(like.width()) * size_t(like.height());
    v.sums = take<dvec3>(p, end, n);
    if (like.weighted()) v.weights = take<double>(p, end, n);
    v.aov = take<double>(p, end, n * size_t(like.aov_channels()));
    if (like.has_alpha()) v.alpha = take<double>(p, end, n);
    if (v.h.has_splats) v.splats = take<dvec3>(p, end, n);
    v.counts = take<uint32_t>(p, end, n);
    if (p != end) throw Error("internal error: an MPI layer message of the wrong size (do the ranks run the same build?)");
    return v;
}

// Test hooks, "r:n" in the environment: CANDELA_MPI_TEST_SLOW_RANK (rank r sleeps n ms per chunk,
// for the load-balance test) and CANDELA_MPI_TEST_DIE_RANK (rank r kills itself with SIGKILL when
// given its n-th chunk, for the failure test). 0 when unset or for another rank.
int test_hook(const char* name, int rank) {
    const char* v = std::getenv(name);
    if (!v) return 0;
    int r = -1, ms = 0;
    if (std::sscanf(v, "%d:%d", &r, &ms) != 2 || r != rank) return 0;
    return std::max(0, ms);
}

// A layer on rank 0: rendered there (a film) or received (the message, read in place).
struct Layer {
    std::unique_ptr<Film> film;
    std::vector<char> bytes;
    void add_to(Film& total) const {
        if (film) {
            total.add(*film);
            return;
        }
        const LayerView v = view_layer(bytes, total);
        total.add(v.sums, v.counts, v.weights, v.aov, v.alpha, v.splats, v.h.splat_paths, v.h.nonfinite);
    }
};

// Rank 0's film: the layers added in sample-index order. Layers that arrive before their turn wait
// in `early`; layers cut by a stop wait in `cut` and are added at the end (after the checkpoint,
// which must hold whole sample indices). Guarded by `m`.
struct Reducer {
    std::mutex m;
    Film* total = nullptr;
    uint32_t next = 0;  // total holds sample indices [0, next) of every pixel
    std::map<uint32_t, Layer> early;
    std::vector<std::pair<uint32_t, Layer>> cut;
    uint64_t samples = 0, rays = 0, layers = 0;
    double add_seconds = 0;  // time spent adding layers (the reduction's cost on rank 0)

    void deliver(uint32_t index, bool complete, Layer layer, uint64_t s, uint64_t r) {
        std::lock_guard<std::mutex> lock(m);
        samples += s;
        rays += r;
        if (!complete) {
            cut.emplace_back(index, std::move(layer));
            return;
        }
        ++layers;
        if (index != next) {
            early.emplace(index, std::move(layer));
            return;
        }
        const auto t0 = std::chrono::steady_clock::now();
        layer.add_to(*total);
        ++next;
        for (auto it = early.begin(); it != early.end() && it->first == next; it = early.erase(it)) {
            it->second.add_to(*total);
            ++next;
        }
        add_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    // Everything into the film, in index order: the image of a stopped render.
    void finish() {
        std::lock_guard<std::mutex> lock(m);
        for (auto& [i, l] : early) l.add_to(*total);
        early.clear();
        std::sort(cut.begin(), cut.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
        for (auto& [i, l] : cut) l.add_to(*total);
        cut.clear();
    }
};

// Rank 0's share of the work: chunks of `chunk` sample indices, first come first served.
struct Dispenser {
    uint32_t next = 0, target = 0, chunk = 1;
    bool stopped = false;
    std::vector<uint64_t> chunks_per_rank;
    bool take(int rank, uint32_t& first, uint32_t& count) {
        if (stopped || next >= target) return false;
        first = next;
        count = std::min(chunk, target - next);
        next += count;
        ++chunks_per_rank[size_t(rank)];
        return true;
    }
};

// Renders a chunk, one sample index per layer (each into a zeroed film), until done or cancelled.
template <class MakeFilm, class Deliver>
void render_chunk(const Scene& scene, uint32_t first, uint32_t count, int threads, const std::atomic<bool>& cancel,
                  const MakeFilm& make_film, const Deliver& deliver) {
    for (uint32_t s = first; s < first + count; ++s) {
        std::unique_ptr<Film> layer = make_film();
        PassStats ps = Renderer::render_pass(scene, *layer, s, 1, threads, &cancel);
        const bool complete = ps.completed;
        deliver(s, std::move(layer), ps);
        if (!complete) return;
    }
}

struct MpiSession {
    MpiSession() {
        int provided = 0;
        // Only the main thread of each rank calls MPI; the render runs in another thread.
        MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    }
    ~MpiSession() { MPI_Finalize(); }
};

}  // namespace

int run_headless_mpi(const HeadlessOptions& opt) {
    install_handlers();  // before the (possibly long) MPI start-up and scene load
    g_signal = 0;
    clear_interrupt();
    MpiSession session;
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);

    // Set-up errors are agreed on: the first rank that failed prints one line and every rank
    // returns 1 (no rank is left waiting for the others).
    auto agree = [&](const std::string& err) {
        int mine = err.empty() ? size : rank, first = size;
        MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
        if (first == size) return true;
        if (rank == first) {
            if (rank == 0) std::fprintf(stderr, "candela: %s\n", err.c_str());
            else std::fprintf(stderr, "candela: rank %d: %s\n", rank, err.c_str());
        }
        return false;
    };
    auto failed_exit = [&] { return g_signal ? 128 + g_signal.load() : 1; };

    std::shared_ptr<const Scene> scene_ptr;
    uint32_t target = 0, chunk = 1;
    uint64_t fingerprint = 0;
    std::string err;
    try {
        if (opt.out.empty()) throw Error("under MPI candela renders headless: give --out");
        const std::string ext = file_extension(opt.out);
        if (ext != ".png" && ext != ".exr" && ext != ".pfm")
            throw Error(opt.out, 0, "unknown output format '" + ext + "' (expected .png, .exr or .pfm)");
        if (rank == 0) {
            check_writable(opt.out);
            if (!opt.checkpoint.empty()) check_writable(opt.checkpoint);
        }
        // The layers carry the image half only, not adaptive sampling's decision half.
        if (opt.target_error > 0)
            throw Error("--target-error is not available under MPI (docs/adaptive.md): render without it, or in one process");
        scene_ptr = prepare_scene(opt.scene, opt.overrides);
        const RenderSettings& st = scene_ptr->settings;
        check_run_features(st, {true, false, !opt.checkpoint.empty() || !opt.resume.empty(), opt.time_limit > 0});
        // MLT's chains carry state from one sample index to the next, and its film is scaled by a b
        // refined as they run: sample indices cannot go to ranks independently (docs/distributed.md).
        if (st.integrator.type == IntegratorType::Pssmlt || st.integrator.type == IntegratorType::Mmlt)
            throw Error(std::string(integrator_type_name(st.integrator.type)) +
                        " does not run under MPI (its Markov chains run from one sample index to the next): render it "
                        "in one process, without mpirun");
        chunk = uint32_t(std::max(1, opt.spp_per_frame));
        const uint64_t frames = opt.frames > 0 ? uint64_t(opt.frames) : uint64_t(std::max(1, st.spp / int(chunk)));
        const uint64_t t = frames * uint64_t(chunk);
        if (t > std::numeric_limits<uint32_t>::max())
            throw Error("--frames x --spp-per-frame is " + std::to_string(t) + " samples per pixel, more than 2^32 - 1");
        target = uint32_t(t);
        if (!st.integrator.aovs.empty() && !opt.checkpoint.empty())
            throw Error(opt.checkpoint, 0, "checkpoints do not hold the aov integrator's layers; render it without --checkpoint");
        if (!st.integrator.aovs.empty() && !opt.resume.empty())
            throw Error(opt.resume, 0, "checkpoints do not hold the aov integrator's layers; render it without --resume");
        fingerprint = scene_fingerprint(*scene_ptr);
    } catch (const Interrupted&) {
        err = "interrupted while loading the scene: nothing written";
    } catch (const std::exception& e) {
        err = e.what();
    }
    if (!agree(err)) return failed_exit();
    // Every rank must render the same scene: a file that differs between nodes would mix images.
    uint64_t lo = 0, hi = 0;
    MPI_Allreduce(&fingerprint, &lo, 1, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(&fingerprint, &hi, 1, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD);
    if (lo != hi) {
        if (rank == 0)
            std::fprintf(stderr, "candela: the ranks loaded different scenes (a scene file or option differs between "
                                 "nodes): nothing rendered\n");
        return 1;
    }
    const Scene& scene = *scene_ptr;
    const RenderSettings& st = scene.settings;
    const int threads = opt.threads > 0 ? opt.threads : omp_get_max_threads();
    auto make_film = [&] {
        auto f = std::make_unique<Film>(st.width, st.height);
        configure_film(*f, st);
        if (st.alpha) f->enable_alpha();
        return f;
    };

    // Rank 0 holds the film; only it reads the checkpoint (the file need not be on every node).
    std::unique_ptr<Film> film;
    uint32_t start = 0;
    err.clear();
    if (rank == 0) {
        try {
            film = make_film();
            if (!opt.resume.empty()) {
                start = load_checkpoint(opt.resume, *film, fingerprint).spp;
                if (start > target)
                    throw Error(opt.resume, 0, "checkpoint has " + std::to_string(start) + " spp, more than the " +
                                                   std::to_string(target) + " this render asks for");
            }
        } catch (const std::exception& e) {
            err = e.what();
        }
    }
    if (!agree(err)) return failed_exit();
    MPI_Bcast(&start, 1, MPI_UINT32_T, 0, MPI_COMM_WORLD);
    if (rank == 0 && !opt.quiet) {
        for (const std::string& w : scene.warnings) std::fprintf(stderr, "candela: warning: %s\n", w.c_str());
        if (!opt.resume.empty()) std::fprintf(stderr, "candela: resuming %s at %u spp\n", opt.resume.c_str(), start);
    }
    const int slow_ms = test_hook("CANDELA_MPI_TEST_SLOW_RANK", rank);
    const int die_at = test_hook("CANDELA_MPI_TEST_DIE_RANK", rank);
    auto slow_down = [&] {
        if (slow_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(slow_ms));
    };

    // ---- a worker: ask, render, send, until rank 0 says there is nothing left -------------------
    if (rank != 0) {
        int chunks_taken = 0;
        try {
            for (;;) {
                const int sig = g_signal.load();
                int32_t req = sig ? (1 | (sig << 8)) : 0;
                MPI_Send(&req, 1, MPI_INT32_T, 0, kRequest, MPI_COMM_WORLD);
                uint32_t a[2] = {0, 0};
                for (;;) {  // the answer; a stop sent before it (while this rank rendered) is consumed here
                    MPI_Status status;
                    MPI_Probe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &status);
                    if (status.MPI_TAG == kStop) {
                        MPI_Recv(nullptr, 0, MPI_BYTE, 0, kStop, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                        continue;
                    }
                    MPI_Recv(a, 2, MPI_UINT32_T, 0, kAssign, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                    break;
                }
                if (a[1] == 0) break;
                if (die_at > 0 && ++chunks_taken == die_at) raise(SIGKILL);
                std::atomic<bool> cancel{g_signal.load() != 0}, done{false};
                std::vector<std::vector<char>> out;
                std::exception_ptr failure;
                std::thread worker([&] {
                    try {
                        slow_down();
                        render_chunk(scene, a[0], a[1], threads, cancel, make_film,
                                     [&](uint32_t s, std::unique_ptr<Film> layer, const PassStats& ps) {
                                         out.push_back(pack_layer(*layer, s, ps));
                                     });
                    } catch (...) {
                        failure = std::current_exception();
                    }
                    done = true;
                });
                while (!done) {  // this thread keeps MPI: a stop from rank 0 or a signal cuts the chunk
                    int flag = 0;
                    MPI_Iprobe(0, kStop, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE);
                    if (flag) {
                        MPI_Recv(nullptr, 0, MPI_BYTE, 0, kStop, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                        cancel = true;
                    }
                    if (g_signal) cancel = true;
                    std::this_thread::sleep_for(std::chrono::milliseconds(1));
                }
                worker.join();
                if (failure) std::rethrow_exception(failure);
                for (const std::vector<char>& b : out)
                    MPI_Send(b.data(), int(b.size()), MPI_BYTE, 0, kLayer, MPI_COMM_WORLD);
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "candela: rank %d: %s\n", rank, e.what());
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        return g_signal ? 128 + g_signal.load() : 0;
    }

    // ---- rank 0: serve chunks, add layers, render its own share in a thread ---------------------
    Reducer red;
    red.total = film.get();
    red.next = start;
    Dispenser disp;
    disp.next = start;
    disp.target = target;
    disp.chunk = chunk;
    disp.chunks_per_rank.assign(size_t(size), 0);
    std::atomic<bool> cancel{false}, local_done{false};
    std::exception_ptr local_failure;
    std::thread local([&] {
        try {
            for (;;) {
                uint32_t first = 0, count = 0;
                {
                    std::lock_guard<std::mutex> lock(red.m);
                    if (!disp.take(0, first, count)) break;
                }
                slow_down();
                render_chunk(scene, first, count, threads, cancel, make_film,
                             [&](uint32_t s, std::unique_ptr<Film> layer, const PassStats& ps) {
                                 red.deliver(s, ps.completed, Layer{std::move(layer), {}}, ps.samples, ps.rays);
                             });
                if (cancel) break;
            }
        } catch (...) {
            local_failure = std::current_exception();
        }
        local_done = true;
    });

    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    auto last_save = t0, last_progress = t0;
    const bool checkpointing = !opt.checkpoint.empty();
    const bool tty = isatty(fileno(stderr)) && !opt.quiet;
    const uint64_t pixels = uint64_t(st.width) * uint64_t(st.height);
    auto save = [&](const char* when) {  // the caller holds red.m
        try {
            save_checkpoint(opt.checkpoint, *film, red.next, fingerprint);
            last_save = clock::now();
        } catch (const Error& e) {
            std::fprintf(stderr, "candela: warning: %s checkpoint not saved: %s\n", when, e.what());
        }
    };
    uint32_t saved_at = start;
    std::vector<char> busy(size_t(size), 0);
    int workers_left = size - 1;
    bool stopping = false, time_up = false;
    int stop_signal = 0;  // the signal that stopped the render (this rank's or a worker's)
    uint64_t bytes_received = 0, messages = 0;
    double recv_seconds = 0;
    auto stop_all = [&] {
        if (stopping) return;
        stopping = true;
        cancel = true;
        {
            std::lock_guard<std::mutex> lock(red.m);
            disp.stopped = true;
        }
        for (int r = 1; r < size; ++r)
            if (busy[size_t(r)]) MPI_Send(nullptr, 0, MPI_BYTE, r, kStop, MPI_COMM_WORLD);
    };
    try {
        while (workers_left > 0 || !local_done) {
            int flag = 0;
            MPI_Status status;
            MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status);
            if (flag) {
                const int src = status.MPI_SOURCE;
                if (status.MPI_TAG == kLayer) {
                    int bytes = 0;
                    MPI_Get_count(&status, MPI_BYTE, &bytes);
                    const auto u0 = clock::now();
                    std::vector<char> b(size_t(std::max(0, bytes)));
                    MPI_Recv(b.data(), bytes, MPI_BYTE, src, kLayer, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                    const LayerHeader h = view_layer(b, *film).h;  // checks the size
                    recv_seconds += std::chrono::duration<double>(clock::now() - u0).count();
                    bytes_received += uint64_t(bytes);
                    ++messages;
                    red.deliver(h.index, h.complete != 0, Layer{nullptr, std::move(b)}, h.samples, h.rays);
                } else if (status.MPI_TAG == kRequest) {
                    int32_t req = 0;
                    MPI_Recv(&req, 1, MPI_INT32_T, src, kRequest, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                    if (req & 1) {  // a worker was signalled: the whole render stops, as if rank 0 had been
                        if (!stop_signal) stop_signal = req >> 8;
                        stop_all();
                    }
                    uint32_t a[2] = {0, 0};
                    {
                        std::lock_guard<std::mutex> lock(red.m);
                        if (!disp.take(src, a[0], a[1])) a[1] = 0;
                    }
                    MPI_Send(a, 2, MPI_UINT32_T, src, kAssign, MPI_COMM_WORLD);
                    busy[size_t(src)] = a[1] > 0;
                    if (a[1] == 0) --workers_left;
                } else {
                    throw Error("internal error: an MPI message with tag " + std::to_string(status.MPI_TAG));
                }
                continue;  // drain the messages before anything else
            }
            const auto now = clock::now();
            const double elapsed = std::chrono::duration<double>(now - t0).count();
            if (g_signal && !stopping) {
                stop_signal = g_signal;
                stop_all();
            }
            if (opt.time_limit > 0 && elapsed >= opt.time_limit && !stopping) {
                time_up = true;
                stop_all();
            }
            if (checkpointing && !stopping && std::chrono::duration<double>(now - last_save).count() >= opt.checkpoint_every) {
                std::lock_guard<std::mutex> lock(red.m);
                if (red.next > saved_at && red.next < target) {
                    save("periodic");
                    saved_at = red.next;
                }
            }
            if (tty && std::chrono::duration<double>(now - last_progress).count() >= 0.25) {
                last_progress = now;
                uint64_t done_spp, samples;
                {
                    std::lock_guard<std::mutex> lock(red.m);
                    done_spp = uint64_t(start) + red.layers;
                    samples = red.samples;
                }
                std::string line = progress_line(done_spp, target, pixels, elapsed, elapsed > 0 ? double(samples) / elapsed : 0.0,
                                                 opt.time_limit);
                std::fprintf(stderr, "\r%s ", line.c_str());
                std::fflush(stderr);
            }
            std::this_thread::sleep_for(std::chrono::microseconds(500));
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "candela: rank 0: %s\n", e.what());
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    local.join();
    if (local_failure) {
        try {
            std::rethrow_exception(local_failure);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "candela: rank 0: %s\n", e.what());
        }
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    const double secs = std::chrono::duration<double>(clock::now() - t0).count();
    if (tty) std::fprintf(stderr, "\n");
    if (!stop_signal && g_signal) stop_signal = g_signal;

    // The checkpoint holds the whole sample indices [0, red.next); the image has everything.
    const uint32_t prefix = red.next;
    if (checkpointing && prefix > 0) {
        std::lock_guard<std::mutex> lock(red.m);
        save("final");
    }
    red.finish();
    const uint64_t total = film->total_samples();
    if (stop_signal && total == 0) {
        std::fprintf(stderr, "candela: %s before the first sample finished: nothing written (%s left as it was)\n",
                     stop_signal == SIGTERM ? "terminated" : "interrupted", opt.out.c_str());
        return 128 + stop_signal;
    }
    if (time_up && total == 0) {
        std::fprintf(stderr, "candela: the time limit ended the render before any tile finished: nothing written (%s "
                             "left as it was)\n", opt.out.c_str());
        return 1;
    }
    WrittenImage wi;
    try {
        wi = write_headless_image(opt, scene, *film);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "candela: %s\n", e.what());
        return 1;
    }
    if (!opt.quiet) {
        const double spp = double(total) / double(pixels);
        print_memory_summary(scene);
        std::string per_rank;
        for (uint64_t c : disp.chunks_per_rank) per_rank += (per_rank.empty() ? "" : " ") + std::to_string(c);
        std::fprintf(stderr,
                     "candela: mpi: %d ranks x %d threads; chunks of %u spp per rank: %s; rank 0 received %.1f MB in "
                     "%llu layers, %.3f s receiving and %.3f s adding\n",
                     size, threads, chunk, per_rank.c_str(), double(bytes_received) / 1e6, (unsigned long long)messages,
                     recv_seconds, red.add_seconds);
        std::fprintf(stderr,
                     "candela: %s%s %dx%d, %s, %.6g spp in %.2f s, %.3f Msamples/s, %.3f Mrays/s, %d ranks x %d threads, "
                     "accel %s, %llu non-finite samples -> %s\n",
                     stop_signal ? (stop_signal == SIGTERM ? "terminated: " : "interrupted: ") : time_up ? "time limit: " : "",
                     scene.source.c_str(), st.width, st.height, integrator_summary(st).c_str(), spp, secs, secs > 0 ? double(red.samples) / secs * 1e-6 : 0.0,
                     secs > 0 ? double(red.rays) / secs * 1e-6 : 0.0, size, threads, scene.accel->name().c_str(),
                     (unsigned long long)film->nonfinite_count(), wi.path.c_str());
        if (checkpointing && prefix > 0)
            std::fprintf(stderr, "candela: checkpoint %s at %u spp\n", opt.checkpoint.c_str(), prefix);
    }
    if (wi.png_failed) return 1;
    return stop_signal ? 128 + stop_signal : 0;
}

}  // namespace candela
