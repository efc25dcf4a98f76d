#include "scene/camera.h"

namespace candela {

void Camera::set_film_size(int width, int height) {
    inv_width_ = 1.f / float(width);
    inv_height_ = 1.f / float(height);
    float aspect = float(width) / float(height);
    // Mitsuba: the fov spans the chosen axis; diagonal, smaller and larger resolve to x or y.
    float t = std::tan(glm::radians(fov_deg) * 0.5f);
    FovAxis axis = fov_axis;
    if (axis == FovAxis::Smaller) axis = aspect > 1.f ? FovAxis::Y : FovAxis::X;
    if (axis == FovAxis::Larger) axis = aspect > 1.f ? FovAxis::X : FovAxis::Y;
    switch (axis) {
        case FovAxis::X: tan_half_x_ = t; tan_half_y_ = t / aspect; break;
        case FovAxis::Y: tan_half_y_ = t; tan_half_x_ = t * aspect; break;
        default: {  // diagonal
            float diag = std::sqrt(1.f + 1.f / (aspect * aspect));
            tan_half_x_ = t / diag;
            tan_half_y_ = tan_half_x_ / aspect;
        }
    }
    origin_ = vec3(to_world[3]);
}

}  // namespace candela
