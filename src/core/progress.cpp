#include "core/progress.h"
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace candela {

std::string format_duration(double seconds) {
    if (!(seconds >= 0) || !std::isfinite(seconds)) return "--";
    char buf[48];
    const double s = std::ceil(seconds);
    if (s < 60) {
        std::snprintf(buf, sizeof buf, "%.0fs", s);
    } else if (s < 3600) {
        std::snprintf(buf, sizeof buf, "%.0fm%02.0fs", std::floor(s / 60), std::fmod(s, 60));
    } else {
        const double m = std::ceil(seconds / 60);  // hours and minutes: round up to the minute
        std::snprintf(buf, sizeof buf, "%.0fh%02.0fm", std::floor(m / 60), std::fmod(m, 60));
    }
    return buf;
}

double eta_seconds(uint64_t done_spp, uint64_t total_spp, uint64_t pixels, double elapsed,
                   double samples_per_second, double time_limit, bool* limited) {
    if (limited) *limited = false;
    double eta = -1;
    if (done_spp >= total_spp) eta = 0;
    else if (samples_per_second > 0)
        eta = double(total_spp - done_spp) * double(pixels) / samples_per_second;
    if (time_limit > 0) {
        const double left = std::max(0.0, time_limit - elapsed);
        if (eta < 0 || left < eta) {
            eta = left;
            if (limited) *limited = true;
        }
    }
    return eta;
}

std::string progress_line(uint64_t done_spp, uint64_t total_spp, uint64_t pixels, double elapsed,
                          double samples_per_second, double time_limit) {
    constexpr int kWidth = 30;
    const int filled =
        total_spp > 0 ? int(double(kWidth) * double(std::min(done_spp, total_spp)) / double(total_spp)) : 0;
    std::string bar(kWidth, ' ');
    for (int i = 0; i < kWidth; ++i) bar[size_t(i)] = i < filled ? '=' : (i == filled ? '>' : ' ');
    bool limited = false;
    const double eta = eta_seconds(done_spp, total_spp, pixels, elapsed, samples_per_second, time_limit, &limited);
    char buf[256];
    std::snprintf(buf, sizeof buf, "[%s] %llu/%llu spp  %.2f Msamples/s  %.1fs  ETA %s%s", bar.c_str(),
                  (unsigned long long)done_spp, (unsigned long long)total_spp, samples_per_second * 1e-6, elapsed,
                  format_duration(eta).c_str(), limited ? " (time limit)" : "");
    return buf;
}

}  // namespace candela
