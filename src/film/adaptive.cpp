#include "film/adaptive.h"
#include <algorithm>
#include <cmath>
#include <limits>

namespace candela {

double adaptive_pixel_error(const Film& film, int x, int y, int h) {
    const uint32_t n = film.half_count(x, y, h);
    if (n < 2) return std::numeric_limits<double>::infinity();
    const double dn = double(n);
    const double m = film.half_lum_sum(x, y, h) / dn;
    const double s2 = std::max(0.0, (film.half_lum_sq(x, y, h) - dn * m * m) / (dn - 1.0));
    return std::sqrt(s2 / dn) / std::max(std::abs(m), kAdaptiveFloor);
}

uint64_t update_adaptive(Film& film, const AdaptiveSettings& s) {
    uint64_t active = 0;
    const int h = s.decide_on_image ? 1 : 0;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            if (!film.active(x, y)) continue;
            if (film.samples_taken(x, y) >= s.min_spp && adaptive_pixel_error(film, x, y, h) < s.target_error)
                film.set_active(x, y, false);
            else
                ++active;
        }
    return active;
}

}  // namespace candela
