#pragma once
#include <atomic>
#include <string>
#include <vector>
#include "core/math.h"

namespace candela {

// Accumulates radiance samples. Sums are kept in double so that a million samples per pixel still
// average to float precision. Each pixel is written by one thread per pass (tiles are disjoint), so
// add_sample needs no atomics; splats (light paths of bidirectional methods, which land anywhere)
// go to a separate buffer that is only allocated when first used.
//
// Non-finite samples never enter the sums: they are counted (nonfinite_count) and recorded as a
// zero-radiance sample, so that the pixel's sample count stays the number of samples taken.
class Film {
public:
    Film() = default;
    Film(int width, int height) { resize(width, height); }

    void resize(int width, int height);
    void clear();

    int width() const { return width_; }
    int height() const { return height_; }

    void add_sample(ivec2 px, vec3 L) {
        size_t i = size_t(px.y) * size_t(width_) + size_t(px.x);
        if (!all_finite(L)) {
            nonfinite_.fetch_add(1, std::memory_order_relaxed);
            L = vec3(0.f);
        }
        sum_[i] += dvec3(L);
        count_[i] += 1;
    }
    // Alpha (hdrfilm pixel_format rgba): per pixel, the fraction of its samples whose camera ray
    // hit a surface, as Mitsuba. Off (and not allocated) until enable_alpha; kept over resize.
    void enable_alpha();
    bool has_alpha() const { return alpha_enabled_; }
    void add_coverage(ivec2 px, bool hit) { alpha_[size_t(px.y) * size_t(width_) + size_t(px.x)] += hit ? 1.0 : 0.0; }
    float alpha(int x, int y) const;
    std::vector<float> resolve_alpha() const;  // row-major from the top-left, 1 float per pixel
    const std::vector<double>& alpha_sums() const { return alpha_; }
    void restore_alpha(std::vector<double> sums);

    // Splats are scaled by 1 / (passes) when resolved: splat_scale is set by the integrator.
    void add_splat(vec2 film_pos, vec3 L);

    // Mean radiance of a pixel (the box-filtered estimate), plus splats.
    vec3 pixel(int x, int y) const;
    uint32_t sample_count(int x, int y) const { return count_[size_t(y) * size_t(width_) + size_t(x)]; }
    dvec3 pixel_sum(int x, int y) const { return sum_[size_t(y) * size_t(width_) + size_t(x)]; }
    // RGB float image, row-major from the top-left, 3 floats per pixel.
    std::vector<float> resolve() const;
    void resolve_into(std::vector<float>& rgb) const;

    uint64_t nonfinite_count() const { return nonfinite_.load(std::memory_order_relaxed); }
    // Total number of samples over all pixels.
    uint64_t total_samples() const;

    void set_splat_scale(double s) { splat_scale_ = s; }

    // Raw state for checkpoints.
    const std::vector<dvec3>& sums() const { return sum_; }
    const std::vector<uint32_t>& counts() const { return count_; }
    void restore(std::vector<dvec3> sums, std::vector<uint32_t> counts, uint64_t nonfinite);

private:
    int width_ = 0, height_ = 0;
    std::vector<dvec3> sum_;
    std::vector<uint32_t> count_;
    std::vector<dvec3> splat_;
    bool alpha_enabled_ = false;
    std::vector<double> alpha_;  // sums of coverage (0 or 1 per sample)
    double splat_scale_ = 1.0;
    std::atomic<uint64_t> nonfinite_{0};
};

}  // namespace candela

namespace candela {
// Throws Error when a film of this size cannot exist: a non-positive size, or more memory than
// half of this machine's RAM. Called before anything is allocated. `where` names the source.
void check_film_size(int width, int height, const std::string& where);
}  // namespace candela
