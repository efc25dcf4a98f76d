#include "viewer/viewer.h"

#define GLFW_INCLUDE_NONE  // GL comes from display/gl_api.h, through glfwGetProcAddress
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <future>
#include <thread>
#include "core/error.h"
#include "display/display_program.h"
#include "display/gl_api.h"
#include "film/image_io.h"
#include "headless/headless.h"
#include "render/session.h"
#include "viewer/camera_control.h"
#include "viewer/panel.h"
#include "viewer/pick.h"

namespace candela {

namespace {

constexpr float kPanelWidth = 370.f;  // window coordinates
// After the last edit, the session keeps rendering quarter-resolution previews this long, so that
// a drag that pauses for a moment does not start a full pass that the next motion cancels.
constexpr double kInteractiveHold = 0.2;
// Edits are sent to the session when the previous one has shown its image, or after this long:
// mouse events can arrive faster than previews render, and cancelling every preview would freeze
// the view during a fast drag.
constexpr double kMaxUpdateDelay = 0.1;
// While something animates (fly keys held), frames are paced at this rate.
constexpr double kFrameInterval = 1.0 / 60.0;

// (Re)allocates an RGBA8 texture of w x h and a framebuffer that renders into it.
void ensure_color_target(const GlApi& gl, unsigned& fbo, unsigned& tex, int& cur_w, int& cur_h, int w, int h) {
    if (w == cur_w && h == cur_h && fbo && tex) return;
    if (!tex) gl.GenTextures(1, &tex);
    if (!fbo) gl.GenFramebuffers(1, &fbo);
    gl.BindTexture(GL_TEXTURE_2D, tex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE) throw Error("viewer: the display cache framebuffer is incomplete");
    cur_w = w;
    cur_h = h;
}


double thread_cpu_seconds() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

void glfw_error(int code, const char* what) { std::fprintf(stderr, "candela: GLFW error 0x%x: %s\n", code, what); }

// Resamples the convergence history onto `n` points uniform in time (the value in force at each
// time), so that the plot's x axis is time, not pass index. log10, for a curve that falls ~1/sqrt(t).
std::vector<float> resample_log(const std::vector<float>& v, const std::vector<float>& t, int n) {
    std::vector<float> out;
    if (v.empty()) return out;
    float t0 = t.front(), t1 = std::max(t.back(), t0 + 1e-6f);
    size_t j = 0;
    for (int i = 0; i < n; ++i) {
        float ti = t0 + (t1 - t0) * float(i) / float(n - 1);
        while (j + 1 < t.size() && t[j + 1] <= ti) ++j;
        out.push_back(std::log10(std::max(v[j], 1e-6f)));
    }
    return out;
}

class Viewer {
public:
    explicit Viewer(const ViewerOptions& opt);
    ~Viewer();
    int run();

private:
    void open_window(int image_w, int image_h);
    void switch_scene(std::shared_ptr<const Scene> scene);
    void layout();
    void camera_input();
    void camera_changed();
    void params_changed();
    void flush_updates();
    void panel();
    void panel_pick();
    void poll_background_work();
    void save_png(const std::string& path);
    void save_exr(const std::string& path);
    void set_status(const std::string& s, bool error) { status_ = s, status_error_ = error; }
    bool write_screenshot();
    void benchmark_step(double frame_start, double frame_cpu_start);
    bool frame_new_image_ = false;  // this frame uploaded a new image (for the benchmark)

    ViewerOptions opt_;
    GLFWwindow* window_ = nullptr;
    bool imgui_ready_ = false;
    GlApi gl_;
    std::unique_ptr<DisplayProgram> program_, saver_;
    std::unique_ptr<RenderSession> session_;

    std::shared_ptr<const Scene> scene_;  // immutable snapshot: picking, names, bounds
    SceneParams params_;                   // the window's copy of what the worker renders
    CameraController camera_;
    SessionImage image_;                   // on screen
    SessionStats stats_;
    DisplaySettings display_;
    int threads_ = 1;

    // Edits: `dirty_` until sent; `sent_gen_` is the generation of the last one sent.
    bool dirty_ = false;
    uint64_t sent_gen_ = 0;
    double last_sent_ = 0, last_edit_ = -1e9;
    bool interactive_ = false;

    // Mouse drags that started over the render area.
    int drag_button_ = -1;
    float drag_distance_ = 0;
    ImVec2 drag_start_;

