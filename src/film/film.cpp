#include "film/film.h"
#include <algorithm>

namespace candela {

void Film::resize(int width, int height) {
    width_ = width;
    height_ = height;
    const size_t n = size_t(width) * size_t(height);
    sum_.assign(n, dvec3(0.0));
    count_.assign(n, 0u);
    if (weighted_) weight_.assign(n, 0.0);
    else weight_.clear();
    aov_.assign(n * size_t(aov_channels_), 0.0);
    splat_.clear();
    splat_paths_ = 0;
    if (alpha_enabled_) alpha_.assign(sum_.size(), 0.0);
    if (adaptive_) enable_adaptive();
    nonfinite_ = 0;
}

void Film::enable_adaptive() {
    adaptive_ = true;
    const size_t n = sum_.size();
    decision_count_.assign(n, 0u);
    lum_.assign(2 * n, 0.0);
    lum2_.assign(2 * n, 0.0);
    active_.assign(n, 1);
}

void Film::enable_alpha() {
    alpha_enabled_ = true;
    alpha_.assign(sum_.size(), 0.0);
}

float Film::alpha(int x, int y) const {
    size_t i = size_t(y) * size_t(width_) + size_t(x);
    if (!alpha_enabled_) return 0.f;
    const double norm = weighted_ ? weight_[i] : double(count_[i]);  // filtered like the colour
    return norm > 0.0 ? float(alpha_[i] / norm) : 0.f;
}

std::vector<float> Film::resolve_alpha() const {
    std::vector<float> a(size_t(width_) * size_t(height_));
    for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_; ++x) a[size_t(y) * size_t(width_) + size_t(x)] = alpha(x, y);
    return a;
}

void Film::restore_alpha(std::vector<double> sums) {
    alpha_enabled_ = true;
    alpha_ = std::move(sums);
}

void Film::clear() { resize(width_, height_); }

void Film::set_layout(bool weighted, int aov_channels) {
    weighted_ = weighted;
    aov_channels_ = std::max(0, aov_channels);
    resize(width_, height_);
}

void Film::merge(const FilmTile& t) {
    for (int y = 0; y < t.height; ++y)
        for (int x = 0; x < t.width; ++x) {
            const size_t j = size_t(y) * size_t(t.width) + size_t(x);
            const size_t i = size_t(t.y0 + y) * size_t(width_) + size_t(t.x0 + x);
            sum_[i] += dvec3(t.sum_weight[j]);
            weight_[i] += t.sum_weight[j].w;
            if (alpha_enabled_) alpha_[i] += t.alpha[j];
            for (int k = 0; k < aov_channels_; ++k)
                aov_[i * size_t(aov_channels_) + size_t(k)] += t.aov[j * size_t(aov_channels_) + size_t(k)];
        }
}

void Film::add(const Film& o) {
    add(o.sum_.data(), o.count_.data(), o.weight_.data(), o.aov_.data(), o.alpha_enabled_ ? o.alpha_.data() : nullptr,
        o.splat_.empty() ? nullptr : o.splat_.data(), o.splat_paths_, o.nonfinite_count());
}

void Film::add(const dvec3* sums, const uint32_t* counts, const double* weights, const double* aov,
               const double* alpha, const dvec3* splats, uint64_t splat_paths, uint64_t nonfinite) {
    const size_t n = sum_.size();
    for (size_t i = 0; i < n; ++i) {
        sum_[i] += sums[i];
        count_[i] += counts[i];
    }
    if (weighted_)
        for (size_t i = 0; i < n; ++i) weight_[i] += weights[i];
    for (size_t i = 0; i < aov_.size(); ++i) aov_[i] += aov[i];
    if (alpha_enabled_ && alpha)
        for (size_t i = 0; i < n; ++i) alpha_[i] += alpha[i];
    if (splats) {
        if (splat_.empty()) splat_.assign(n, dvec3(0.0));
        for (size_t i = 0; i < n; ++i) splat_[i] += splats[i];
    }
    splat_paths_ += splat_paths;
    nonfinite_.fetch_add(nonfinite, std::memory_order_relaxed);
}

void FilmTile::reset(const Film& film, int tx0, int ty0, int tx1, int ty1, int margin) {
    x0 = std::max(0, tx0 - margin);
    y0 = std::max(0, ty0 - margin);
    width = std::min(film.width(), tx1 + margin) - x0;
    height = std::min(film.height(), ty1 + margin) - y0;
    aov_channels = film.aov_channels();
    const size_t n = size_t(width) * size_t(height);
    sum_weight.assign(n, dvec4(0.0));
    aov.assign(n * size_t(aov_channels), 0.0);
    if (film.has_alpha()) alpha.assign(n, 0.0);
    else alpha.clear();
}

