#pragma once
// One-sample MIS between the BSDF and the guide (Müller et al. 2017, section 5.1): a direction is
// drawn from the BSDF with probability `bsdf_fraction`, else from the guide, and whichever was
// drawn, the estimate divides by the mixture density
//     p(w) = a p_bsdf(w) + (1 - a) p_guide(w),   a = bsdf_fraction,
// both densities per steradian (the BSDF's as bsdf.h defines it, the guide's from Quadtree::pdf).
// This is the balance heuristic of the two strategies in one-sample form: unbiased wherever either
// density is positive, so cells the guide never saw light in are still reached through the BSDF.
// Delta lobes are not guided: a vertex whose sampled lobe is delta keeps the BSDF's own weight.
//
// The fraction is fixed (0.5 in the paper) or learned (FractionLearner below, Müller 2019).
#include <algorithm>
#include <cmath>

namespace candela::guiding {

struct GuideMixture {
    float bsdf_fraction = 0.5f;

    // Chooses the strategy with u (in [0,1)) and rescales u to [0,1) for the chosen one.
    bool use_bsdf(float& u) const {
        const bool bsdf = u < bsdf_fraction;
        u = bsdf ? u / bsdf_fraction : (u - bsdf_fraction) / (1.f - bsdf_fraction);
        u = u < 0x1.fffffep-1f ? u : 0x1.fffffep-1f;  // the division may round up to 1
        return bsdf;
    }
    float pdf(float bsdf_pdf, float guide_pdf) const {
        return bsdf_fraction * bsdf_pdf + (1.f - bsdf_fraction) * guide_pdf;
    }
};

// The learned BSDF fraction of Müller 2019 (from Neural Importance Sampling, Müller et al. 2019):
// a = sigmoid(theta), theta moved by Adam to lower the KL divergence from the normalised integrand
// to the mixture. One sample's gradient of that divergence with respect to a is
//     dD/da ~ -(f / p(w)) (p_bsdf(w) - p_guide(w)) / p_sampled(w)
// (f: the integrand's value at w, BSDF x cosine x incident radiance, one channel; p: the mixture at
// the current a; p_sampled: the density w was actually drawn with), times da/dtheta = a (1 - a),
// plus 0.01 theta (L2: theta stays finite where one strategy never wins). The integrand's unknown
// normalisation only scales the gradient, which Adam's step does not see.
//
// Each step depends on the previous: like the quadtree's sums, the steps must come in a fixed order
// (per leaf, in tile order, as SDTree::record orders splats) for the result not to depend on threads.
class FractionLearner {
public:
    float fraction() const { return float(1.0 / (1.0 + std::exp(-theta_))); }
    GuideMixture mixture() const { return {fraction()}; }

    void step(float integrand, float bsdf_pdf, float guide_pdf, float sampled_pdf) {
        const double a = 1.0 / (1.0 + std::exp(-theta_));
        const double mix = a * bsdf_pdf + (1.0 - a) * guide_pdf;
        if (!(mix > 0) || !(sampled_pdf > 0) || !(integrand >= 0) || !std::isfinite(integrand)) return;
        const double d_a = -(double(integrand) / mix) * (double(bsdf_pdf) - double(guide_pdf)) / double(sampled_pdf);
        const double g = d_a * a * (1.0 - a) + 0.01 * theta_;
        if (!std::isfinite(g)) return;
        // Adam (Kingma and Ba 2015) with its usual constants.
        ++t_;
        m_ = kBeta1 * m_ + (1 - kBeta1) * g;
        v_ = kBeta2 * v_ + (1 - kBeta2) * g * g;
        const double m_hat = m_ / (1 - std::pow(kBeta1, double(t_))), v_hat = v_ / (1 - std::pow(kBeta2, double(t_)));
        theta_ -= learning_rate * m_hat / (std::sqrt(v_hat) + 1e-8);
        theta_ = std::clamp(theta_, -20.0, 20.0);
    }

    double learning_rate = 0.01;

private:
    static constexpr double kBeta1 = 0.9, kBeta2 = 0.999;
    double theta_ = 0;  // fraction 0.5 until it learns
    double m_ = 0, v_ = 0;
    long long t_ = 0;
};

}  // namespace candela::guiding