    // Layout, in framebuffer pixels with GL's bottom-left origin, and the window/framebuffer scale.
    int fb_w_ = 0, fb_h_ = 0;
    float fb_scale_ = 1;
    DisplayRect area_, image_rect_;

    // Panel state.
    int selected_material_ = -1;
    bool reveal_selected_ = false;
    bool has_pick_ = false;
    ivec2 pick_pixel_{0};
    PickResult pick_;
    std::string status_;
    bool status_error_ = false;
    char png_path_[512] = "candela.png";
    char exr_path_[512] = "candela.exr";

    // Background work: a scene being loaded (dropped file), files being written.
    std::vector<std::string> dropped_;
    std::future<std::shared_ptr<const Scene>> loading_;
    std::string loading_path_;
    std::vector<std::future<std::string>> saving_;

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
    void update_display_cache();

    int frame_ = 0;
    // Benchmark state.
    double bench_start_ = 0, bench_next_move_ = 0, bench_change_time_ = -1;
    uint64_t bench_change_gen_ = 0;
    bool bench_waiting_gen_ = false;
    int bench_burst_left_ = 0;
};

Viewer::Viewer(const ViewerOptions& opt) : opt_(opt), display_(opt.display) {
    std::shared_ptr<const Scene> scene = prepare_scene(opt.scene, opt.overrides);
    params_ = scene->params();
    camera_.reset(scene->camera, scene->geometry->bounds);
    scene_ = scene;

    glfwSetErrorCallback(glfw_error);
    if (!glfwInit()) throw Error("viewer: cannot initialise GLFW (no display?)");
    open_window(params_.settings.width, params_.settings.height);

    SessionOptions so;
    so.threads = opt.threads;
    so.spp_per_pass = std::max(1, opt.spp_per_frame);
    so.max_passes = opt.screenshot_after;
    so.priority = opt.render_priority.value_or(opt.screenshot_after > 0 ? RenderPriority::Normal : RenderPriority::Idle);
    so.preview_budget = 0.025;    // previews that keep up with the mouse on a slow machine
    session_ = std::make_unique<RenderSession>(scene, so);
    // Wakes the event loop when an image is ready: the window sleeps in glfwWaitEvents otherwise.
    session_->set_on_publish([] { glfwPostEmptyEvent(); });
    threads_ = session_->threads();
    if (opt.benchmark && opt.benchmark->paused) session_->set_paused(true);
}

Viewer::~Viewer() {
    session_.reset();  // joins the worker (at most one tile per thread)
    for (auto& f : saving_) f.wait();
    if (loading_.valid()) loading_.wait();
    if (window_) {
        glfwMakeContextCurrent(window_);
        saver_.reset();
        program_.reset();  // GL objects die with the context still current
        if (cache_fbo_) gl_.DeleteFramebuffers(1, &cache_fbo_);
        if (cache_tex_) gl_.DeleteTextures(1, &cache_tex_);
        if (small_fbo_) gl_.DeleteFramebuffers(1, &small_fbo_);
        if (small_tex_) gl_.DeleteTextures(1, &small_tex_);
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
    if (!window_) throw Error("viewer: cannot open a GL 3.3 core window");
    glfwMakeContextCurrent(window_);
    // Vsync paces the loop on a real display; the frame loop also paces itself (Xvfb has no vsync).
    glfwSwapInterval(opt_.benchmark || opt_.screenshot_after > 0 ? 0 : 1);
    gl_ = load_gl_api(reinterpret_cast<GlGetProcAddress>(glfwGetProcAddress));
    program_ = std::make_unique<DisplayProgram>(gl_);
    {
        // A software GL compiles each pipeline variant on first use (60 ms measured with llvmpipe,
        // whose samplers are specialised on power-of-two texture sizes): run the preview's scaling
        // blit now from a power-of-two and from another source, so that no camera change pays.
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

void Viewer::switch_scene(std::shared_ptr<const Scene> scene) {
    params_ = scene->params();
    camera_.reset(scene->camera, scene->geometry->bounds);
    scene_ = scene;
    sent_gen_ = session_->replace_scene(std::move(scene));
    last_sent_ = now();
    dirty_ = false;
    selected_material_ = -1;
    has_pick_ = false;
    glfwSetWindowTitle(window_, ("candela - " + scene_->source).c_str());
}

void Viewer::layout() {
    int win_w, win_h;
    glfwGetFramebufferSize(window_, &fb_w_, &fb_h_);
    glfwGetWindowSize(window_, &win_w, &win_h);
    fb_scale_ = win_w > 0 ? float(fb_w_) / float(win_w) : 1.f;
    int panel = std::min(fb_w_, int(kPanelWidth * fb_scale_));
    area_ = {0, 0, fb_w_ - panel, fb_h_};
    const int iw = params_.settings.width, ih = params_.settings.height;
    if (iw <= area_.width && ih <= area_.height) {
        // Pixel for pixel when it fits: no resampling of the converged image.
        image_rect_ = {(area_.width - iw) / 2, (area_.height - ih) / 2, iw, ih};
    } else {
        image_rect_ = fit_image_rect(iw, ih, area_);
    }
}

void Viewer::camera_changed() {
    camera_.apply(params_.camera);
    params_changed();
}

void Viewer::params_changed() {
    dirty_ = true;
    last_edit_ = now();
}

void Viewer::flush_updates() {
    double t = now();
    if (dirty_) {
        bool shown = image_.generation >= sent_gen_;  // the last edit has reached the screen
        if (shown || t - last_sent_ >= kMaxUpdateDelay) {
            sent_gen_ = session_->update(params_);
            last_sent_ = t;
            dirty_ = false;
            if (opt_.benchmark && bench_waiting_gen_) {
                bench_change_gen_ = sent_gen_;
                bench_waiting_gen_ = false;
            }
        }
    }
    bool interactive = dirty_ || t - last_edit_ < kInteractiveHold;
    if (interactive != interactive_) {
        interactive_ = interactive;
        session_->set_interactive(interactive);
    }
}

void Viewer::camera_input() {
    ImGuiIO& io = ImGui::GetIO();
    // Mouse position in framebuffer pixels, y up (GL), to compare with the layout.
    const float mx = io.MousePos.x * fb_scale_, my = float(fb_h_) - io.MousePos.y * fb_scale_;
    const bool over_area = !io.WantCaptureMouse && mx >= area_.x && mx < area_.x + area_.width && my >= area_.y &&
                           my < area_.y + area_.height;
    for (int b = 0; b < 3; ++b)
        if (over_area && drag_button_ < 0 && ImGui::IsMouseClicked(b)) {
            drag_button_ = b;
            drag_distance_ = 0;
            drag_start_ = io.MousePos;
        }

    const float view_h = std::max(1.f, float(area_.height) / fb_scale_);
    if (drag_button_ >= 0) {
        ImVec2 d = io.MouseDelta;
        if (d.x != 0.f || d.y != 0.f) {
            drag_distance_ += std::abs(d.x) + std::abs(d.y);
            if (drag_button_ == 0) {
                // Half a turn per window height; the scene follows the hand (drag right: it turns right).
                camera_.orbit(-d.x * kPi / view_h, d.y * kPi / view_h);
            } else {
                // The point under the cursor stays under it: one image extent per image size.
                float span = float(params_.camera.fov_axis == FovAxis::Y ? image_rect_.height : image_rect_.width);
                span = std::max(span, 1.f) / fb_scale_;
                camera_.pan(-d.x / span, d.y / span);
            }
            camera_changed();
        }
        if (!ImGui::IsMouseDown(drag_button_)) {
            // A click without motion picks what is under the cursor.
            if (drag_button_ == 0 && drag_distance_ < 3.f) {
                float fx = (drag_start_.x * fb_scale_ - image_rect_.x) / float(image_rect_.width);
                float fy = (drag_start_.y * fb_scale_ - (fb_h_ - image_rect_.y - image_rect_.height)) / float(image_rect_.height);
                if (fx >= 0 && fx < 1 && fy >= 0 && fy < 1) {
                    ivec2 px(int(fx * params_.settings.width), int(fy * params_.settings.height));
                    Camera cam = params_.camera;
                    cam.set_film_size(params_.settings.width, params_.settings.height);
                    pick_ = pick(*scene_, cam, vec2(px) + 0.5f);
                    pick_pixel_ = px;
                    has_pick_ = true;
                    if (pick_.hit) {
                        selected_material_ = int(pick_.material);
                        reveal_selected_ = true;
                    }
                }
            }
            drag_button_ = -1;
        }
    }
    if (over_area && io.MouseWheel != 0.f) {
        camera_.dolly(io.MouseWheel);
        camera_changed();
    }
    if (!io.WantCaptureKeyboard) {
        vec3 move(0.f);
        auto key = [](int k) { return ImGui::IsKeyDown(k) ? 1.f : 0.f; };
        move.x = key(GLFW_KEY_D) - key(GLFW_KEY_A);
        move.y = key(GLFW_KEY_E) - key(GLFW_KEY_Q);
        move.z = key(GLFW_KEY_W) - key(GLFW_KEY_S);
        if (move != vec3(0.f)) {
            // A quarter of the scene per second; shift for four times that.
            float speed = 0.25f * (io.KeyShift ? 4.f : 1.f) * std::min(io.DeltaTime, 0.1f);
            camera_.fly(move * speed);
            camera_changed();
        }
    }
}

void Viewer::poll_background_work() {
    using namespace std::chrono_literals;
    if (loading_.valid() && loading_.wait_for(0s) == std::future_status::ready) {
        try {
            switch_scene(loading_.get());
            set_status("loaded " + loading_path_, false);
        } catch (const std::exception& e) {
            // The old scene keeps rendering; the message says why the new one did not load.
            set_status(e.what(), true);
        }
    }
    for (size_t i = 0; i < saving_.size();) {
        if (saving_[i].wait_for(0s) != std::future_status::ready) {
            ++i;
            continue;
        }
        std::string err = saving_[i].get();
        if (!err.empty()) set_status(err, true);
        saving_.erase(saving_.begin() + long(i));
    }
    if (!dropped_.empty() && !loading_.valid()) {
        std::string path = dropped_.front();
        dropped_.clear();  // one scene at a time: the first file dropped wins
        std::string ext = file_extension(path);
        if (ext != ".obj" && ext != ".xml") {
            set_status(path + ": not a scene (drop an .obj or .xml file)", true);
            return;
        }
        SceneOverrides ov = opt_.overrides;
        ov.defines.clear();  // -D and the image size were meant for the command line's scene
        ov.width.reset();
        ov.height.reset();
        loading_path_ = path;
        loading_ = std::async(std::launch::async, [path, ov] { return prepare_scene(path, ov); });
        set_status("loading " + path + " ...", false);
    }
}

void Viewer::save_png(const std::string& path) {
    SessionImage img = session_->latest_full_image();
    if (img.rgb.empty()) return set_status("nothing to save yet: no full pass has finished", true);
    try {
        // Through the display program, as headless PNGs; a second program keeps the on-screen
        // texture untouched. Encoding and writing happen off the window's thread.
        if (!saver_) saver_ = std::make_unique<DisplayProgram>(gl_);
        saver_->upload(img.width, img.height, img.rgb.data());
        auto rgba = std::make_shared<std::vector<unsigned char>>(saver_->read_srgb8(display_));
        int w = img.width, h = img.height;
        saving_.push_back(std::async(std::launch::async, [path, w, h, rgba]() -> std::string {
            try {
                write_png_srgb8(path, w, h, *rgba);
                return {};
            } catch (const std::exception& e) {
                return e.what();
            }
        }));
        set_status("saved " + path + " (" + std::to_string(img.passes * std::max(1, opt_.spp_per_frame)) + " spp)", false);
    } catch (const std::exception& e) {
        set_status(e.what(), true);
    }
}

void Viewer::save_exr(const std::string& path) {
    SessionImage img = session_->latest_full_image();
    if (img.rgb.empty()) return set_status("nothing to save yet: no full pass has finished", true);
    auto data = std::make_shared<Image>(Image{img.width, img.height, std::move(img.rgb)});
    saving_.push_back(std::async(std::launch::async, [path, data]() -> std::string {
        try {
            write_linear_image(path, *data);
            return {};
        } catch (const std::exception& e) {
            return e.what();
        }
    }));
    set_status("saved " + path + " (" + std::to_string(img.passes * std::max(1, opt_.spp_per_frame)) + " spp)", false);
}

void Viewer::panel() {
    const float win_w = float(fb_w_) / fb_scale_, win_h = float(fb_h_) / fb_scale_;
    ImGui::SetNextWindowPos(ImVec2(win_w - std::min(kPanelWidth, win_w), 0.f), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(std::min(kPanelWidth, win_w), win_h), ImGuiCond_Always);
    ImGui::Begin("candela", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                                         ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoSavedSettings);
    ImGui::PushItemWidth(-110.f);
    ImGui::TextUnformatted(scene_->source.c_str());
    ImGui::TextDisabled("%dx%d, %zu triangles, %zu lights", params_.settings.width, params_.settings.height,
                        scene_->mesh.triangle_count(), params_.emitters.size());
    if (!status_.empty()) {
        if (status_error_) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.f, 0.4f, 0.35f, 1.f));
        ImGui::TextWrapped("%s", status_.c_str());
        if (status_error_) ImGui::PopStyleColor();
    }
    if (loading_.valid()) ImGui::TextDisabled("loading %s ...", loading_path_.c_str());

    // ---- render control and statistics (none of these widgets changes the image)
    if (ImGui::CollapsingHeader("Render", ImGuiTreeNodeFlags_DefaultOpen)) {
        bool paused = session_->paused();
        if (ImGui::Button(paused ? "Resume" : "Pause", ImVec2(80, 0))) session_->set_paused(!paused);
        ImGui::SameLine();
        if (ImGui::Button("Reset", ImVec2(80, 0))) {
            sent_gen_ = session_->reset();
            last_sent_ = now();
        }
        ImGui::SameLine();
        const bool done = stats_.idle || (opt_.screenshot_after > 0 && stats_.passes >= opt_.screenshot_after);
        ImGui::TextDisabled(paused ? "paused" : stats_.preview ? "preview" : done ? "done" : "rendering");
        ImGui::Text("%.0f spp  (%d passes)", stats_.spp, stats_.passes);
        ImGui::Text("%.2f s   %.3f Msamples/s   %.3f Mrays/s", stats_.elapsed, stats_.msamples_per_s,
                    stats_.mrays_per_s);
        if (stats_.nonfinite > 0) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.f, 0.4f, 0.35f, 1.f));
        ImGui::Text("NaN/Inf samples: %llu", (unsigned long long)stats_.nonfinite);
        if (stats_.nonfinite > 0) ImGui::PopStyleColor();
        std::vector<float> curve = resample_log(stats_.change, stats_.change_time, 120);
        char overlay[64];
        std::snprintf(overlay, sizeof overlay, "rel. change/pass %.2e",
                      stats_.change.empty() ? 0.0 : double(stats_.change.back()));
        ImGui::PlotLines("##convergence", curve.empty() ? nullptr : curve.data(), int(curve.size()), 0, overlay, FLT_MAX,
                         FLT_MAX, ImVec2(ImGui::GetContentRegionAvail().x, 56.f));
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Mean relative change of the image per pass, log10, over render time.\n"
                              "Monte Carlo noise falls as 1/sqrt(spp): the curve flattens as it converges.");
        int max_threads = int(std::max(1u, std::thread::hardware_concurrency()));
        if (ImGui::SliderInt("threads", &threads_, 1, max_threads)) session_->set_threads(threads_);
        ImGui::InputText("##png", png_path_, sizeof png_path_);
        ImGui::SameLine();
        if (ImGui::Button("Save PNG")) save_png(png_path_);
        ImGui::InputText("##exr", exr_path_, sizeof exr_path_);
        ImGui::SameLine();
        if (ImGui::Button("Save EXR")) save_exr(exr_path_);
    }

