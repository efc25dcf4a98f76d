#pragma once
#include <string>
#include "display/display.h"
#include "render/launch.h"

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
};

// Renders the passes, shows progress (a bar on a terminal, a summary line otherwise), and writes
// the image. SIGINT/SIGTERM stop the render early; the image so far is still written. Returns the
// process exit code.
int run_headless(const HeadlessOptions& opt);

}  // namespace candela
