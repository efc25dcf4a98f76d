#include "viewer/viewer.h"

#define GLFW_INCLUDE_NONE  // GL comes from display/gl_api.h, through glfwGetProcAddress
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include "core/error.h"
#include "viewer/window.h"

namespace candela {

namespace {

// While something animates (fly keys held, a drag, a measuring tool), frames are paced at this rate.
constexpr double kFrameInterval = 1.0 / 60.0;

double thread_cpu_seconds() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void glfw_error(int code, const char* what) { std::fprintf(stderr, "candela: GLFW error 0x%x: %s\n", code, what); }

}  // namespace

double viewer_now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

Viewer::Viewer(const ViewerOptions& opt) : opt_(opt), display_(opt.display) {
    // The display first: without one the caller renders headless, and must not load the scene twice.
    glfwSetErrorCallback(glfw_error);
    if (!glfwInit()) throw DisplayUnavailable("viewer: cannot initialise GLFW (no display?)");
    try {
        init();
    } catch (...) {
        // The destructor does not run for a constructor that throws.
        if (window_) glfwDestroyWindow(window_);
        glfwTerminate();
        throw;
    }
}

void Viewer::init() {
    ViewerOptions& opt = opt_;
    // The denoiser's albedo and normal cost a ray or more per sample, and its box filter changes
    // the image: only when asked for (--denoise). Without them the toggle denoises the beauty alone.
    denoise_unavailable_ = denoiser_unavailable_reason();
    opt.overrides.denoise_aux = opt.overrides.denoise_box_filter = opt.denoise && denoise_unavailable_.empty();
    std::shared_ptr<const Scene> scene = prepare_scene(opt.scene, opt.overrides);
    for (const std::string& w : scene->warnings) std::fprintf(stderr, "candela: warning: %s\n", w.c_str());
    open_window(scene->settings.width, scene->settings.height);

    SessionOptions so;
    so.threads = opt.threads;
    so.spp_per_pass = std::max(1, opt.spp_per_frame);
    so.max_passes = opt.screenshot_after;
    so.priority = opt.render_priority.value_or(opt.screenshot_after > 0 ? RenderPriority::Normal : RenderPriority::Idle);
    so.preview_budget = 0.025;  // previews that keep up with the mouse on a slow machine
    SceneOverrides drop = opt.overrides;
    drop.defines.clear();  // -D and the image size were meant for the command line's scene
    drop.width.reset();
    drop.height.reset();
    fe_ = std::make_unique<ViewerFrontEnd>(std::move(scene), so, drop);
    // Wakes the event loop when an image is ready: the window sleeps in glfwWaitEvents otherwise.
    fe_->session().set_on_publish([] { glfwPostEmptyEvent(); });
    fe_->set_on_scene_switched([this] { glfwSetWindowTitle(window_, ("candela - " + fe_->scene().source).c_str()); });
    threads_ = fe_->session().threads();
    if (opt.denoise && denoise_unavailable_.empty()) fe_->set_denoise_view(true, opt.denoise_quality);
    if (opt.denoise && !denoise_unavailable_.empty()) fe_->set_status(denoise_unavailable_, true);
    if (opt_.hooks) opt_.hooks->started(*fe_);
}

Viewer::~Viewer() {
    fe_.reset();  // the render session first: its publish callback wakes this window
    if (window_) {
        glfwMakeContextCurrent(window_);
        release_gl();
        if (imgui_ready_) {
            ImGui_ImplOpenGL3_Shutdown();
            ImGui_ImplGlfw_Shutdown();
            ImGui::DestroyContext();
        }
        glfwDestroyWindow(window_);
    }
    glfwTerminate();
}

void Viewer::open_window(int image_w, int image_h) {
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    // The image at its own size beside the panel, within the screen.
    int w = image_w + int(kPanelWidth), h = std::max(image_h, 640);
    if (GLFWmonitor* mon = glfwGetPrimaryMonitor()) {
        int x, y, mw, mh;
        glfwGetMonitorWorkarea(mon, &x, &y, &mw, &mh);
        if (mw > 0 && mh > 0) {
            w = std::min(w, mw);
            h = std::min(h, mh);
        }
    }
    window_ = glfwCreateWindow(w, h, "candela", nullptr, nullptr);
    if (!window_) throw DisplayUnavailable("viewer: cannot open a GL 3.3 core window");
    glfwMakeContextCurrent(window_);
    // Vsync paces the loop on a real display; the frame loop also paces itself (Xvfb has no vsync).
    glfwSwapInterval(opt_.hooks || opt_.screenshot_after > 0 ? 0 : 1);
    gl_ = load_gl_api(reinterpret_cast<GlGetProcAddress>(glfwGetProcAddress));
    program_ = std::make_unique<DisplayProgram>(gl_);
    {
        // A software GL compiles each pipeline variant on first use (llvmpipe specialises its
        // samplers on power-of-two texture sizes; docs/viewer.md has the cost): run the preview's
        // scaling blit now from a power-of-two and from another source, so that no camera change
        // pays for it.
        unsigned fbo = 0, tex = 0;
        int cw = 0, ch = 0;
        ensure_color_target(gl_, fbo, tex, cw, ch, 8, 8);
        for (int n : {2, 3}) {
            ensure_color_target(gl_, small_fbo_, small_tex_, small_w_, small_h_, n, n);
            gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, small_fbo_);
            gl_.BindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
            gl_.BlitFramebuffer(0, 0, n, n, 0, 0, 8, 8, GL_COLOR_BUFFER_BIT, GL_LINEAR);
        }
        gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
        std::vector<unsigned char> px(8 * 8 * 4);
        gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        gl_.ReadPixels(0, 0, 8, 8, GL_RGBA, GL_UNSIGNED_BYTE, px.data());  // waits for it to run
        gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
        gl_.DeleteFramebuffers(1, &fbo);
        gl_.DeleteTextures(1, &tex);
    }