    // ---- what the image depends on: every change restarts the render
    if (ImGui::CollapsingHeader("Integrator", ImGuiTreeNodeFlags_DefaultOpen)) {
        RenderSettings& st = params_.settings;
        int mode = int(st.sampling);
        if (ImGui::Combo("sampling", &mode, "light sampling\0BSDF sampling\0MIS\0")) {
            st.sampling = SamplingMode(mode);
            params_changed();
        }
        if (ImGui::InputInt("max depth", &st.max_depth)) {
            st.max_depth = std::max(-1, st.max_depth);
            params_changed();
        }
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Scattering events per path; -1: unbounded (unbiased, ended by Russian roulette)");
        // A finite depth drops every longer path: the image converges to a darker one. Say so
        // where the setting is made (docs/accuracy.md measures the energy lost per depth).
        if (st.max_depth >= 0) ImGui::TextColored(ImVec4(1.f, 0.75f, 0.3f, 1.f), "biased: paths longer than %d are dropped", st.max_depth);
        if (ImGui::InputInt("RR depth", &st.rr_depth)) {
            st.rr_depth = std::max(0, st.rr_depth);
            params_changed();
        }
        ImGui::Text("path tracer, accelerator: %s", scene_->accel ? scene_->accel->name().c_str() : "-");
    }

