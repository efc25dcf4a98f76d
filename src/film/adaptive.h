#pragma once
// The stopping rule of adaptive sampling (--target-error, docs/adaptive.md). Run between passes,
// from the film alone, so the image does not depend on the thread count.
//
// The estimated error of a pixel is the relative standard error of the mean luminance of its
// decision half (the samples of even index, Film::add_adaptive_sample):
//     e = sqrt(s2 / n) / max(m, kAdaptiveFloor)
// with n the half's sample count, m the mean of its luminances and s2 their unbiased sample
// variance. The image half (odd indices) has n or n - 1 samples of the same distribution, so e
// also estimates the relative error of the pixel's value in the image. Pixels darker than the
// floor are judged on the absolute error E * kAdaptiveFloor instead (else black pixels never stop).
#include <cstdint>
#include "film/film.h"

namespace candela {

constexpr double kAdaptiveFloor = 1e-2;

struct AdaptiveSettings {
    double target_error = 0;  // E: a pixel stops once e < E
    uint32_t min_spp = 16;    // samples (both halves) a pixel takes before it may stop; >= 4
    // The control of the tests only: decide on the image half, i.e. with the very samples that are
    // averaged (the naive rule, biased: it stops early on pixels that missed their rare bright paths).
    bool decide_on_image = false;
};

// e of half h of a pixel; +infinity with fewer than 2 samples in that half.
double adaptive_pixel_error(const Film& film, int x, int y, int h = 0);

// Marks inactive each active pixel with at least min_spp samples whose e < E. Returns the number
// of pixels still active.
uint64_t update_adaptive(Film& film, const AdaptiveSettings& s);

}  // namespace candela
