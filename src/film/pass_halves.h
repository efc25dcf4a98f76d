#pragma once
// The estimated error of an accumulating image, from two halves of its passes: the viewer's
// (render/session.h), with any sampler, filter and integrator (docs/adaptive.md, "The viewer").
//
// After each full pass the film's per-pixel luminance sums are compared with those after the
// previous pass: their difference is that pass alone, and the passes of odd index are summed into
// half B; half A is the film less B. With a and b the halves' values of a pixel, and n_A, n_B
// their pass counts, E[(a - b)^2] = s^2 (1/n_A + 1/n_B) for independent passes of per-pass
// variance s^2, while the image's variance is s^2 / (n_A + n_B): so
//     f (a - b)^2,  f = n_A n_B / (n_A + n_B)^2  (1/4 for equal halves)
// estimates the squared error of the pixel without bias. The image's estimate is the RMS over
// pixels of that, relative to max(pixel luminance, kAdaptiveFloor) as in --target-error:
//     e = sqrt(mean_i f (a_i - b_i)^2 / max(m_i, floor)^2).
// The passes must be independent for this to hold: true of the independent sampler; with the
// stratified and Sobol samplers a pass is part of a set or sequence that the next pass continues,
// so the halves are not independent and e is not an unbiased estimate of the error there.
#include <cstdint>
#include <vector>
#include "film/film.h"

namespace candela {

class PassHalvesError {
public:
    void reset();
    // After full pass `k` (0-based, since the film was cleared) has been added to `film`.
    void add_pass(const Film& film, int k);
    // e as above; -1 until each half has a pass.
    double relative_rms(const Film& film) const;
    int passes(int half) const { return passes_[half]; }

private:
    // Per pixel: luminance of the sums, the normaliser (weight or count) and the splats' luminance.
    std::vector<double> prev_, odd_;  // 3 per pixel
    uint64_t prev_paths_ = 0, odd_paths_ = 0;
    int passes_[2] = {0, 0};
};

}  // namespace candela
