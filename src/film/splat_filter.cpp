#include "film/splat_filter.h"
#include <algorithm>
#include <cmath>

namespace candela {

namespace {
// 1 / (the integral over [0, n] of w(c - p) dp) for each pixel centre c = i + 0.5.
std::vector<float> inverse_norms(const PixelFilter& f, int n) {
    std::vector<float> out(size_t(std::max(0, n)));
    for (int i = 0; i < n; ++i) {
        const double c = double(i) + 0.5;
        out[size_t(i)] = float(1.0 / f.integral_discretized(c - double(n), c));
    }
    return out;
}
}  // namespace

SplatFilter::SplatFilter(const FilterDesc& desc, int width, int height)
    : filter_(desc), box_(desc.is_box()), width_(width), height_(height) {
    if (box_) return;
    inv_wx_ = inverse_norms(filter_, width);
    inv_wy_ = inverse_norms(filter_, height);
}

void SplatFilter::add(dvec3* sums, vec2 pos, vec3 L, int row_begin, int row_end) const {
    if (box_) {
        const int x = std::min(int(pos.x), width_ - 1), y = std::min(int(pos.y), height_ - 1);
        if (y >= row_begin && y < row_end) sums[size_t(y) * size_t(width_) + size_t(x)] += dvec3(L);
        return;
    }
    // Its rows (as weights_1d finds them) against the band, before any weight is evaluated.
    const float pfy = pos.y - 0.5f, r = filter_.radius();
    if (int(std::floor(pfy + r)) < row_begin || int(std::ceil(pfy - r)) >= row_end) return;
    float wx[PixelFilter::kMaxReach], wy[PixelFilter::kMaxReach];
    int x0, y0;
    const int ny = filter_.weights_1d(pos.y, 0, height_ - 1, y0, wy);
    const int j0 = std::max(0, row_begin - y0), j1 = std::min(ny, row_end - y0);
    if (j0 >= j1) return;  // none of its rows in this band
    const int nx = filter_.weights_1d(pos.x, 0, width_ - 1, x0, wx);
    for (int i = 0; i < nx; ++i) wx[i] *= inv_wx_[size_t(x0 + i)];
    const double lx = double(L.x), ly = double(L.y), lz = double(L.z);
    for (int j = j0; j < j1; ++j) {
        const float wyj = wy[j] * inv_wy_[size_t(y0 + j)];
        dvec3* row = sums + size_t(y0 + j) * size_t(width_) + size_t(x0);
        for (int i = 0; i < nx; ++i) {
            const double w = double(wx[i] * wyj);
            row[i].x += lx * w;
            row[i].y += ly * w;
            row[i].z += lz * w;
        }
    }
}

}  // namespace candela
