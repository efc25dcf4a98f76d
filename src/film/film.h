#pragma once
#include <atomic>
#include <string>
#include <vector>
#include "core/math.h"
#include "film/splat_filter.h"

namespace candela {

// Accumulates radiance samples. Sums are kept in double so that a million samples per pixel still
// average to float precision. Each pixel is written by one thread per pass (tiles are disjoint), so
// add_sample needs no atomics; splats (light paths of bidirectional methods, which land anywhere)
// go to a separate buffer that is only allocated when first used.
//
// Non-finite samples never enter the sums: they are counted (nonfinite_count) and recorded as a
// zero-radiance sample, so that the pixel's sample count stays the number of samples taken.
//
// Two layouts (set_layout). Unweighted (the box filter of radius 0.5, the default): a pixel is the
// plain mean of its own samples, sum / count. Weighted (tent, gaussian: film/filter.h): samples
// splat into neighbouring pixels with filter weights, so each pixel also keeps the sum of the
// weights it received and is sum(w L) / sum(w); count stays the number of samples taken IN the
// pixel. Splatting crosses tiles, so a weighted pass accumulates each tile into a FilmTile (the
// tile plus a margin) and merges the tiles in a fixed order (merge): the sums then do not depend on
// the thread schedule. Optional AOV channels (aov_channels > 0) are filtered the same way.
struct FilmTile;

class Film {
public:
    Film() = default;
    Film(int width, int height) { resize(width, height); }

    void resize(int width, int height);  // keeps the layout
    void clear();
    // Weighted or not, and how many AOV channels per pixel. Clears the film.
    void set_layout(bool weighted, int aov_channels);
    bool weighted() const { return weighted_; }
    int aov_channels() const { return aov_channels_; }

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
    // Unweighted layout: the AOV values (aov_channels floats) of a sample added to pixel px.
    void add_aov(ivec2 px, const float* v) {
        double* a = &aov_[(size_t(px.y) * size_t(width_) + size_t(px.x)) * size_t(aov_channels_)];
        for (int k = 0; k < aov_channels_; ++k) a[k] += double(v[k]);
    }
    // Weighted layout: counts a sample taken in pixel px (the tile that owns px calls it, so no
    // two threads touch one pixel) and the non-finite ones.
    void count_sample(ivec2 px) { count_[size_t(px.y) * size_t(width_) + size_t(px.x)] += 1; }
    void count_nonfinite() { nonfinite_.fetch_add(1, std::memory_order_relaxed); }
    // Weighted layout: adds a tile's sums into the film. Call from one thread, tiles in a fixed order.
    void merge(const FilmTile& tile);
    // Adds another film of the same size and layout, pixel by pixel: sums, weights, counts, AOVs,
    // alpha, splats and the non-finite count. A weighted pass merges each sample index's tiles into
    // a zeroed layer and adds the layer with this, so the film is always the sum, in sample order,
    // of per-sample-index layers: MPI ranks ship such layers and rank 0 adds them in the same order
    // (docs/distributed.md), which makes its image the single-process one bit for bit.
    void add(const Film& other);
    // The same from raw arrays of a film of this size and layout (an MPI layer message read in
    // place): `weights` when weighted, `aov` when aov_channels > 0, `alpha` when alpha is on;
    // `splats` may be null (none); `splat_paths` light paths are counted either way.
    void add(const dvec3* sums, const uint32_t* counts, const double* weights, const double* aov, const double* alpha,
             const dvec3* splats, uint64_t splat_paths, uint64_t nonfinite);
    // Alpha (hdrfilm pixel_format rgba): per pixel, the fraction of its samples whose camera ray
    // hit a surface, as Mitsuba. Off (and not allocated) until enable_alpha; kept over resize.
    void enable_alpha();
    bool has_alpha() const { return alpha_enabled_; }
    void add_coverage(ivec2 px, bool hit) { alpha_[size_t(px.y) * size_t(width_) + size_t(px.x)] += hit ? 1.0 : 0.0; }
    float alpha(int x, int y) const;
    std::vector<float> resolve_alpha() const;  // row-major from the top-left, 1 float per pixel
    const std::vector<double>& alpha_sums() const { return alpha_; }
    void restore_alpha(std::vector<double> sums);

