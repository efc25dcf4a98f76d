#pragma once
#include "core/ray.h"
#include "sampling/warp.h"

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

// A connection from a point of the scene to the camera (Camera::sample_wi): what light tracing
// and BDPT's t = 1 strategy need. See "Importance" in Camera for the measures.
struct CameraWiSample {
    vec3 p{0.f};        // the point on the camera: the pinhole, a point of the lens, or of the
                        // orthographic camera's film plane (world space)
    vec3 wi{0.f};       // unit direction from the reference point towards p
    float dist = 0.f;   // |p - ref|
    float Wi = 0.f;     // We(p, -wi): the importance the camera emits towards the reference point
    float pdf = 0.f;    // density of p, as seen from ref (see below); 0: no connection
    vec2 raster{0.f};   // where the ray p -> ref lands on the image, in image pixels [0,W)x[0,H)
};

// The sensors of Mitsuba 3 that candela renders: a closed set chosen by a type field, so that ray
// generation is one switch and no virtual call (src/sensors/perspective.cpp, thinlens.cpp and
// orthographic.cpp in Mitsuba 3.9 define every convention below).
enum class CameraType : uint8_t { Perspective, ThinLens, Orthographic };

// Camera space looks along +z with +y up and +x to the LEFT of the image (Mitsuba's lookat builds
// the basis (left, up, forward)); to_world maps camera space to world space (rigid for the
// perspective and thin lens cameras; the orthographic camera's scale is its extent).
//
// Film coordinates are in pixels of the FULL film (Mitsuba's hdrfilm width x height): (0,0) is the
// top-left corner, (W, H) the bottom-right. A crop window (crop_offset, crop_size) is the part of
// the film that is rendered: the image's pixel (0,0) is film pixel crop_offset, and every ray is
// the one the full film would have there. The field of view and the orthographic extent follow
// the full film's aspect W / H, as in Mitsuba.
struct Camera {
    CameraType type = CameraType::Perspective;
    mat4 to_world{1.f};
    // Perspective and thin lens: the field of view in degrees along fov_axis (a focal_length is
    // converted to a diagonal fov by the loader, as Mitsuba's parse_fov).
    float fov_deg = 39.3077f;
    FovAxis fov_axis = FovAxis::X;
    float near_clip = 1e-2f;
    float far_clip = 1e4f;
    // Perspective: the principal point's offset from the film's centre, in fractions of the full
    // film's width and height (Mitsuba's principal_point_offset_x/y; +x moves the image content
    // towards the left as in Mitsuba, whose sample space shifts by the offset).
    vec2 principal_point_offset{0.f};
    // Thin lens: the aperture's radius in camera space (0 renders exactly as the pinhole) and the
    // distance along +z of the plane in focus.
    float aperture_radius = 0.f;
    float focus_distance = 1e4f;
    // The full film and the crop window, in film pixels. film_size 0: the image is the whole film.
    ivec2 film_size{0};
    ivec2 crop_offset{0};
    ivec2 crop_size{0};

    // Prepares the per-ray constants for an image of the given size: the crop window (the whole
    // film without one) rendered at width x height pixels. At the crop's own size an image pixel
    // is exactly a film pixel; at another size (a preview, --width) the same window is scaled.
    // Call before generate_ray.
    void set_film_size(int width, int height);

    // True when a ray needs the 2D lens sample (a thin lens with an aperture). The renderer draws
    // it from the sampler right after the pixel jitter, and only then, so that a pinhole camera's
    // paths keep their dimensions.
    bool needs_lens_sample() const { return type == CameraType::ThinLens && aperture_radius > 0.f; }

    // The film pixel that image pixel `px` is: the sampler is seeded with it, so that a crop
    // renders the same samples as the full film in that window.
    ivec2 sampler_pixel(ivec2 px) const { return px + seed_offset_; }

    // Film position (full-film pixels) of image pixel `px` at `jitter` in [0,1)^2 within it.
    vec2 film_position(ivec2 px, vec2 jitter) const {
        // Scale 1 and an integer offset at the crop's own size: float(px) + offset is exact, so a
        // crop reproduces the full film's positions bit for bit.
        return vec2(px) * pixel_scale_ + pixel_offset_ + jitter * pixel_scale_;
    }

    // The primary ray through film position `film` (full-film pixels); `lens` in [0,1)^2 is used by
    // a thin lens with an aperture only (uniform over the aperture disk by the concentric map).
    // The direction is unit length; the ray starts on the near clip plane and ends on the far one,
    // as Mitsuba's sample_ray (for the orthographic camera: tmax = far - near, unscaled, as Mitsuba).
    // The ray's importance weight is 1 for every type: nothing is divided by a pdf here.
    Ray generate_ray(vec2 film, vec2 lens = vec2(0.5f)) const {
        vec2 u = film * inv_film_;
        Ray r;
        r.tmin = 0.f;
        if (type == CameraType::Orthographic) {
            vec3 p(1.f - 2.f * u.x, (1.f - 2.f * u.y) * inv_aspect_, near_clip);
            r.o = vec3(to_world * glm::vec4(p, 1.f));
            r.d = ortho_dir_;
            r.tmax = far_clip - near_clip;
            return r;
        }
        u += principal_point_offset;
        // The point on the plane z = 1 in camera space.
        vec3 p1((1.f - 2.f * u.x) * tan_half_x_, (1.f - 2.f * u.y) * tan_half_y_, 1.f);
        vec3 dc, o = origin_;
        if (needs_lens_sample()) {
            // Thin lens: from a point on the aperture disk (z = 0) through the point of the focal
            // plane that the pinhole ray would reach.
            vec2 a = aperture_radius * square_to_uniform_disk_concentric(lens);
            dc = glm::normalize(p1 * focus_distance - vec3(a, 0.f));
            o = vec3(to_world * glm::vec4(a, 0.f, 1.f));
        } else {
            dc = glm::normalize(p1);
        }
        r.d = glm::normalize(vec3(to_world * glm::vec4(dc, 0.f)));
        float inv_z = 1.f / dc.z;
        r.o = o + r.d * (near_clip * inv_z);
        r.tmax = (far_clip - near_clip) * inv_z;
        return r;
    }
    Ray generate_ray(ivec2 px, vec2 jitter, vec2 lens) const { return generate_ray(film_position(px, jitter), lens); }

