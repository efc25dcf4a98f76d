#pragma once
#include <string>
#include "denoise/denoiser.h"
#include "display/display.h"
#include "film/film.h"
#include "render/launch.h"
#include "scene/scene.h"

namespace candela {

struct HeadlessOptions {
    std::string scene;        // empty: the built-in Cornell box
    std::string out;          // .png, .exr or .pfm
    SceneOverrides overrides;
    int frames = 0;           // 0: the scene's sample_count / spp_per_frame
    int spp_per_frame = 1;
    int threads = 0;          // 0: all cores
    double time_limit = 0;    // seconds; 0: none
    DisplaySettings display;
    bool quiet = false;
    // Checkpoints (see app/checkpoint.h): saved to `checkpoint` every `checkpoint_every` seconds
    // (0: after every pass), at the end and when stopped by a signal; `resume` continues from one.
    std::string checkpoint;
    double checkpoint_every = 60;
    std::string resume;
    // Adaptive sampling (docs/adaptive.md): > 0 stops each pixel once its estimated relative error
    // is below target_error (after adaptive_min_spp samples), and the render when all have stopped.
    double target_error = 0;
    int adaptive_min_spp = 16;
    // --bdpt-strategies DIR: after the render, one EXR per BDPT strategy (s, t), weighted and
    // unweighted, over the same samples per pixel (integrator/bdpt/bdpt.h render_bdpt_strategies).
    std::string bdpt_strategies;
    // --denoise (docs/denoising.md): the image at `out` is denoised by Open Image Denoise; the raw
    // beauty ("noisy.R" ...) and the auxiliaries ("albedo.R" ..., "normal.X" ...) are layers of the
    // EXR: `out` itself when it is .exr, else denoise_layers_path(out) beside it. When denoising
    // fails the raw image is written instead, and the exit status is 1.
    bool denoise = false;
    DenoiseQuality denoise_quality = DenoiseQuality::High;
};

// The EXR beside a --denoise output that is not .exr: "out.png" -> "out.layers.exr".
std::string denoise_layers_path(const std::string& out);

// Renders the passes, shows progress (a bar on a terminal, a summary line otherwise), and writes
// the image. SIGINT/SIGTERM stop the render early: the image so far is still written and the
// summary says how many spp it has. With a checkpoint file the first signal lets the current pass
// finish (a checkpoint holds whole passes) and a second one stops at once. Returns the process
// exit code: 0, or 128 + the signal's number when stopped by one.
int run_headless(const HeadlessOptions& opt);

// Pieces of run_headless that the MPI run (app/mpi_run.h) shares.
// Refuses an output whose directory is missing or not writable (Error naming the file).
void check_writable(const std::string& path);
// Writes the film to opt.out: PNG through the display shaders (a linear EXR beside it if GL
// fails), EXR (with the AOV layers), or PFM. Returns the file written and whether the PNG failed.
struct WrittenImage {
    std::string path;
    bool png_failed = false;
    bool denoise_failed = false;  // --denoise asked for and not done: the raw image was written
    double denoise_seconds = 0;
};
WrittenImage write_headless_image(const HeadlessOptions& opt, const Scene& scene, const Film& film);
// The line saying what --denoise did (nothing when it was not asked for or failed).
void print_denoise_summary(const HeadlessOptions& opt, const Scene& scene, const WrittenImage& wi);
// The summary line of the scene's memory (triangles, MB, bytes per triangle).
void print_memory_summary(const Scene& scene);

}  // namespace candela
