#include "film/pass_halves.h"
#include <algorithm>
#include <cmath>
#include "film/adaptive.h"

namespace candela {

namespace {

double lum(const dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

// The film's luminance state of pixel i: sum, normaliser, splat sum.
void state(const Film& film, size_t i, double* out) {
    out[0] = lum(film.sums()[i]);
    out[1] = film.weighted() ? film.weights()[i] : double(film.counts()[i]);
    out[2] = film.splat_sums().empty() ? 0.0 : lum(film.splat_sums()[i]);
}

// A pixel's luminance from a state, as Film::pixel resolves it (n pixels, `paths` light paths).
double value(const double* s, uint64_t paths, size_t n) {
    double v = s[1] > 0.0 ? s[0] / s[1] : 0.0;
    if (paths > 0) v += s[2] * double(n) / double(paths);
    return v;
}

}  // namespace

void PassHalvesError::reset() {
    prev_.clear();
    odd_.clear();
    prev_paths_ = odd_paths_ = 0;
    passes_[0] = passes_[1] = 0;
}

void PassHalvesError::add_pass(const Film& film, int k) {
    const size_t n = size_t(film.width()) * size_t(film.height());
    if (prev_.size() != 3 * n) {
        prev_.assign(3 * n, 0.0);
        odd_.assign(3 * n, 0.0);
    }
    const bool odd = k & 1;
    for (size_t i = 0; i < n; ++i) {
        double cur[3];
        state(film, i, cur);
        for (int c = 0; c < 3; ++c) {
            if (odd) odd_[3 * i + size_t(c)] += cur[c] - prev_[3 * i + size_t(c)];
            prev_[3 * i + size_t(c)] = cur[c];
        }
    }
    if (odd) odd_paths_ += film.splat_paths() - prev_paths_;
    prev_paths_ = film.splat_paths();
    ++passes_[odd ? 1 : 0];
}

double PassHalvesError::relative_rms(const Film& film) const {
    const size_t n = size_t(film.width()) * size_t(film.height());
    if (passes_[0] == 0 || passes_[1] == 0 || prev_.size() != 3 * n) return -1.0;
    const double na = passes_[0], nb = passes_[1], f = na * nb / ((na + nb) * (na + nb));
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double* all = &prev_[3 * i];
        const double* b = &odd_[3 * i];
        const double a_state[3] = {all[0] - b[0], all[1] - b[1], all[2] - b[2]};
        const double va = value(a_state, prev_paths_ - odd_paths_, n), vb = value(b, odd_paths_, n);
        const double m = std::max(std::abs(value(all, prev_paths_, n)), kAdaptiveFloor);
        sum += f * (va - vb) * (va - vb) / (m * m);
    }
    return std::sqrt(sum / double(n));
}

}  // namespace candela