    glfwSetWindowUserPointer(window_, this);
    glfwSetDropCallback(window_, [](GLFWwindow* win, int count, const char** paths) {
        auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(win));
        for (int i = 0; i < count; ++i) self->dropped_.emplace_back(paths[i]);
    });

    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // no imgui.ini in the user's directory
    ImGui::StyleColorsDark();
    // An opaque panel: what is behind it never shows through (and the tests can find it).
    ImGui::GetStyle().Colors[ImGuiCol_WindowBg].w = 1.f;
    ImGui_ImplGlfw_InitForOpenGL(window_, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
    imgui_ready_ = true;
}

void Viewer::layout() {
    int win_w, win_h;
    glfwGetFramebufferSize(window_, &fb_w_, &fb_h_);
    glfwGetWindowSize(window_, &win_w, &win_h);
    fb_scale_ = win_w > 0 ? float(fb_w_) / float(win_w) : 1.f;
    int panel = std::min(fb_w_, int(kPanelWidth * fb_scale_));
    area_ = {0, 0, fb_w_ - panel, fb_h_};
    const RenderSettings& st = fe_->params().settings;
    const int iw = st.width, ih = st.height;
    if (iw <= area_.width && ih <= area_.height) {
        // Pixel for pixel when it fits: no resampling of the converged image.
        image_rect_ = {(area_.width - iw) / 2, (area_.height - ih) / 2, iw, ih};
    } else {
        image_rect_ = fit_image_rect(iw, ih, area_);
    }
}

bool Viewer::animating() const {
    return drag_button_ >= 0 || ImGui::IsKeyDown(GLFW_KEY_W) || ImGui::IsKeyDown(GLFW_KEY_A) ||
           ImGui::IsKeyDown(GLFW_KEY_S) || ImGui::IsKeyDown(GLFW_KEY_D) || ImGui::IsKeyDown(GLFW_KEY_Q) ||
           ImGui::IsKeyDown(GLFW_KEY_E) || fe_->dirty() || opt_.hooks != nullptr;
}

int Viewer::run() {
    double frame_start = viewer_now();
    for (;;) {
        // Sleep until something happens: input, a new image (the worker posts an empty event), the
        // end of the interactive hold, or the next paced frame while something animates.
        double timeout = 0.25;  // statistics refresh even when nothing else happens
        if (fe_->interactive()) timeout = std::min(timeout, std::max(0.0, fe_->interactive_until() - viewer_now()));
        if (animating()) timeout = std::min(timeout, std::max(0.0, frame_start + kFrameInterval - viewer_now()));
        if (frame_ < 3 || opt_.screenshot_after > 0) timeout = std::min(timeout, 0.05);
        if (timeout > 0) glfwWaitEventsTimeout(timeout);
        else glfwPollEvents();
        if (glfwWindowShouldClose(window_)) break;
        frame_start = viewer_now();
        const double frame_cpu_start = opt_.hooks ? thread_cpu_seconds() : 0.0;

        if (!dropped_.empty()) {
            fe_->drop(dropped_);
            dropped_.clear();
        }
        const bool new_image = fe_->begin_frame(frame_start);
        if (new_image) {
            const SessionImage& img = fe_->image();
            program_->upload(img.width, img.height, img.rgb.data());
            cache_valid_ = false;
        }

        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        layout();
        camera_input();
        if (opt_.hooks) opt_.hooks->before_panel(*fe_, viewer_now());
        panel();
        fe_->end_frame(viewer_now());
        ImGui::Render();

        update_display_cache();
        gl_.Viewport(0, 0, fb_w_, fb_h_);
        gl_.ClearColor(0.02f, 0.02f, 0.02f, 1.f);
        gl_.Clear(GL_COLOR_BUFFER_BIT);
        if (!fe_->image().rgb.empty() && cache_valid_) {
            // The tonemapped image is copied, not drawn: a blit of the cache costs a software GL
            // (llvmpipe) a fraction of a textured, blended quad. Both are bottom-up, so no flip;
            // the panel is drawn over it.
            gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, cache_fbo_);
            gl_.BlitFramebuffer(0, 0, image_rect_.width, image_rect_.height, image_rect_.x, image_rect_.y,
                                image_rect_.x + image_rect_.width, image_rect_.y + image_rect_.height,
                                GL_COLOR_BUFFER_BIT, GL_NEAREST);
            gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
        }
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        ++frame_;

        // Screenshot: once the requested passes are on screen, unedited, and the panel has settled.
        const SessionImage& img = fe_->image();
        bool shot = opt_.screenshot_after > 0 && !img.preview && img.generation == 0 &&
                    img.passes >= opt_.screenshot_after && frame_ > 3;
        if (shot) write_screenshot();
        glfwSwapBuffers(window_);
        if (shot) return 0;
        if (opt_.hooks) {
            ViewerHooks::Frame f;
            f.start = frame_start;
            f.end = viewer_now();
            f.cpu_ms = (thread_cpu_seconds() - frame_cpu_start) * 1e3;
            f.new_image = new_image;
            if (!opt_.hooks->after_frame(*fe_, f)) break;
        }
    }
    return 0;
}

int run_viewer(const ViewerOptions& opt) {
    if (opt.screenshot_after > 0 && opt.screenshot.empty()) throw Error("--screenshot-after needs a PNG file name");
    Viewer viewer(opt);
    return viewer.run();
}

}  // namespace candela
