#include "film/filter.h"
#include <algorithm>
#include <cmath>
#include "core/math.h"

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

FilterDesc mitchell_filter(float b, float c) {
    FilterDesc d;
    d.type = FilterType::Mitchell;
    d.radius = 2.f;
    d.b = b;
    d.c = c;
    return d;
}

FilterDesc catmullrom_filter() {
    FilterDesc d = mitchell_filter(0.f, 0.5f);
    d.type = FilterType::CatmullRom;
    return d;
}

FilterDesc lanczos_filter(int lobes) {
    FilterDesc d;
    d.type = FilterType::Lanczos;
    d.radius = float(lobes);
    return d;
}

const char* filter_name(FilterType t) {
    switch (t) {
        case FilterType::Box: return "box";
        case FilterType::Tent: return "tent";
        case FilterType::Gaussian: return "gaussian";
        case FilterType::Mitchell: return "mitchell";
        case FilterType::CatmullRom: return "catmullrom";
        case FilterType::Lanczos: return "lanczos";
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

double PixelFilter::cumulative(double t) const {
    const double a = std::abs(t), bin = double(radius_) / double(kResolution);
    double sum = 0.0;
    for (int i = 0; i < kResolution && a > double(i) * bin; ++i)
        sum += double(values_[i]) * (std::min(a, double(i + 1) * bin) - double(i) * bin);
    return t < 0.0 ? -sum : sum;
}

float PixelFilter::eval(float x) const {
    switch (desc_.type) {
        case FilterType::Box: return (x >= -0.5f && x < 0.5f) ? 1.f : 0.f;
        case FilterType::Tent: return std::max(0.f, 1.f - std::abs(x * inv_radius_));
        case FilterType::Gaussian: return std::max(0.f, std::exp(alpha_ * x * x) - bias_);
        case FilterType::Mitchell:
        case FilterType::CatmullRom: {
            // Mitchell and Netravali's cubic, evaluated as Mitsuba writes it.
            const float a = std::abs(x), a2 = a * a, a3 = a2 * a, B = desc_.b, C = desc_.c;
            if (a >= 2.f) return 0.f;
            const float r = a < 1.f ? (12.f - 9.f * B - 6.f * C) * a3 + (-18.f + 12.f * B + 6.f * C) * a2 + (6.f - 2.f * B)
                                    : (-B - 6.f * C) * a3 + (6.f * B + 30.f * C) * a2 + (-12.f * B - 48.f * C) * a +
                                          (8.f * B + 24.f * C);
            return r * (1.f / 6.f);
        }
        case FilterType::Lanczos: {
            const float a = std::abs(x);
            if (a < 1.1920929e-7f) return 1.f;  // Mitsuba's dr::Epsilon
            if (a > radius_) return 0.f;
            const float x1 = kPi * a, x2 = x1 / radius_;
            return std::sin(x1) * std::sin(x2) / (x1 * x2);
        }
    }
    return 0.f;
}

}  // namespace candela
