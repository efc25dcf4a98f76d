#pragma once
// Pixel reconstruction filters, as Mitsuba 3 defines and applies them (src/rfilters/*.cpp,
// src/core/rfilter.cpp, src/render/imageblock.cpp in its scalar variants):
//   * a sample taken at film position p (pixels; pixel i covers [i, i + 1), its centre is i + 0.5)
//     adds w(x) w(y) L to every pixel whose centre lies within the filter's radius of p, where
//     x, y are the offsets from p to the pixel's centre;
//   * the pixel is then sum(w L) / sum(w) over the samples that reached it.
// The sample positions stay uniform in their own pixel (no filter importance sampling), so a
// pixel's value is a ratio estimator, consistent but not unbiased at low sample counts.
// Weights are Mitsuba's discretised ones: the 1D filter tabulated at 31 points over [0, radius),
// looked up by truncation (ReconstructionFilter::eval_discretized), evaluated in float.
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace candela {

enum class FilterType { Box, Tent, Gaussian, Mitchell, CatmullRom, Lanczos };

// What the scene file asks for. Box has radius 0.5 (Mitsuba's box takes no parameters); tent's
// radius defaults to 1; gaussian's stddev to 0.5, with radius 4 stddev. Mitchell-Netravali (B, C
// default 1/3) and Catmull-Rom (B = 0, C = 1/2) are the cubic family of radius 2; Lanczos is
// sinc(x) sinc(x / lobes) over |x| <= lobes (default 3). The last three have negative lobes:
// a pixel's value stays sum(w L) / sum(w), as in Mitsuba.
struct FilterDesc {
    FilterType type = FilterType::Box;
    float radius = 0.5f;  // tent: the radius; gaussian: derived (4 stddev); box: 0.5; cubics: 2;
                          // lanczos: the number of lobes
    float stddev = 0.5f;  // gaussian only
    float b = 1.f / 3.f, c = 1.f / 3.f;  // mitchell (catmullrom: 0 and 0.5)
    bool is_box() const { return type == FilterType::Box; }
};
inline bool operator==(const FilterDesc& a, const FilterDesc& b) {
    return a.type == b.type && a.radius == b.radius && a.stddev == b.stddev && a.b == b.b && a.c == b.c;
}
inline bool operator!=(const FilterDesc& a, const FilterDesc& b) { return !(a == b); }

FilterDesc box_filter();
FilterDesc tent_filter(float radius = 1.f);
FilterDesc gaussian_filter(float stddev = 0.5f);
FilterDesc mitchell_filter(float b = 1.f / 3.f, float c = 1.f / 3.f);
FilterDesc catmullrom_filter();
FilterDesc lanczos_filter(int lobes = 3);
const char* filter_name(FilterType t);

// The filter ready for splatting.
class PixelFilter {
public:
    static constexpr int kResolution = 31;  // MI_FILTER_RESOLUTION

    explicit PixelFilter(const FilterDesc& d);

    float radius() const { return radius_; }
    // Pixels a sample may reach beyond its own pixel on each side.
    int reach() const { return reach_; }
    // The continuous filter (Mitsuba's eval()).
    float eval(float x) const;
    // The tabulated filter the film uses (Mitsuba's eval_discretized in scalar variants).
    float eval_discretized(float x) const {
        float a = x < 0.f ? -x : x;
        uint32_t i = uint32_t(a * scale_);
        return values_[i < uint32_t(kResolution) ? i : uint32_t(kResolution)];
    }
    // The pixels along one axis that a sample at film coordinate p reaches: those whose centres
    // (i + 0.5) lie within the radius of p, clipped to [lo, hi]. Writes their discretised weights,
    // the first pixel's weight at w[0], to w (room for kMaxReach), sets `first` and returns their
    // number (0: none). Mitsuba's ImageBlock::put; camera samples and splats both use it.
    static constexpr int kMaxReach = 2 * 64 + 2;  // the XML reader caps radii at 64 pixels
    int weights_1d(float p, int lo, int hi, int& first, float* w) const {
        const float pf = p - 0.5f;  // pixel centres are at integers + 0.5
        first = std::max(int(std::ceil(pf - radius_)), lo);
        const int last = std::min(int(std::floor(pf + radius_)), hi);
        if (first > last) return 0;
        const int n = std::min(last - first + 1, kMaxReach);
        float r = float(first) - pf;
        for (int i = 0; i < n; ++i, r += 1.f) w[i] = eval_discretized(r);
        return n;
    }
    // The integral of the discretised filter over [a, b] (pixels), exact for its steps.
    double integral_discretized(double a, double b) const { return cumulative(b) - cumulative(a); }

private:
    double cumulative(double t) const;  // the integral over [0, t], odd in t
    FilterDesc desc_;
    float radius_ = 0.5f, scale_ = 0.f;
    float inv_radius_ = 2.f;           // tent: 1 - |x inv_radius|
    float alpha_ = 0.f, bias_ = 0.f;  // gaussian: exp(alpha x^2) - bias
    int reach_ = 0;
    float values_[kResolution + 1] = {};
};

}  // namespace candela