    if (ImGui::CollapsingHeader("Camera & display", ImGuiTreeNodeFlags_DefaultOpen)) {
        float fov = camera_.fov();
        if (ImGui::SliderFloat("fov (deg)", &fov, 5.f, 150.f, "%.1f")) {
            camera_.set_fov(fov);
            camera_changed();
        }
        if (ImGui::Button("Reset camera")) {
            camera_.reset(camera_.initial(), scene_->geometry->bounds);
            camera_changed();
        }
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Left drag: orbit   right/middle drag: pan   wheel: dolly\n"
                              "W A S D Q E: fly (shift: faster)   click: inspect a pixel");
        // Exposure is applied by the display shader: it changes nothing that the film holds.
        ImGui::SliderFloat("exposure", &display_.exposure, -10.f, 10.f, "%.2f stops");
    }

    if (ImGui::CollapsingHeader("Materials", ImGuiTreeNodeFlags_DefaultOpen)) {
        for (size_t i = 0; i < params_.materials.size(); ++i) {
            Material& m = params_.materials[i];
            ImGui::PushID(int(i));
            const bool selected = int(i) == selected_material_;
            if (selected && reveal_selected_) ImGui::SetNextItemOpen(true);
            else if (i == 0) ImGui::SetNextItemOpen(true, ImGuiCond_Once);  // show what editing looks like
            ImGuiTreeNodeFlags flags = ImGuiTreeNodeFlags_OpenOnArrow | (selected ? ImGuiTreeNodeFlags_Selected : 0);
            bool open = ImGui::TreeNodeEx("##m", flags, "%s  (%s)", m.name.empty() ? "(unnamed)" : m.name.c_str(),
                                          bsdf_type_name(m.bsdf));
            if (ImGui::IsItemClicked()) selected_material_ = int(i);
            if (selected && reveal_selected_) {
                ImGui::SetScrollHereY();
                reveal_selected_ = false;
            }
            if (open) {
                if (edit_material(m)) params_changed();
                ImGui::TreePop();
            }
            ImGui::PopID();
        }
    }

    if (!params_.emitters.empty() && ImGui::CollapsingHeader("Lights", ImGuiTreeNodeFlags_DefaultOpen)) {
        for (size_t i = 0; i < params_.emitters.size(); ++i) {
            ImGui::PushID(int(i) + 100000);
            std::string label = "light " + std::to_string(i);
            for (const Shape& s : scene_->shapes)
                if (s.emitter == int32_t(i)) {
                    label += " (" + s.name + ")";
                    break;
                }
            ImGui::TextUnformatted(label.c_str());
            if (edit_emitter(params_.emitters[i])) params_changed();
            ImGui::PopID();
        }
    }

    if (ImGui::CollapsingHeader("Pixel", ImGuiTreeNodeFlags_DefaultOpen)) panel_pick();
    ImGui::TextDisabled("Drop an .obj or .xml file here to open it.");
    ImGui::PopItemWidth();
    ImGui::End();
}