    // ---- Importance (light tracing, BDPT; pbrt-v4's Camera::We / PDF_We / SampleWi) -----------
    // The camera is a sensor whose response to radiance L is the image: pixel value
    //   I_j = integral over camera points p and directions w of W_j(p, w) L(p, -w) |cos theta| dA(p) dw,
    // theta the angle between w and the view axis. W_j = N We h_j with h_j the indicator of pixel
    // j's area on the image and N the image's pixel count, so that a pixel is the mean radiance
    // over its area; We is normalised over the IMAGE (the crop window, at the film's current size:
    // set_film_size), i.e. integral of We(p, w) |cos theta| dA dw = 1, and zero for rays that leave
    // the image. Consequently a light tracer that traces M light paths estimates pixel j by
    // (N / M) x (sum of the splats that land in j) (film/film.h).
    //   perspective:  We(w) = 1 / (A cos^4 theta), A the image's area on the plane z = 1 in camera
    //                 space; the position is a delta (the pinhole, a "lens" of area 1).
    //   thin lens:    We(p, w) = 1 / (A pi r^2 cos^4 theta), p uniform on the aperture disk of
    //                 radius r; w leaves the image when the focal-plane point it reaches does.
    //   orthographic: We(p, w) = delta(w - forward) / A_perp, A_perp the image's area on the film
    //                 plane measured perpendicular to the view direction (world units).
    // Rays start on the near clip plane and end on the far one (generate_ray), so a point is seen
    // only with camera-space depth in [near_clip, far_clip].

    // We of a ray leaving the camera (unit direction; its origin on the lens for a thin lens). The
    // image position it reaches is written to `raster` (image pixels) when it is on the image.
    // Orthographic: the positional density 1 / A_perp (the direction is a delta: only the camera's
    // forward direction has importance; other directions return 0).
    float We(const Ray& ray, vec2* raster = nullptr) const;
    // pbrt-v4's PDF_We: the densities with which a camera ray sampled uniformly on the image (and
    // the lens) has this origin (area measure; 1 for the pinhole's delta position, 1 / (pi r^2) on
    // a lens, 1 / A_perp on the orthographic film plane) and this direction (solid angle: 1 /
    // (A cos^3 theta) for perspective and thin lens; 1 for the orthographic delta direction).
    // Both 0 when the ray leaves the image.
    void pdf_We(const Ray& ray, float& pdf_pos, float& pdf_dir) const;
    // Connects `ref` to the camera: p on the camera (the pinhole; a point of the lens drawn
    // uniformly from u; the orthographic film plane's point straight before ref), its direction,
    // and pdf = the density of p in SOLID ANGLE at ref: dist^2 / (|cos theta| lens_area) with
    // lens_area = pi r^2 (thin lens) or 1 (pinhole, a delta: pdf is then that conversion only);
    // orthographic: 1 (a delta in both). The light tracer's estimate of the connection is
    //   beta f(ref, wi) |cos| Wi / pdf  (times the visibility of p from ref),
    // which is We cos theta / dist^2 for the pinhole and 1 / A_perp for the orthographic camera.
    // Returns false (and pdf 0) when ref is not seen: behind the camera, out of the clip range,
    // or projecting outside the image.
    bool sample_wi(vec3 ref, vec2 u, CameraWiSample& out) const;
    // The image's area behind We's normalisation (A, or A_perp for the orthographic camera).
    float importance_area() const { return importance_area_; }
    float lens_area() const { return needs_lens_sample() ? kPi * aperture_radius * aperture_radius : 1.f; }

    // The camera's position (the pinhole, the lens centre, or the orthographic camera's to_world
    // origin).
    vec3 origin() const { return origin_; }
    // The view direction in world space (unit).
    vec3 forward() const { return glm::normalize(vec3(to_world[2])); }

private:
    float tan_half_x_ = 0.35f, tan_half_y_ = 0.35f;
    vec2 inv_film_{1.f};
    float inv_aspect_ = 1.f;
    vec2 pixel_scale_{1.f}, pixel_offset_{0.f};
    ivec2 seed_offset_{0};
    vec3 origin_{0.f};
    vec3 ortho_dir_{0.f, 0.f, 1.f};
    // Importance: world -> camera space, the image size and its area (see We).
    mat4 from_world_{1.f};
    ivec2 image_size_{1};
    float importance_area_ = 1.f;
    // Image pixels of a camera-space direction through the pinhole plane z = 1 (perspective and
    // thin lens: p1 = the point on z = 1) or of a camera-space point (orthographic).
    vec2 raster_of_plane_point(vec2 p1) const;
    bool on_image(vec2 raster) const {
        return raster.x >= 0.f && raster.y >= 0.f && raster.x < float(image_size_.x) && raster.y < float(image_size_.y);
    }
};

// Mitsuba's parse_fov: the horizontal field of view (degrees) of `fov_deg` along `axis` on a
// film of aspect width / height, computed in double as Mitsuba does.
double horizontal_fov(double fov_deg, FovAxis axis, double aspect);

// Mitsuba's focal_length: a 35 mm-equivalent focal length (mm) as a diagonal fov in degrees.
double focal_length_to_fov(double focal_mm);

}  // namespace candela
