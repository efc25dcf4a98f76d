#include "film/splat_filter.h"
#include <algorithm>

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
    const float r = filter_.radius();
    if (pos.y - 0.5f + r < float(row_begin) - 1.f || pos.y - 0.5f - r > float(row_end) + 1.f) return;  // clearly outside
    float wx[PixelFilter::kMaxReach], wy[PixelFilter::kMaxReach];
    int x0, y0;
    const int nx = filter_.weights_1d(pos.x, 0, width_ - 1, x0, wx);
    const int ny = filter_.weights_1d(pos.y, 0, height_ - 1, y0, wy);
    const int j0 = std::max(0, row_begin - y0), j1 = std::min(ny, row_end - y0);
    if (j0 >= j1) return;
    for (int i = 0; i < nx; ++i) wx[i] *= inv_wx_[size_t(x0 + i)];
    const dvec3 v(L);
    for (int j = j0; j < j1; ++j) {
        const float wyj = wy[j] * inv_wy_[size_t(y0 + j)];
        dvec3* row = sums + size_t(y0 + j) * size_t(width_) + size_t(x0);
        for (int i = 0; i < nx; ++i) row[i] += v * double(wx[i] * wyj);
    }
}

}  // namespace candela