void Viewer::panel_pick() {
    if (!has_pick_) {
        ImGui::TextDisabled("Click the image to inspect a pixel.");
        return;
    }
    ImGui::Text("pixel (%d, %d)", pick_pixel_.x, pick_pixel_.y);
    const SessionImage& img = image_;
    if (!img.preview && img.width == params_.settings.width && pick_pixel_.x < img.width && pick_pixel_.y < img.height) {
        size_t k = (size_t(pick_pixel_.y) * size_t(img.width) + size_t(pick_pixel_.x)) * 3;
        ImGui::Text("mean  %.4g %.4g %.4g", img.rgb[k], img.rgb[k + 1], img.rgb[k + 2]);
        ImGui::Text("samples  %d", img.passes * std::max(1, opt_.spp_per_frame));
    } else {
        ImGui::TextDisabled("mean: waiting for a full pass");
    }
    if (!pick_.hit) {
        ImGui::TextDisabled("nothing there (background)");
        return;
    }
    const Shape& shape = scene_->shapes[pick_.shape];
    ImGui::Text("object  %s", shape.name.c_str());
    static const char* const kKinds[] = {"triangle", "sphere", "disk", "cylinder"};
    if (pick_.kind == PrimKind::Triangle) ImGui::Text("triangle  %u", pick_.triangle);
    else ImGui::Text("%s  uv %.4f %.4f", kKinds[int(pick_.kind)], pick_.uv.x, pick_.uv.y);
    if (pick_.material < params_.materials.size()) {
        const Material& m = params_.materials[pick_.material];
        ImGui::Text("material  %s (%s)", m.name.c_str(), bsdf_type_name(m.bsdf));
    }
    if (pick_.emitter >= 0) ImGui::Text("emits light %d", pick_.emitter);
    ImGui::Text("position  %.4g %.4g %.4g", pick_.position.x, pick_.position.y, pick_.position.z);
    ImGui::Text("normal  %.3f %.3f %.3f", pick_.normal.x, pick_.normal.y, pick_.normal.z);
    ImGui::Text("distance  %.4g", pick_.distance);
}