    // ---- Splats: contributions of light paths (light tracing, BDPT's t = 1, MLT), which land anywhere.
    // They go through the film's filter (film/splat_filter.h) into a buffer of their own
    // (allocated when first used), beside the count of light paths traced (`splat_paths`), and a
    // pixel resolves to
    //     sum(samples) / count  +  splat_sum x N / splat_paths,
    // N the number of pixels: each light path is a sample of the whole image (the camera's We is
    // normalised over the image, scene/camera.h), so with one light path per pixel sample
    // (splat_paths = spp x N) the splats are divided by the samples per pixel.
    // Deterministic at any thread count: threads never touch the film's splats; each tile fills a
    // SplatTile with (position, value) in its own sample order, and add_splats spreads the tiles'
    // splats over their pixels in tile order, then splat order: with n_threads > 1 and a filter
    // wider than the box, threads share out bands of rows, each adding every splat's share of its
    // rows, so each pixel's sum takes its terms in that order whatever the threads. Call from one
    // thread.
    void add_splats(const std::vector<struct SplatTile>& tiles, const SplatFilter& filter, int n_threads = 1);
    bool has_splats() const { return !splat_.empty() || splat_paths_ > 0; }
    uint64_t splat_paths() const { return splat_paths_; }
    const std::vector<dvec3>& splat_sums() const { return splat_; }  // empty when none
    // The splats' share of pixel i (row-major index), normalised as above.
    dvec3 splat_value(size_t i) const {
        return splat_.empty() || splat_paths_ == 0 ? dvec3(0.0) : splat_[i] * splat_norm();
    }
    void restore_splats(std::vector<dvec3> sums, uint64_t paths);

    // Mean radiance of a pixel (sum / count, or sum(w L) / sum(w) when weighted), plus splats.
    vec3 pixel(int x, int y) const;
    // AOV channel k of a pixel, normalised like pixel().
    float aov(int x, int y, int k) const;
    // The AOV channels as float images, channel-major: aov_channels x (width x height).
    std::vector<std::vector<float>> resolve_aovs() const;
    uint32_t sample_count(int x, int y) const { return count_[size_t(y) * size_t(width_) + size_t(x)]; }
    dvec3 pixel_sum(int x, int y) const { return sum_[size_t(y) * size_t(width_) + size_t(x)]; }
    // RGB float image, row-major from the top-left, 3 floats per pixel.
    std::vector<float> resolve() const;
    void resolve_into(std::vector<float>& rgb) const;

    // Adaptive sampling (film/adaptive.h, docs/adaptive.md), unweighted layout only. Two halves:
    // samples of even sample index go to the decision half, which keeps only the sum and the sum
    // of squares of their luminance and is never averaged into the image; samples of odd index go
    // to the image (sum_, count_, as add_sample) and also keep their luminance moments (for the
    // naive-rule control of the tests). A pixel whose decision half says it has converged is
    // marked inactive and the tile loop skips it. Its stopping time depends on the even samples
    // only, which are independent of the odd ones, so the image stays unbiased.
    void enable_adaptive();
    bool adaptive() const { return adaptive_; }
    bool active(int x, int y) const { return active_[size_t(y) * size_t(width_) + size_t(x)] != 0; }
    void set_active(int x, int y, bool a) { active_[size_t(y) * size_t(width_) + size_t(x)] = a ? 1 : 0; }
    // A sample of pixel px with sample index `index` (its parity picks the half).
    void add_adaptive_sample(ivec2 px, vec3 L, uint32_t index) {
        size_t i = size_t(px.y) * size_t(width_) + size_t(px.x);
        if (!all_finite(L)) {
            nonfinite_.fetch_add(1, std::memory_order_relaxed);
            L = vec3(0.f);
        }
        const unsigned h = index & 1u;
        if (h) {
            sum_[i] += dvec3(L);
            count_[i] += 1;
        } else {
            decision_count_[i] += 1;
        }
        const double y = double(luminance(L));
        lum_[2 * i + h] += y;
        lum2_[2 * i + h] += y * y;
    }
    // Luminance moments of half h (0: decision, 1: image) of a pixel: count, sum, sum of squares.
    uint32_t half_count(int x, int y, int h) const {
        size_t i = size_t(y) * size_t(width_) + size_t(x);
        return h ? count_[i] : decision_count_[i];
    }
    double half_lum_sum(int x, int y, int h) const { return lum_[2 * (size_t(y) * size_t(width_) + size_t(x)) + size_t(h)]; }
    double half_lum_sq(int x, int y, int h) const { return lum2_[2 * (size_t(y) * size_t(width_) + size_t(x)) + size_t(h)]; }
    // Samples taken in the pixel, both halves (sample_count is the image's share when adaptive).
    uint32_t samples_taken(int x, int y) const {
        size_t i = size_t(y) * size_t(width_) + size_t(x);
        return count_[i] + (adaptive_ ? decision_count_[i] : 0u);
    }

