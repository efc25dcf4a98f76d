#pragma once
#include "core/ray.h"

namespace candela {

// Mitsuba's lookat transform: camera-to-world with columns (left, up, forward, origin), where
// left = normalize(up x forward). Degenerate input (target == origin, up parallel to the view)
// yields NaNs; callers validate.
inline mat4 look_at(vec3 origin, vec3 target, vec3 up) {
    vec3 dir = glm::normalize(target - origin);
    vec3 left = glm::normalize(glm::cross(up, dir));
    vec3 new_up = glm::cross(dir, left);
    mat4 m(1.f);
    m[0] = glm::vec4(left, 0.f);
    m[1] = glm::vec4(new_up, 0.f);
    m[2] = glm::vec4(dir, 0.f);
    m[3] = glm::vec4(origin, 1.f);
    return m;
}

enum class FovAxis { X, Y, Diagonal, Smaller, Larger };

// Mitsuba 3's `perspective` sensor. Camera space looks along +z with +y up and +x to the LEFT
// of the image (Mitsuba's lookat builds the basis (left, up, forward)); to_world maps camera
// space to world space. Film coordinates run from (0,0) at the top-left corner to (width, height).
struct Camera {
    mat4 to_world{1.f};
    float fov_deg = 39.3077f;
    FovAxis fov_axis = FovAxis::X;
    float near_clip = 1e-2f;
    float far_clip = 1e4f;

    // Prepares the per-ray constants for a film of the given size. Call before generate_ray.
    void set_film_size(int width, int height);

    // The primary ray through film position `film` (in pixels, may be fractional). Unit direction;
    // it starts at the near clip plane and ends at the far one, as in Mitsuba.
    Ray generate_ray(vec2 film) const {
        float sx = 1.f - 2.f * film.x * inv_width_;
        float sy = 1.f - 2.f * film.y * inv_height_;
        vec3 dc = glm::normalize(vec3(sx * tan_half_x_, sy * tan_half_y_, 1.f));
        Ray r;
        r.d = glm::normalize(vec3(to_world * glm::vec4(dc, 0.f)));
        float inv_z = 1.f / dc.z;
        r.o = origin_ + r.d * (near_clip * inv_z);
        r.tmin = 0.f;
        r.tmax = (far_clip - near_clip) * inv_z;
        return r;
    }

    vec3 origin() const { return origin_; }

private:
    float tan_half_x_ = 0.35f, tan_half_y_ = 0.35f;
    float inv_width_ = 1.f, inv_height_ = 1.f;
    vec3 origin_{0.f};
};

}  // namespace candela
