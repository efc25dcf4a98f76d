#pragma once
// The interactive viewer: a GLFW window that shows the film converging (through the shared display
// program, the one tonemap), a Dear ImGui panel to edit the scene, and camera controls. Rendering
// happens in a RenderSession; the window's thread never waits for a pass.
#include <optional>
#include <string>
#include <vector>
#include "core/error.h"
#include "display/display.h"
#include "render/launch.h"
#include "render/session.h"

namespace candela {

// Responsiveness measurement (bench/viewer): the viewer moves the camera by itself on a schedule
// and records how the window keeps up. Not used by the program's command line.
struct ViewerBenchmark {
    double duration = 10;       // seconds of measurement, after the first full-resolution pass
    double move_every = 0.25;   // seconds between scripted camera changes (a small orbit step)
    int moves_per_burst = 1;    // consecutive frames that each change the camera (a "drag")
    bool paused = false;        // full passes paused: the window's own cost, previews only
    // Results.
    std::vector<double> frame_ms;   // per frame, from the end of the event wait to the swap: events, panel, upload, draw, swap
    std::vector<double> frame_cpu_ms;  // the same, in CPU time of the window's thread: what the
                                       // frame costs on an idle core (with LP_NUM_THREADS=0 the
                                       // software rasteriser runs in this thread too)
    std::vector<double> update_ms;  // camera change -> end of the first frame showing its image
    std::vector<bool> frame_new_image;  // per frame: a new image was uploaded and tonemapped in it
    int frames = 0;
};

struct ViewerOptions {
    std::string scene;           // empty: the built-in Cornell box
    SceneOverrides overrides;
    int threads = 0;             // render threads; 0: all cores
    DisplaySettings display;     // initial exposure
    int spp_per_frame = 1;       // samples per pixel in each full-resolution pass
    int screenshot_after = 0;    // > 0: render this many passes, save the window, exit
    std::string screenshot;      // PNG file for screenshot_after
    // Render threads' priority; unset: Idle for an interactive window (the window first), Normal
    // for --screenshot-after runs, where nobody is waiting on the window's frames.
    std::optional<RenderPriority> render_priority;
    ViewerBenchmark* benchmark = nullptr;
};

// Thrown by run_viewer when GLFW cannot initialise (no display server, a refused connection) or
// cannot open a GL 3.3 window, before anything was rendered: the caller may render headless.
class DisplayUnavailable : public Error {
public:
    using Error::Error;
};

// Opens the window and runs until it is closed (or the screenshot is written). Returns the process
// exit code. Throws Error when the scene cannot be loaded, DisplayUnavailable when no window can
// be opened.
int run_viewer(const ViewerOptions& opt);

}  // namespace candela
