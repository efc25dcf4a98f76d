#pragma once
// Mitsuba 3's `envmap` (src/emitters/envmap.cpp): an infinitely distant emitter whose radiance is a
// latitude-longitude image. This file holds the image and its sampling distribution in the map's
// own frame; the emitter (scale, to_world) is EnvmapLight in light/emitter.h.
//
// Orientation (Mitsuba's, y up): a local direction d and its image coordinates uv in [0,1]^2
// (u = 0 at the image's left, v = 0 at its top) are related by
//     theta = v pi, phi = u 2 pi,   d = (sin phi sin theta, cos theta, -cos phi sin theta)
// so the top row is +y, the bottom row -y, the image's left edge looks along -z and its middle
// column (u = 1/2) along +z, with u = 1/4 towards +x.
//
// Radiance (Mitsuba's eval_spectrum): the W x H pixels are extended by a copy of column 0 as
// column W (the periodic seam) and interpolated bilinearly on a grid whose column x sits at
// u = (x + 1/2) / W and whose row y sits at v = y / (H - 1): the first and last rows lie on the
// poles. The value is the plain bilinear blend of the four pixels around uv.
//
// Sampling: piecewise constant over the W x (H - 1) cells of that grid, cell weight = the mean
// luminance of its four corner pixels times the mean of sin(theta) over its rows, so that the
// density over directions follows the radiance. A cell whose corners are all black has weight 0,
// and the bilinear radiance is 0 inside it: no radiance is left unsampled. Mitsuba samples a
// bilinear density instead (Hierarchical2D); both are unbiased, only the noise differs slightly.
// With p_uv the density w.r.t. area in uv (the sample's u shifted back by half a texel), the
// density w.r.t. solid angle is p_uv / (2 pi^2 sin theta) (the Jacobian of the map above).
#include <memory>
#include <string>
#include <vector>
#include "core/math.h"
#include "sampling/distribution.h"
#include "texture/texture.h"

namespace candela {

class EnvironmentMap {
public:
    // From linear texels (1 or 3 channels), at least 2 x 3 pixels as Mitsuba requires.
    explicit EnvironmentMap(const TexelGrid& texels, std::string name = "");
    // Loads `path` (EXR, PFM, HDR; PNG/JPEG/BMP/TGA decoded from sRGB, as Mitsuba's Bitmap does).
    // Throws Error naming the file when it is missing, unreadable or too small.
    static std::shared_ptr<const EnvironmentMap> load(const std::string& path);

    int width() const { return width_; }
    int height() const { return height_; }
    const std::string& name() const { return name_; }

    // The bilinear radiance at uv (u wraps around; v in [0, 1]).
    vec3 eval(vec2 uv) const;
    // Samples uv with density pdf_uv w.r.t. area in uv (uv.x may exceed 1 by half a texel; the
    // map is periodic in u). False when the map is black.
    bool sample(vec2 u, vec2& uv, float& pdf_uv) const;
    // The density of sample() at uv.
    float pdf(vec2 uv) const;

    // The integral of eval over the sphere, int L(w) dw, by the exact integral of the bilinear
    // interpolation against sin(theta) dtheta dphi (used by the tests).
    vec3 integral() const;

    size_t memory_bytes() const { return data_.capacity() * sizeof(vec3) + dist_.memory_bytes(); }

    // The lat-long map in the local frame (above). direction_to_uv returns u in [-1/2, 1/2].
    static vec3 uv_to_direction(vec2 uv, float& sin_theta);
    static vec2 direction_to_uv(vec3 d);

private:
    int width_ = 0, height_ = 0;  // the image's; data_ has width_ + 1 columns
    std::vector<vec3> data_;      // (width_ + 1) x height_, row-major from the top
    Distribution2D dist_;         // width_ x (height_ - 1) cells over (u - half texel, v)
    std::string name_;

    float half_texel() const { return 0.5f / float(width_); }
    const vec3& at(int x, int y) const { return data_[size_t(y) * size_t(width_ + 1) + size_t(x)]; }
};

}  // namespace candela
