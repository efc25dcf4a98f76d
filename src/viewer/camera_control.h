#pragma once
// Interactive camera motion for the viewer: orbit around a target, pan, dolly and fly. It edits a
// copy of Scene::camera (to_world, fov); the caller hands the result to the render session. No
// window system here, so the tests can drive it directly.
//
// The state is (origin, target, up): `up` is the scene camera's up vector, kept fixed so that
// orbiting never rolls the horizon. to_world is rebuilt with look_at (Mitsuba's convention: columns
// left, up, forward, origin); a scene camera with a mirrored basis (det < 0) stays mirrored.
// An orthographic camera keeps its to_world scale (its extent) through every move; its dolly zooms
// (scales the extent), since moving it along the view changes nothing but the clipping.
#include <algorithm>
#include <cmath>
#include "core/aabb.h"
#include "scene/camera.h"

namespace candela {

class CameraController {
public:
    CameraController() = default;
    CameraController(const Camera& cam, const AABB& scene_bounds) { reset(cam, scene_bounds); }

    // Back to the scene's camera, exactly. The orbit target is the scene's centre projected on the
    // view axis (so orbiting turns around the middle of what is in view), or a point at half the
    // scene's size in front of the camera when the centre is behind it.
    void reset(const Camera& cam, const AABB& bounds) {
        initial_ = cam;
        to_world_ = cam.to_world;
        fov_deg_ = cam.fov_deg;
        ortho_ = cam.type == CameraType::Orthographic;
        extent_ = vec3(glm::length(vec3(cam.to_world[0])), glm::length(vec3(cam.to_world[1])),
                       glm::length(vec3(cam.to_world[2])));
        origin_ = vec3(cam.to_world[3]);
        vec3 fwd = glm::normalize(vec3(cam.to_world[2]));
        up_ = glm::normalize(vec3(cam.to_world[1]));
        vec3 left = vec3(cam.to_world[0]);
        mirrored_ = glm::dot(glm::cross(up_, fwd), left) < 0.f;
        scale_ = bounds.empty() ? 1.f : std::max(glm::length(bounds.extent()), 1e-6f);
        vec3 center = bounds.empty() ? origin_ + fwd : bounds.center();
        float d = glm::dot(center - origin_, fwd);
        if (!(d > 1e-3f * scale_)) d = 0.5f * scale_;
        target_ = origin_ + d * fwd;
    }

    // Writes the current pose and field of view into `cam` (other fields are left alone). The
    // caller calls cam.set_film_size before generating rays with it.
    void apply(Camera& cam) const {
        cam.to_world = to_world_;
        cam.fov_deg = fov_deg_;
    }
    Camera initial() const { return initial_; }

    // Turns the camera around the target: `yaw` about the up vector, `pitch` about the camera's
    // horizontal axis (radians; positive pitch raises the camera). The pitch stops short of the
    // poles, where the view would align with `up` and the basis would become undefined.
    void orbit(float yaw, float pitch) {
        vec3 offset = origin_ - target_;
        float dist = glm::length(offset);
        if (!(dist > 0.f)) return;
        offset = rotate(offset, yaw, up_);
        float angle = std::acos(std::clamp(glm::dot(offset / dist, up_), -1.f, 1.f));  // from the pole
        const float margin = 0.01f;
        float new_angle = std::clamp(angle - pitch, margin, kPi - margin);
        vec3 axis = glm::cross(up_, offset);  // horizontal, perpendicular to the offset
        if (glm::dot(axis, axis) > 0.f) offset = rotate(offset, angle - new_angle, glm::normalize(axis));
        origin_ = target_ + offset;
        rebuild();
    }

    // Moves camera and target together within the view plane, by (right, up) in units of the
    // visible height at the target's distance: pan(0, 1) shifts the view by one screen height.
    // An orthographic camera's unit is its visible width (2 x its to_world x scale).
    void pan(float right, float up) {
        float h = ortho_ ? 2.f * extent_.x : 2.f * distance() * std::tan(glm::radians(fov_deg_) * 0.5f);
        vec3 delta = h * (right * right_axis() + up * up_axis());
        origin_ += delta;
        target_ += delta;
        rebuild();
    }

    // Moves towards the target (steps > 0) by a factor 0.85 per step; never reaches it.
    // An orthographic camera instead shrinks its extent by that factor (a zoom).
    void dolly(float steps) {
        if (ortho_) {
            extent_.x = std::max(extent_.x * std::pow(0.85f, steps), 1e-6f * scale_);
            extent_.y = std::max(extent_.y * std::pow(0.85f, steps), 1e-6f * scale_);
            rebuild();
            return;
        }
        vec3 offset = origin_ - target_;
        float d = glm::length(offset) * std::pow(0.85f, steps);
        d = std::max(d, 1e-4f * scale_);
        origin_ = target_ + glm::normalize(offset) * d;
        rebuild();
    }

    // Flies camera and target by `move` = (right, up, forward) in scene sizes: fly(0, 0, 1) moves
    // forward by the diagonal of the scene's bounding box. "up" is the fixed up vector (Q/E).
    void fly(vec3 move) {
        vec3 delta = scale_ * (move.x * right_axis() + move.y * up_ + move.z * forward());
        origin_ += delta;
        target_ += delta;
        rebuild();
    }

    void set_fov(float deg) {
        fov_deg_ = std::clamp(deg, 1.f, 170.f);
    }
    float fov() const { return fov_deg_; }

    vec3 origin() const { return origin_; }
    vec3 target() const { return target_; }
    float distance() const { return glm::length(target_ - origin_); }
    vec3 forward() const { return glm::normalize(target_ - origin_); }
    const mat4& to_world() const { return to_world_; }
    float scene_scale() const { return scale_; }

private:
    static vec3 rotate(vec3 v, float angle, vec3 axis) {  // Rodrigues' formula, axis unit length
        float c = std::cos(angle), s = std::sin(angle);
        return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.f - c);
    }
    // Image-space axes in world space. Camera space has +x to the image's LEFT (Mitsuba).
    vec3 right_axis() const { return -glm::normalize(vec3(to_world_[0])); }
    vec3 up_axis() const { return glm::normalize(vec3(to_world_[1])); }

    void rebuild() {
        to_world_ = look_at(origin_, target_, up_);
        if (mirrored_) to_world_[0] = -to_world_[0];
        if (ortho_) {
            to_world_[0] *= extent_.x;
            to_world_[1] *= extent_.y;
            to_world_[2] *= extent_.z;
        }
    }

    Camera initial_;
    mat4 to_world_{1.f};
    float fov_deg_ = 40.f;
    vec3 origin_{0.f}, target_{0.f, 0.f, 1.f}, up_{0.f, 1.f, 0.f};
    float scale_ = 1.f;
    bool mirrored_ = false;
    bool ortho_ = false;
    vec3 extent_{1.f};  // orthographic: the lengths of to_world's columns
};

}  // namespace candela
