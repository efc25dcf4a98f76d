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
// The fraction is fixed (0.5 in the paper); Müller's 2019 learned per-leaf fraction is not here.
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

}  // namespace candela::guiding