void Viewer::update_display_cache() {
    const int w = image_rect_.width, h = image_rect_.height;
    if (image_.rgb.empty() || w <= 0 || h <= 0) return;
    if (cache_valid_ && w == cache_w_ && h == cache_h_ && display_.exposure == cache_exposure_) return;
    ensure_color_target(gl_, cache_fbo_, cache_tex_, cache_w_, cache_h_, w, h);
    if (image_.preview && image_.width < w && image_.height < h) {
        // A preview is tonemapped at its own size (1/16 of the pixels), then scaled up by a
        // bilinear blit: in a software GL the full-size shader pass cost ~13 ms per preview, and
        // previews arrive every ~25 ms while the camera moves. (Filtering after the display
        // transform, not before as for the full image; it is a stand-in until the full pass.)
        ensure_color_target(gl_, small_fbo_, small_tex_, small_w_, small_h_, image_.width, image_.height);
        gl_.BindFramebuffer(GL_FRAMEBUFFER, small_fbo_);
        program_->draw({0, 0, image_.width, image_.height}, display_, DisplayFilter::Nearest);
        gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, small_fbo_);
        gl_.BindFramebuffer(GL_DRAW_FRAMEBUFFER, cache_fbo_);
        gl_.BlitFramebuffer(0, 0, image_.width, image_.height, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_LINEAR);
    } else {
        gl_.BindFramebuffer(GL_FRAMEBUFFER, cache_fbo_);
        program_->draw({0, 0, w, h}, display_, image_.preview ? DisplayFilter::Linear : DisplayFilter::Nearest);
    }
    gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
    check_gl_error(gl_, "display cache");
    cache_valid_ = true;
    cache_exposure_ = display_.exposure;
}

