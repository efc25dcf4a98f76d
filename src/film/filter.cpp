#include "film/filter.h"
#include <algorithm>
#include <cmath>

namespace candela {

FilterDesc box_filter() { return FilterDesc{}; }

FilterDesc tent_filter(float radius) {
    FilterDesc d;
    d.type = FilterType::Tent;
    d.radius = radius;
    return d;
}

FilterDesc gaussian_filter(float stddev) {
    FilterDesc d;
    d.type = FilterType::Gaussian;
    d.stddev = stddev;
    d.radius = 4.f * stddev;  // Mitsuba cuts the gaussian off after 4 standard deviations
    return d;
}

const char* filter_name(FilterType t) {
    switch (t) {
        case FilterType::Box: return "box";
        case FilterType::Tent: return "tent";
        case FilterType::Gaussian: return "gaussian";
    }
    return "?";
}

PixelFilter::PixelFilter(const FilterDesc& d) : desc_(d) {
    radius_ = d.type == FilterType::Box ? 0.5f : d.radius;
    inv_radius_ = 1.f / radius_;
    if (d.type == FilterType::Gaussian) {
        alpha_ = -1.f / (2.f * d.stddev * d.stddev);
        bias_ = std::exp(alpha_ * radius_ * radius_);
    }
    for (int i = 0; i < kResolution; ++i) values_[i] = eval((radius_ * float(i)) / float(kResolution));
    values_[kResolution] = 0.f;
    scale_ = float(kResolution) / radius_;
    // A sample in pixel i at offset f in [0, 1) reaches pixel centres up to radius away:
    // j + 0.5 <= i + f + radius, so j - i <= floor(radius + 0.5) (and symmetrically).
    reach_ = int(std::floor(radius_ + 0.5f));
}

float PixelFilter::eval(float x) const {
    switch (desc_.type) {
        case FilterType::Box: return (x >= -0.5f && x < 0.5f) ? 1.f : 0.f;
        case FilterType::Tent: return std::max(0.f, 1.f - std::abs(x * inv_radius_));
        case FilterType::Gaussian: return std::max(0.f, std::exp(alpha_ * x * x) - bias_);
    }
    return 0.f;
}

}  // namespace candela
