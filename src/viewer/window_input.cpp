// Mouse and keyboard over the render area: orbit, pan, dolly, fly, and a click to pick.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <algorithm>
#include <cmath>
#include "viewer/window.h"

namespace candela {

void Viewer::camera_input() {
    ImGuiIO& io = ImGui::GetIO();
    const double t = viewer_now();
    CameraController& camera = fe_->camera();
    // Mouse position in framebuffer pixels, y up (GL), to compare with the layout.
    const float mx = io.MousePos.x * fb_scale_, my = float(fb_h_) - io.MousePos.y * fb_scale_;
    const bool over_area = !io.WantCaptureMouse && mx >= area_.x && mx < area_.x + area_.width && my >= area_.y &&
                           my < area_.y + area_.height;
    for (int b = 0; b < 3; ++b)
        if (over_area && drag_button_ < 0 && ImGui::IsMouseClicked(b)) {
            drag_button_ = b;
            drag_distance_ = 0;
            drag_start_x_ = io.MousePos.x;
            drag_start_y_ = io.MousePos.y;
        }

    const float view_h = std::max(1.f, float(area_.height) / fb_scale_);
    if (drag_button_ >= 0) {
        ImVec2 d = io.MouseDelta;
        if (d.x != 0.f || d.y != 0.f) {
            drag_distance_ += std::abs(d.x) + std::abs(d.y);
            if (drag_button_ == 0) {
                // Half a turn per window height; the scene follows the hand (drag right: it turns right).
                camera.orbit(-d.x * kPi / view_h, d.y * kPi / view_h);
            } else {
                // The point under the cursor stays under it: one image extent per image size.
                float span = float(fe_->params().camera.fov_axis == FovAxis::Y ? image_rect_.height : image_rect_.width);
                span = std::max(span, 1.f) / fb_scale_;
                camera.pan(-d.x / span, d.y / span);
            }
            fe_->camera_changed(t);
        }
        if (!ImGui::IsMouseDown(drag_button_)) {
            // A click without motion picks what is under the cursor.
            if (drag_button_ == 0 && drag_distance_ < 3.f) {
                float fx = (drag_start_x_ * fb_scale_ - float(image_rect_.x)) / float(image_rect_.width);
                float fy = (drag_start_y_ * fb_scale_ - float(fb_h_ - image_rect_.y - image_rect_.height)) /
                           float(image_rect_.height);
                const RenderSettings& st = fe_->params().settings;
                if (fx >= 0 && fx < 1 && fy >= 0 && fy < 1) fe_->pick(ivec2(int(fx * float(st.width)), int(fy * float(st.height))));
            }
            drag_button_ = -1;
        }
    }
    if (over_area && io.MouseWheel != 0.f) {
        camera.dolly(io.MouseWheel);
        fe_->camera_changed(t);
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
            camera.fly(move * speed);
            fe_->camera_changed(t);
        }
    }
}

}  // namespace candela
