#pragma once
// The training schedule of "Practical Path Guiding" (section 5.2): iterations of 1, 2, 4, ...
// samples per pixel, iteration k sampling from the tree learned in iteration k - 1 and recording
// into a new one (SDTree::end_iteration(k) after it), so that each tree is learned from twice the
// samples of the one before, drawn from a better guide. Training stops when the samples left after
// an iteration of 2^k would be fewer than the next one's 2^(k+1): the rest of the budget is the
// final iteration, rendered with the last tree, recording nothing. Its length is then at least
// twice the last training iteration's.
//
// Which iterations' images are kept is the integrator's choice (the paper keeps only the final one;
// Müller 2019 weights every iteration's image by its inverse variance); this plan only says how
// long each iteration is and whether the tree learns from it.
#include <vector>

namespace candela::guiding {

struct TrainingIteration {
    int index = 0;          // k: pass it to SDTree::end_iteration after a training iteration
    int spp = 0;            // samples per pixel of this iteration
    bool training = false;  // record splats, then end_iteration(index); false: the final iteration
};

inline std::vector<TrainingIteration> plan_training(int total_spp) {
    std::vector<TrainingIteration> plan;
    int left = total_spp, k = 0;
    while (k < 30 && left - (1 << k) >= (2 << k)) {
        plan.push_back({k, 1 << k, true});
        left -= 1 << k;
        ++k;
    }
    if (left > 0) plan.push_back({k, left, false});
    return plan;
}

}  // namespace candela::guiding
