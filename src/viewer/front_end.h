#pragma once
// The viewer's side of the render session, without a window: the parameters the panel edits, the
// camera controller, when edits are sent, the image on screen, picking, dropped files loaded in the
// background and images saved in the background. The window (viewer.cpp) feeds it input and draws
// what it holds; the tests drive it the same way, without GL, and so does ThreadSanitizer.
//
// Threads: every member function is called on the window's thread. The session's worker renders
// and builds scenes on its own threads; what the front end reads of the scene is an immutable
// snapshot (RenderSession::scene), and its own copy of the parameters is never shared.
#include <future>
#include <memory>
#include <string>
#include <vector>
#include "render/launch.h"
#include "render/session.h"
#include "viewer/camera_control.h"
#include "viewer/pick.h"

namespace candela {

class ViewerFrontEnd {
public:
    // After the last edit, previews continue this long, so that a drag that pauses for a moment
    // does not start a full pass that the next motion cancels.
    static constexpr double kInteractiveHold = 0.2;
    // Edits are sent when the previous one has reached the screen, or after this long: mouse events
    // can arrive faster than previews render, and cancelling every preview would freeze the view.
    static constexpr double kMaxUpdateDelay = 0.1;

    // `drop_overrides`: the command line's overrides less what was meant for its own scene, for
    // scenes dropped on the window.
    ViewerFrontEnd(std::shared_ptr<const Scene> scene, const SessionOptions& opt, const SceneOverrides& drop_overrides);
    // Joins the worker, then waits for background loads and saves.
    ~ViewerFrontEnd();
    ViewerFrontEnd(const ViewerFrontEnd&) = delete;
    ViewerFrontEnd& operator=(const ViewerFrontEnd&) = delete;

    // Once per frame, before input and the panel: finished loads and saves, the next dropped file,
    // the newest image (true when a new one arrived: upload it), the statistics.
    bool begin_frame(double now);
    // Once per frame, after input and the panel: sends the edits when it is time, and tells the
    // session whether the user is interacting.
    void end_frame(double now);

    // Edits. The panel changes params() (or camera()) and then says so.
    SceneParams& params() { return params_; }
    CameraController& camera() { return camera_; }
    void params_changed(double now);
    void camera_changed(double now);  // camera() -> params().camera, then params_changed
    void reset_camera(double now);
    bool dirty() const { return dirty_; }
    bool interactive() const { return interactive_; }
    double interactive_until() const { return last_edit_ + kInteractiveHold; }  // when the hold ends
    uint64_t sent_generation() const { return sent_gen_; }
    void restart(double now);  // the panel's Reset button: same parameters, a new accumulation

    // Files: dropped scenes load in the background while the old scene keeps rendering; the first
    // file of a drop wins. Saves write the newest full-resolution image off this thread.
    void drop(const std::vector<std::string>& paths);
    bool loading() const { return loading_.valid(); }
    const std::string& loading_path() const { return loading_path_; }
    void save_exr(const std::string& path);
    // A PNG is tonemapped by the window's display program (GL); this writes the bytes it made.
    void save_png(const std::string& path, const SessionImage& img, std::vector<unsigned char> rgba);
    bool saving() const { return !saving_.empty(); }

    // What is under pixel `px` of the full image (x right, y down), with the current camera.
    void pick(ivec2 px);
    bool has_pick() const { return has_pick_; }
    ivec2 pick_pixel() const { return pick_pixel_; }
    const PickResult& pick_result() const { return pick_; }
    int selected_material = -1;  // highlighted in the panel
    bool reveal_selected = false;  // scroll the panel to it once

    RenderSession& session() { return *session_; }
    const Scene& scene() const { return *scene_; }
    // The image on screen: the denoised film when the denoised view is on and the denoiser has
    // caught up with the film's generation (the raw film until then, and during previews).
    const SessionImage& image() const { return showing_denoised() ? denoised_ : image_; }
    const SessionImage& raw_image() const { return image_; }
    // The denoised view (docs/denoising.md): one toggle; the raw film is the other state.
    void set_denoise_view(bool on, DenoiseQuality q);
    bool denoise_view() const { return denoise_view_; }
    DenoiseQuality denoise_quality() const { return denoise_quality_; }
    bool showing_denoised() const {
        return denoise_view_ && !denoised_.rgb.empty() && !image_.preview && denoised_.generation == image_.generation &&
               denoised_.width == image_.width && denoised_.height == image_.height;
    }
    const SessionStats& stats() const { return stats_; }
    int spp_per_pass() const { return spp_per_pass_; }
    const std::string& status() const { return status_; }
    bool status_is_error() const { return status_error_; }
    void set_status(const std::string& s, bool error) { status_ = s, status_error_ = error; }
    // Called after a dropped scene replaced the old one (e.g. to retitle the window).
    void set_on_scene_switched(std::function<void()> f) { on_switched_ = std::move(f); }

private:
    void switch_scene(std::shared_ptr<const Scene> scene);

    std::unique_ptr<RenderSession> session_;
    std::shared_ptr<const Scene> scene_;  // the snapshot the window shows names and bounds from
    SceneParams params_;                  // the window's copy of what the worker renders
    CameraController camera_;
    SceneOverrides drop_overrides_;
    int spp_per_pass_ = 1;
    SessionImage image_;     // the newest raw image
    SessionImage denoised_;  // the newest denoised one
    bool denoise_view_ = false;
    DenoiseQuality denoise_quality_ = DenoiseQuality::Balanced;
    const SessionImage* last_shown_ = nullptr;  // what begin_frame last reported
    uint64_t last_shown_sequence_ = 0;
    SessionStats stats_;

    bool dirty_ = false;  // edited since the last update()
    uint64_t sent_gen_ = 0;
    double last_sent_ = 0, last_edit_ = -1e9;
    bool interactive_ = false;

    bool has_pick_ = false;
    ivec2 pick_pixel_{0};
    PickResult pick_;
    std::string status_;
    bool status_error_ = false;

    std::vector<std::string> dropped_;
    std::future<std::shared_ptr<const Scene>> loading_;
    std::string loading_path_;
    std::vector<std::future<std::string>> saving_;  // each: empty, or the error
    std::function<void()> on_switched_;
};

}  // namespace candela
