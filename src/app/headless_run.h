#pragma once
#include <string>
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
};

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
};
WrittenImage write_headless_image(const HeadlessOptions& opt, const Scene& scene, const Film& film);
// The summary line of the scene's memory (triangles, MB, bytes per triangle).
void print_memory_summary(const Scene& scene);

}  // namespace candela
