#include "viewer/front_end.h"
#include <chrono>
#include "core/error.h"
#include "film/image_io.h"
#include "headless/headless.h"

namespace candela {

namespace {

bool ready(const std::future<std::string>& f) {
    return f.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

}  // namespace

ViewerFrontEnd::ViewerFrontEnd(std::shared_ptr<const Scene> scene, const SessionOptions& opt,
                               const SceneOverrides& drop_overrides)
    : scene_(scene), params_(scene->params()), camera_(scene->camera, scene->geometry->bounds),
      drop_overrides_(drop_overrides), spp_per_pass_(std::max(1, opt.spp_per_pass)) {
    session_ = std::make_unique<RenderSession>(std::move(scene), opt);
}

ViewerFrontEnd::~ViewerFrontEnd() {
    session_.reset();  // joins the worker (at most one tile per thread)
    for (auto& f : saving_) f.wait();
    if (loading_.valid()) loading_.wait();
}

void ViewerFrontEnd::switch_scene(std::shared_ptr<const Scene> scene) {
    params_ = scene->params();
    camera_.reset(scene->camera, scene->geometry->bounds);
    scene_ = scene;
    sent_gen_ = session_->replace_scene(std::move(scene));
    dirty_ = false;
    selected_material = -1;
    has_pick_ = false;
    if (on_switched_) on_switched_();
}

bool ViewerFrontEnd::begin_frame(double now) {
    if (loading_.valid() && loading_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
        try {
            switch_scene(loading_.get());
            last_sent_ = now;
            set_status("loaded " + loading_path_, false);
        } catch (const std::exception& e) {
            set_status(e.what(), true);  // the old scene keeps rendering; this says why
        }
    }
    for (size_t i = 0; i < saving_.size();) {
        if (!ready(saving_[i])) {
            ++i;
            continue;
        }
        std::string err = saving_[i].get();
        if (!err.empty()) set_status(err, true);
        saving_.erase(saving_.begin() + long(i));
    }
    if (!dropped_.empty() && !loading_.valid()) {
        std::string path = dropped_.front();
        dropped_.clear();
        std::string ext = file_extension(path);
        if (ext != ".obj" && ext != ".xml") {
            set_status(path + ": not a scene (drop an .obj or .xml file)", true);
        } else {
            SceneOverrides ov = drop_overrides_;
            loading_path_ = path;
            loading_ = std::async(std::launch::async, [path, ov] { return prepare_scene(path, ov); });
            set_status("loading " + path + " ...", false);
        }
    }
    session_->take_image(image_);
    if (denoise_view_) session_->take_denoised(denoised_);
    stats_ = session_->stats();
    // New to the screen: another image, or the same one switched between raw and denoised.
    const SessionImage* shown = &image();
    const bool fresh = shown != last_shown_ || shown->sequence != last_shown_sequence_;
    last_shown_ = shown;
    last_shown_sequence_ = shown->sequence;
    return fresh && !shown->rgb.empty();
}

void ViewerFrontEnd::set_denoise_view(bool on, DenoiseQuality q) {
    denoise_view_ = on;
    denoise_quality_ = q;
    session_->set_denoise(on, q);
}

void ViewerFrontEnd::end_frame(double now) {
    if (dirty_) {
        const bool shown = image_.generation >= sent_gen_;  // the last edit has reached the screen
        if (shown || now - last_sent_ >= kMaxUpdateDelay) {
            sent_gen_ = session_->update(params_);
            last_sent_ = now;
            dirty_ = false;
        }
    }
    const bool interactive = dirty_ || now - last_edit_ < kInteractiveHold;
    if (interactive != interactive_) {
        interactive_ = interactive;
        session_->set_interactive(interactive);
    }
}

void ViewerFrontEnd::params_changed(double now) {
    dirty_ = true;
    last_edit_ = now;
}

void ViewerFrontEnd::camera_changed(double now) {
    camera_.apply(params_.camera);
    params_changed(now);
}

void ViewerFrontEnd::reset_camera(double now) {
    camera_.reset(camera_.initial(), scene_->geometry->bounds);
    camera_changed(now);
}

void ViewerFrontEnd::restart(double now) {
    sent_gen_ = session_->reset();
    last_sent_ = now;
}

void ViewerFrontEnd::drop(const std::vector<std::string>& paths) {
    if (!paths.empty()) dropped_ = {paths.front()};
}

void ViewerFrontEnd::save_exr(const std::string& path) {
    SessionImage img = session_->latest_full_image();
    if (img.rgb.empty()) return set_status("nothing to save yet: no full pass has finished", true);
    const int spp = img.passes * spp_per_pass_;
    auto data = std::make_shared<Image>(Image{img.width, img.height, std::move(img.rgb)});
    saving_.push_back(std::async(std::launch::async, [path, data]() -> std::string {
        try {
            write_linear_image(path, *data);
            return {};
        } catch (const std::exception& e) {
            return e.what();
        }
    }));
    set_status("saved " + path + " (" + std::to_string(spp) + " spp)", false);
}

void ViewerFrontEnd::save_png(const std::string& path, const SessionImage& img, std::vector<unsigned char> rgba) {
    auto data = std::make_shared<std::vector<unsigned char>>(std::move(rgba));
    const int w = img.width, h = img.height;
    saving_.push_back(std::async(std::launch::async, [path, w, h, data]() -> std::string {
        try {
            write_png_srgb8(path, w, h, *data);
            return {};
        } catch (const std::exception& e) {
            return e.what();
        }
    }));
    set_status("saved " + path + " (" + std::to_string(img.passes * spp_per_pass_) + " spp)", false);
}

void ViewerFrontEnd::pick(ivec2 px) {
    Camera cam = params_.camera;
    cam.set_film_size(params_.settings.width, params_.settings.height);
    pick_ = candela::pick(*scene_, cam, vec2(px) + 0.5f);
    pick_pixel_ = px;
    has_pick_ = true;
    if (pick_.hit) {
        selected_material = int(pick_.material);
        reveal_selected = true;
    }
}

}  // namespace candela
