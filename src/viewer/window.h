#pragma once
// The viewer's window (internal to src/viewer): one class, its concerns in separate files.
//   viewer.cpp          window and GL setup, the frame loop, layout
//   window_display.cpp  the tonemapped image: display cache, PNG saving through the display program
//   window_input.cpp    mouse and keyboard: camera motion, picking
//   window_panel.cpp    the Dear ImGui panel
//   window_screenshot.cpp  --screenshot-after
// What the window edits and the render session it talks to live in ViewerFrontEnd (no GL).
#include <memory>
#include <string>
#include <vector>
#include "display/display.h"
#include "display/display_program.h"
#include "display/gl_api.h"
#include "viewer/front_end.h"
#include "viewer/viewer.h"

struct GLFWwindow;

namespace candela {

constexpr float kPanelWidth = 370.f;  // window coordinates

double viewer_now();  // seconds, steady clock

class Viewer {
public:
    explicit Viewer(const ViewerOptions& opt);
    ~Viewer();
    int run();

private:
    void init();  // everything after glfwInit: the scene, the window, the render session
    void open_window(int image_w, int image_h);
    void layout();
    void camera_input();        // window_input.cpp
    void panel();               // window_panel.cpp
    void panel_pick();
    void update_display_cache();  // window_display.cpp
    void save_png(const std::string& path);
    void release_gl();
    bool write_screenshot();    // window_screenshot.cpp
    bool animating() const;

    ViewerOptions opt_;
    GLFWwindow* window_ = nullptr;
    bool imgui_ready_ = false;
    GlApi gl_;
    std::unique_ptr<DisplayProgram> program_, saver_;
    std::unique_ptr<ViewerFrontEnd> fe_;
    DisplaySettings display_;
    int threads_ = 1;
    std::string denoise_unavailable_;  // why there is no denoised view (empty: there is one)

    // Mouse drags that started over the render area.
    int drag_button_ = -1;
    float drag_distance_ = 0;
    float drag_start_x_ = 0, drag_start_y_ = 0;

    // Layout, in framebuffer pixels with GL's bottom-left origin, and the window/framebuffer scale.
    int fb_w_ = 0, fb_h_ = 0;
    float fb_scale_ = 1;
    DisplayRect area_, image_rect_;

    char png_path_[512] = "candela.png";
    char exr_path_[512] = "candela.exr";
    std::vector<std::string> dropped_;  // filled by GLFW's drop callback

    // The display shader's output for the current image, exposure and layout, kept in a texture:
    // the shader runs when one of those changes, not every frame (it is most of a frame's cost
    // in a software GL), and each frame blits the texture to the window pixel for pixel.
    unsigned cache_fbo_ = 0, cache_tex_ = 0;
    int cache_w_ = 0, cache_h_ = 0;
    // A preview goes through the shader at its own size into this target, then is scaled up into
    // the cache by a bilinear blit (see update_display_cache).
    unsigned small_fbo_ = 0, small_tex_ = 0;
    int small_w_ = 0, small_h_ = 0;
    bool cache_valid_ = false;
    float cache_exposure_ = 0;

    int frame_ = 0;
};

// (Re)allocates an RGBA8 texture of w x h and a framebuffer that renders into it.
void ensure_color_target(const GlApi& gl, unsigned& fbo, unsigned& tex, int& cur_w, int& cur_h, int w, int h);

}  // namespace candela
