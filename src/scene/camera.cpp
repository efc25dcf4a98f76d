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

    // Importance: the image (the crop window) as a fraction of the full film, on the plane z = 1
    // (perspective, thin lens) or on the orthographic film plane, seen along the view direction.
    from_world_ = glm::inverse(to_world);
    image_size_ = image;
    const vec2 frac = vec2(window) * inv_film_;
    if (type == CameraType::Orthographic) {
        const float local = 4.f * inv_aspect_ * frac.x * frac.y;  // [-1,1] x [-1/aspect, 1/aspect]
        importance_area_ = local * std::abs(glm::dot(glm::cross(vec3(to_world[0]), vec3(to_world[1])), ortho_dir_));
    } else {
        importance_area_ = 4.f * tan_half_x_ * tan_half_y_ * frac.x * frac.y;
    }
}

vec2 Camera::raster_of_plane_point(vec2 p1) const {
    // generate_ray backwards: p1 = ((1 - 2u.x) tx, (1 - 2u.y) ty) with u the film fraction (plus
    // the principal point offset), film = u / inv_film, image = (film - offset) / scale.
    vec2 u;
    if (type == CameraType::Orthographic) {
        u = vec2(0.5f * (1.f - p1.x), 0.5f * (1.f - p1.y / inv_aspect_));
    } else {
        u = vec2(0.5f * (1.f - p1.x / tan_half_x_), 0.5f * (1.f - p1.y / tan_half_y_)) - principal_point_offset;
    }
    const vec2 film = u / inv_film_;
    return (film - pixel_offset_) / pixel_scale_;
}

float Camera::We(const Ray& ray, vec2* raster) const {
    const vec3 dc = glm::normalize(vec3(from_world_ * glm::vec4(ray.d, 0.f)));
    if (type == CameraType::Orthographic) {
        // Only the forward direction carries importance (a delta); its density over the film plane.
        if (glm::dot(ray.d, ortho_dir_) < 1.f - 1e-5f) return 0.f;
        const vec3 pc = vec3(from_world_ * glm::vec4(ray.o, 1.f));
        const vec2 r = raster_of_plane_point(vec2(pc));
        if (!on_image(r)) return 0.f;
        if (raster) *raster = r;
        return 1.f / importance_area_;
    }
    const float cos_theta = dc.z;
    if (!(cos_theta > 0.f)) return 0.f;
    vec2 p1;
    if (needs_lens_sample()) {
        // The focal-plane point the ray reaches, seen through the pinhole: where generate_ray
        // would have started this ray.
        const vec3 oc = vec3(from_world_ * glm::vec4(ray.o, 1.f));
        const vec3 pf = oc + dc * ((focus_distance - oc.z) / cos_theta);
        p1 = vec2(pf) / focus_distance;
    } else {
        p1 = vec2(dc) / cos_theta;
    }
    const vec2 r = raster_of_plane_point(p1);
    if (!on_image(r)) return 0.f;
    if (raster) *raster = r;
    const float c2 = cos_theta * cos_theta;
    return 1.f / (importance_area_ * lens_area() * c2 * c2);
}

void Camera::pdf_We(const Ray& ray, float& pdf_pos, float& pdf_dir) const {
    pdf_pos = pdf_dir = 0.f;
    if (!(We(ray) > 0.f)) return;
    if (type == CameraType::Orthographic) {
        pdf_pos = 1.f / importance_area_;
        pdf_dir = 1.f;
        return;
    }
    const float cos_theta = glm::normalize(vec3(from_world_ * glm::vec4(ray.d, 0.f))).z;
    pdf_pos = 1.f / lens_area();
    pdf_dir = 1.f / (importance_area_ * cos_theta * cos_theta * cos_theta);
}

bool Camera::sample_wi(vec3 ref, vec2 u, CameraWiSample& out) const {
    out.pdf = 0.f;
    out.Wi = 0.f;
    const vec3 rc = vec3(from_world_ * glm::vec4(ref, 1.f));  // camera space
    if (type == CameraType::Orthographic) {
        // The film-plane point straight before ref; the ray travels far - near from it (world units).
        const vec2 r = raster_of_plane_point(vec2(rc));
        if (!on_image(r)) return false;
        out.p = vec3(to_world * glm::vec4(rc.x, rc.y, near_clip, 1.f));
        const float t = glm::dot(ref - out.p, ortho_dir_);
        if (!(t > 0.f) || t > far_clip - near_clip) return false;
        out.wi = -ortho_dir_;
        out.dist = t;
        out.raster = r;
        out.Wi = 1.f / importance_area_;
        out.pdf = 1.f;
        return true;
    }
    if (!(rc.z >= near_clip && rc.z <= far_clip)) return false;
    vec3 lens_c(0.f);
    if (needs_lens_sample()) lens_c = vec3(aperture_radius * square_to_uniform_disk_concentric(u), 0.f);
    out.p = vec3(to_world * glm::vec4(lens_c, 1.f));
    const vec3 d = ref - out.p;
    out.dist = glm::length(d);
    if (!(out.dist > 0.f)) return false;
    out.wi = -d / out.dist;
    Ray ray;
    ray.o = out.p;
    ray.d = -out.wi;
    out.Wi = We(ray, &out.raster);
    if (!(out.Wi > 0.f)) return false;
    const float cos_theta = glm::normalize(vec3(from_world_ * glm::vec4(ray.d, 0.f))).z;
    out.pdf = out.dist * out.dist / (cos_theta * lens_area());
    return true;
}

}  // namespace candela
