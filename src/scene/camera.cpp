#include "scene/camera.h"
#include <cmath>

namespace candela {

double horizontal_fov(double fov_deg, FovAxis axis, double aspect) {
    // Smaller and larger resolve to x or y by the film's aspect, as Mitsuba's parse_fov.
    if (axis == FovAxis::Smaller) axis = aspect > 1.0 ? FovAxis::Y : FovAxis::X;
    if (axis == FovAxis::Larger) axis = aspect > 1.0 ? FovAxis::X : FovAxis::Y;
    const double to_rad = 3.14159265358979323846 / 180.0;
    switch (axis) {
        case FovAxis::X: return fov_deg;
        case FovAxis::Y: return 2.0 * std::atan(std::tan(0.5 * fov_deg * to_rad) * aspect) / to_rad;
        default: {  // diagonal
            double diagonal = 2.0 * std::tan(0.5 * fov_deg * to_rad);
            double width = diagonal / std::sqrt(1.0 + 1.0 / (aspect * aspect));
            return 2.0 * std::atan(width * 0.5) / to_rad;
        }
    }
}

double focal_length_to_fov(double focal_mm) {
    // The diagonal of a 36 x 24 mm film seen from the focal length.
    return 2.0 * std::atan(std::sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2.0 * focal_mm)) * 180.0 / 3.14159265358979323846;
}

void Camera::set_film_size(int width, int height) {
    const bool cropped = film_size.x > 0 && film_size.y > 0;
    const ivec2 image(width, height);
    const ivec2 full = cropped ? film_size : image;
    const ivec2 window = cropped ? crop_size : image;
    inv_film_ = vec2(1.f / float(full.x), 1.f / float(full.y));
    // The image covers the crop window: at the window's own size a pixel is a film pixel (scale
    // exactly 1, an integer offset); otherwise the window is resampled.
    if (image == window) {
        pixel_scale_ = vec2(1.f);
        seed_offset_ = cropped ? crop_offset : ivec2(0);
    } else {
        pixel_scale_ = vec2(float(window.x) / float(width), float(window.y) / float(height));
        seed_offset_ = ivec2(0);
    }
    pixel_offset_ = cropped ? vec2(crop_offset) : vec2(0.f);

    const double aspect = double(full.x) / double(full.y);
    inv_aspect_ = float(1.0 / aspect);
    // As Mitsuba: the horizontal fov is resolved in double, stored as a float, and the vertical
    // extent is the horizontal one divided by the aspect.
    float x_fov = float(horizontal_fov(fov_deg, fov_axis, aspect));
    tan_half_x_ = std::tan(glm::radians(x_fov * 0.5f));
    tan_half_y_ = tan_half_x_ / float(aspect);
    origin_ = vec3(to_world[3]);
    ortho_dir_ = glm::normalize(vec3(to_world[2]));
}

}  // namespace candela