bool Viewer::write_screenshot() {
    // The window's own framebuffer, panel included, before the swap.
    std::vector<unsigned char> rgba(size_t(fb_w_) * size_t(fb_h_) * 4), flipped(rgba.size());
    gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl_.ReadPixels(0, 0, fb_w_, fb_h_, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    check_gl_error(gl_, "screenshot");
    const size_t row = size_t(fb_w_) * 4;
    for (int y = 0; y < fb_h_; ++y)  // GL rows run bottom-up
        std::copy_n(&rgba[size_t(fb_h_ - 1 - y) * row], row, &flipped[size_t(y) * row]);
    write_png_srgb8(opt_.screenshot, fb_w_, fb_h_, flipped);
    // The layout in image coordinates (top-left origin), for tests that inspect the picture.
    const int top = fb_h_ - image_rect_.y - image_rect_.height;
    const int panel_x = area_.width;
    std::printf("candela: screenshot %s: window %dx%d, image %d,%d %dx%d, panel %d,%d %dx%d, %.0f spp\n",
                opt_.screenshot.c_str(), fb_w_, fb_h_, image_rect_.x, top, image_rect_.width, image_rect_.height,
                panel_x, 0, fb_w_ - panel_x, fb_h_, stats_.spp);
    std::fflush(stdout);
    return true;
}

void Viewer::benchmark_step(double frame_start, double frame_cpu_start) {
    ViewerBenchmark& b = *opt_.benchmark;
    double t = now();
    if (bench_start_ == 0) {
        // Start once the first full pass is on screen: the steady state of a session.
        if (image_.rgb.empty() || (image_.preview && !b.paused)) return;
        bench_start_ = t;
        bench_next_move_ = t;
    }
    if (t - bench_start_ > b.duration) {
        glfwSetWindowShouldClose(window_, GLFW_TRUE);
        return;
    }
    b.frame_ms.push_back((t - frame_start) * 1e3);
    b.frame_cpu_ms.push_back((thread_cpu_seconds() - frame_cpu_start) * 1e3);
    b.frame_new_image.push_back(frame_new_image_);
    ++b.frames;
    // A change is "shown" at the end of the first frame whose image comes from it.
    if (bench_change_time_ >= 0 && !bench_waiting_gen_ && image_.generation >= bench_change_gen_) {
        b.update_ms.push_back((t - bench_change_time_) * 1e3);
        bench_change_time_ = -1;
    }
}

int Viewer::run() {
    double frame_start = now();
    for (;;) {
        // Sleep until something happens: input, a new image (the worker posts an empty event), the
        // end of the interactive hold, or the next paced frame while keys fly the camera.
        bool animating = drag_button_ >= 0 || ImGui::IsKeyDown(GLFW_KEY_W) || ImGui::IsKeyDown(GLFW_KEY_A) ||
                         ImGui::IsKeyDown(GLFW_KEY_S) || ImGui::IsKeyDown(GLFW_KEY_D) ||
                         ImGui::IsKeyDown(GLFW_KEY_Q) || ImGui::IsKeyDown(GLFW_KEY_E) || dirty_ ||
                         opt_.benchmark != nullptr;
        double timeout = 0.25;  // statistics refresh even when nothing else happens
        if (interactive_) timeout = std::min(timeout, std::max(0.0, last_edit_ + kInteractiveHold - now()));
        if (animating) timeout = std::min(timeout, std::max(0.0, frame_start + kFrameInterval - now()));
        if (frame_ < 3 || opt_.screenshot_after > 0) timeout = std::min(timeout, 0.05);
        if (timeout > 0) glfwWaitEventsTimeout(timeout);
        else glfwPollEvents();
        if (glfwWindowShouldClose(window_)) break;
        frame_start = now();
        const double frame_cpu_start = opt_.benchmark ? thread_cpu_seconds() : 0.0;

        poll_background_work();
        frame_new_image_ = false;
        if (session_->take_image(image_)) {
            frame_new_image_ = true;
            program_->upload(image_.width, image_.height, image_.rgb.data());
            cache_valid_ = false;
        }
        stats_ = session_->stats();

        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        layout();
        camera_input();
        if (opt_.benchmark && bench_start_ > 0) {
            // Scripted drags: a small orbit step in each frame of a burst.
            double t = now();
            if (bench_burst_left_ == 0 && t >= bench_next_move_) {
                bench_burst_left_ = opt_.benchmark->moves_per_burst;
                bench_next_move_ = t + opt_.benchmark->move_every;
            }
            if (bench_burst_left_ > 0) {
                --bench_burst_left_;
                camera_.orbit(0.01f, 0.f);
                camera_changed();
                if (bench_change_time_ < 0) {
                    bench_change_time_ = t;
                    bench_waiting_gen_ = true;
                }
            }
        }
        panel();
        flush_updates();
        ImGui::Render();

        update_display_cache();
        gl_.Viewport(0, 0, fb_w_, fb_h_);
        gl_.ClearColor(0.02f, 0.02f, 0.02f, 1.f);
        gl_.Clear(GL_COLOR_BUFFER_BIT);
        if (!image_.rgb.empty() && cache_valid_) {
            // The tonemapped image is copied, not drawn: a blit of the cache costs a software GL
            // (llvmpipe) a fraction of a textured, blended quad -- 8 of the 20 ms of CPU a frame
            // took on 2 cores. Both are bottom-up, so no flip; the panel is drawn over it.
            gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, cache_fbo_);
            gl_.BlitFramebuffer(0, 0, image_rect_.width, image_rect_.height, image_rect_.x, image_rect_.y,
                                image_rect_.x + image_rect_.width, image_rect_.y + image_rect_.height,
                                GL_COLOR_BUFFER_BIT, GL_NEAREST);
            gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
        }
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        ++frame_;

        // Screenshot: once the requested passes are on screen, unedited, and the panel has settled.
        bool shot = opt_.screenshot_after > 0 && !image_.preview && image_.generation == 0 &&
                    image_.passes >= opt_.screenshot_after && frame_ > 3;
        if (shot) write_screenshot();
        glfwSwapBuffers(window_);
        if (shot) return 0;
        if (opt_.benchmark) benchmark_step(frame_start, frame_cpu_start);
    }
    return 0;
}

}  // namespace

int run_viewer(const ViewerOptions& opt) {
    if (opt.screenshot_after > 0 && opt.screenshot.empty()) throw Error("--screenshot-after needs a PNG file name");
    Viewer viewer(opt);
    return viewer.run();
}

}  // namespace candela