void Film::add_splats(const std::vector<SplatTile>& tiles, const SplatFilter& filter, int n_threads) {
    size_t n = 0;
    for (const SplatTile& t : tiles) {
        n += t.size();
        splat_paths_ += t.paths;
        if (t.nonfinite) nonfinite_.fetch_add(t.nonfinite, std::memory_order_relaxed);
    }
    if (n == 0) return;
    if (splat_.empty()) splat_.assign(sum_.size(), dvec3(0.0));
    // Bands of rows: four per thread, for balance (a splat's rows may fall in one band only: the
    // others skip it after a test of its rows); one for the box,
    // whose splats are a single addition each.
    const int bands = filter.is_box() || n_threads <= 1 ? 1 : std::min(height_, 4 * n_threads);
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::max(1, n_threads)) if (bands > 1)
    for (int b = 0; b < bands; ++b) {
        const int y0 = int(int64_t(height_) * b / bands), y1 = int(int64_t(height_) * (b + 1) / bands);
        for (const SplatTile& t : tiles)
            for (size_t k = 0; k < t.size(); ++k) filter.add(splat_.data(), t.pos[k], t.value[k], y0, y1);
    }
}

void Film::restore_splats(std::vector<dvec3> sums, uint64_t paths) {
    splat_ = std::move(sums);
    splat_paths_ = paths;
}

vec3 Film::pixel(int x, int y) const {
    size_t i = size_t(y) * size_t(width_) + size_t(x);
    dvec3 v;
    if (weighted_) v = weight_[i] > 0.0 ? sum_[i] / weight_[i] : dvec3(0.0);
    else v = count_[i] > 0 ? sum_[i] / double(count_[i]) : dvec3(0.0);
    v += splat_value(i);
    return vec3(v);
}

float Film::aov(int x, int y, int k) const {
    size_t i = size_t(y) * size_t(width_) + size_t(x);
    double norm = weighted_ ? weight_[i] : double(count_[i]);
    return norm > 0.0 ? float(aov_[i * size_t(aov_channels_) + size_t(k)] / norm) : 0.f;
}

std::vector<std::vector<float>> Film::resolve_aovs() const {
    std::vector<std::vector<float>> out(size_t(aov_channels_), std::vector<float>(size_t(width_) * size_t(height_)));
    for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_; ++x)
            for (int k = 0; k < aov_channels_; ++k) out[size_t(k)][size_t(y) * size_t(width_) + size_t(x)] = aov(x, y, k);
    return out;
}

void Film::resolve_into(std::vector<float>& rgb) const {
    rgb.resize(size_t(width_) * size_t(height_) * 3);
    for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_; ++x) {
            vec3 v = pixel(x, y);
            size_t i = (size_t(y) * size_t(width_) + size_t(x)) * 3;
            rgb[i] = v.x;
            rgb[i + 1] = v.y;
            rgb[i + 2] = v.z;
        }
}

std::vector<float> Film::resolve() const {
    std::vector<float> rgb;
    resolve_into(rgb);
    return rgb;
}

uint64_t Film::total_samples() const {
    uint64_t n = 0;
    for (uint32_t c : count_) n += c;
    for (uint32_t c : decision_count_) n += c;
    return n;
}

void Film::restore(std::vector<dvec3> sums, std::vector<uint32_t> counts, uint64_t nonfinite,
                   std::vector<double> weights) {
    sum_ = std::move(sums);
    count_ = std::move(counts);
    weight_ = std::move(weights);
    nonfinite_ = nonfinite;
    splat_.clear();
    splat_paths_ = 0;
}

}  // namespace candela

#include <unistd.h>
#include "core/error.h"

namespace candela {

void check_film_size(int width, int height, const std::string& where) {
    if (width <= 0 || height <= 0)
        throw Error(where, 0, "image size must be positive, got " + std::to_string(width) + "x" + std::to_string(height));
    // Sums (24 B), counts (4 B), the resolved float image (12 B) and the display copy (12 B).
    double bytes = double(width) * double(height) * 52.0;
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    double ram = pages > 0 && page > 0 ? double(pages) * double(page) : 8e9;
    if (bytes > 0.5 * ram || width > (1 << 20) || height > (1 << 20)) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "image size %dx%d needs %.1f GB, more than half of this machine's %.1f GB",
                      width, height, bytes / 1e9, ram / 1e9);
        throw Error(where, 0, buf);
    }
}

}  // namespace candela
