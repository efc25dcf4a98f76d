#pragma once
// Splats through the film's reconstruction filter: the contributions of light paths (the light
// tracer, BDPT's t = 1 strategies, MLT's states), which land anywhere on the film.
//
// A camera sample at p adds w(c - p) L and w(c - p) to the sum and the weight of every pixel c
// within the filter's radius (film/filter.h), and the pixel is sum(w L) / sum(w). A splat carries
// no weight of its own: it adds w(c - p) L / W(c) to the pixel's splat sum, where
//     W(c) = integral over the image of w(c - p) dp,
// the same separable discretised weights w as camera samples (PixelFilter::weights_1d). Why: each
// light path is one sample of the whole image with a uniform density in p (the film's splat
// normalisation, film/film.h), so the splat image's expectation at c is
//     integral over the image of w(c - p) I(p) dp / W(c),
// exactly the limit of the camera samples' sum(w L) / sum(w) under the same filter: splats and
// camera samples estimate one filtered image, and a render that mixes them (BDPT) is that image.
// Away from the borders W(c) is the filter's integral, pbrt-v4's normalisation (RGBFilm::AddSplat
// adds w L, GetPixelRGB divides by the filter's integral); Mitsuba 3's particle tracer instead
// divides each splat's weights by their sum over its footprint (ImageBlock::put, normalize), the
// same up to the filter's ripple (the two agree for the tent, Mitchell and Catmull-Rom filters,
// whose weights sum to one). Both lose at the border the share of the filter that falls outside
// the image, which W(c) restores (a border pixel is as bright as the path tracer's).
// The box filter (radius 0.5): W = 1, one pixel, the value added as it is.
#include <vector>
#include "core/math.h"
#include "film/filter.h"

namespace candela {

class SplatFilter {
public:
    SplatFilter(const FilterDesc& desc, int width, int height);

    bool is_box() const { return box_; }
    // Adds the splat L at film position pos (pixels) to `sums`, the width x height splat sums
    // (row-major), in the rows [row_begin, row_end) only: threads that own disjoint bands of rows
    // can add the same splats in the same order, and each pixel gets the same sum as from one
    // thread (the weights do not depend on the band). pos must lie in the image (SplatTile::add
    // drops the others).
    void add(dvec3* sums, vec2 pos, vec3 L, int row_begin, int row_end) const;
    // W(c) above, separable: W = norm_x(x) norm_y(y).
    double norm_x(int x) const { return 1.0 / double(inv_wx_[size_t(x)]); }
    double norm_y(int y) const { return 1.0 / double(inv_wy_[size_t(y)]); }

private:
    PixelFilter filter_;
    bool box_;
    int width_, height_;
    std::vector<float> inv_wx_, inv_wy_;  // 1 / W per column and row
};

}  // namespace candela
