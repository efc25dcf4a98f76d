#pragma once
// The interactive viewer: a GLFW window that shows the film converging (through the shared display
// program, the one tonemap), a Dear ImGui panel to edit the scene, and camera controls. Rendering
// happens in a RenderSession; the window's thread never waits for a pass.
#include <optional>
#include <string>
#include "core/error.h"
#include "display/display.h"
#include "render/launch.h"
#include "render/session.h"

namespace candela {

class ViewerFrontEnd;

// A per-frame observer that may also drive the viewer, for tools that measure it (bench/viewer
// moves the camera by itself and times how the window keeps up). The program passes none.
class ViewerHooks {
public:
    struct Frame {
        double start = 0, end = 0;  // seconds (steady clock): from the end of the event wait to the swap
        double cpu_ms = 0;          // CPU time of the window's thread over the same span
        bool new_image = false;     // a new image was uploaded and tonemapped in this frame
    };
    virtual ~ViewerHooks() = default;
    virtual void started(ViewerFrontEnd&) {}                     // once, the session running
    virtual void before_panel(ViewerFrontEnd&, double /*now*/) {}  // each frame after input: may edit
    virtual bool after_frame(ViewerFrontEnd&, const Frame&) { return true; }  // false: close
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
    ViewerHooks* hooks = nullptr;  // measuring tools only; frames are then paced without vsync
    // The denoised view (docs/denoising.md): on at start, and its quality. With it the scene renders
    // the denoiser's albedo and normal (with the box filter); without it the panel's toggle
    // denoises the beauty alone, so that a scene that is never denoised pays nothing.
    bool denoise = false;
    DenoiseQuality denoise_quality = DenoiseQuality::Balanced;
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