    uint64_t nonfinite_count() const { return nonfinite_.load(std::memory_order_relaxed); }
    // Total number of samples over all pixels (both halves when adaptive).
    uint64_t total_samples() const;

    // Raw state for checkpoints.
    const std::vector<dvec3>& sums() const { return sum_; }
    const std::vector<uint32_t>& counts() const { return count_; }
    const std::vector<double>& weights() const { return weight_; }  // weighted layout only
    const std::vector<double>& aov_sums() const { return aov_; }   // aov_channels per pixel
    void restore_aov(std::vector<double> sums) { aov_ = std::move(sums); }
    // `weights` must be empty for an unweighted film and one per pixel for a weighted one.
    void restore(std::vector<dvec3> sums, std::vector<uint32_t> counts, uint64_t nonfinite,
                 std::vector<double> weights = {});

private:
    int width_ = 0, height_ = 0;
    bool weighted_ = false;
    int aov_channels_ = 0;
    std::vector<double> weight_;  // weighted layout: sum of filter weights per pixel
    std::vector<double> aov_;     // aov_channels_ per pixel (weighted sums when weighted_)
    std::vector<dvec3> sum_;
    std::vector<uint32_t> count_;
    std::vector<dvec3> splat_;
    bool alpha_enabled_ = false;
    std::vector<double> alpha_;  // sums of coverage (0 or 1 per sample)
    uint64_t splat_paths_ = 0;
    double splat_norm() const { return double(sum_.size()) / double(splat_paths_); }
    std::atomic<uint64_t> nonfinite_{0};
    bool adaptive_ = false;
    std::vector<uint32_t> decision_count_;
    std::vector<double> lum_, lum2_;  // 2 per pixel: the decision half, the image half
    std::vector<uint8_t> active_;
};

// A tile's splats in the order its light paths made them (film position, value), and how many
// light paths it traced. Reused across tiles: clear() keeps the capacity.
struct SplatTile {
    std::vector<vec2> pos;
    std::vector<vec3> value;
    uint64_t paths = 0;
    uint64_t nonfinite = 0;
    void clear() {
        pos.clear();
        value.clear();
        paths = 0;
        nonfinite = 0;
    }
    size_t size() const { return pos.size(); }
    // Image position (pixels); outside the image or non-finite: dropped.
    void add(int width, int height, vec2 p, vec3 L) {
        if (!(p.x >= 0.f && p.y >= 0.f && p.x < float(width) && p.y < float(height))) return;
        if (!all_finite(L)) {
            ++nonfinite;
            return;
        }
        pos.push_back(p);
        value.push_back(L);
    }
};

// A tile's share of a weighted pass: the tile's pixels plus `margin` on each side (clipped to the
// film), with the weighted sums its samples made.
struct FilmTile {
    int x0 = 0, y0 = 0, width = 0, height = 0;  // the region covered, film pixels
    int aov_channels = 0;
    // Per pixel, sum(w L) in xyz and sum(w) in w: one place for the two sums each splat adds to.
    std::vector<dvec4> sum_weight;
    std::vector<double> aov;
    std::vector<double> alpha;  // when the film has alpha: coverage x weight

    // Covers the film pixels [x0 - margin, x1 + margin) x [y0 - margin, y1 + margin) clipped to the
    // film, zeroed (reusing the buffers).
    void reset(const Film& film, int x0, int y0, int x1, int y1, int margin);
};

}  // namespace candela

namespace candela {
// Throws Error when a film of this size cannot exist: a non-positive size, or more memory than
// half of this machine's RAM. Called before anything is allocated. `where` names the source.
void check_film_size(int width, int height, const std::string& where);
}  // namespace candela
