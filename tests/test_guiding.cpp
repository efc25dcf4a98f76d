// Path guiding's SD-tree (src/guiding): the quadtree samples the density it reports (chi-square,
// with a control that must fail), that density integrates to 1 over the sphere, training on a known
// incident light learns it (KL divergence, against a control that records the wrong value), the
// spatial tree splits where the splats are as c sqrt(2^k) says, the node budget holds, and the
// merged tree is the same bit for bit for any thread count, and the learned BSDF fraction moves
// towards the strategy that matches the integrand.
#include <gtest/gtest.h>
#include <cmath>
#include "core/frame.h"
#include "guiding/mixture.h"
#include "guiding/schedule.h"
#include "guiding/sd_tree.h"
#include "sampling/warp.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::guiding;
using namespace candela::stats;

namespace {

constexpr double kAlpha = 0.01;

vec2 next_2d(PCG32& rng) {
    const float a = rng.next_float();
    return vec2(a, rng.next_float());
}

// The incident light of the learning tests: a smooth lobe exp(kappa (cos - 1)) about an axis that
// is not a pole of the (cos theta, phi) map. Its normalised form (a von Mises-Fisher density) is
// the distribution a perfect guide would sample.
struct Lobe {
    vec3 axis = glm::normalize(vec3(0.6f, -0.3f, 0.45f));
    float kappa = 20.f;
    float radiance(vec3 d) const { return std::exp(kappa * (glm::dot(d, axis) - 1.f)); }
    double density(vec3 d) const {
        return double(kappa) / (2.0 * M_PI * (1.0 - std::exp(-2.0 * kappa))) * double(radiance(d));
    }
    vec3 sample(vec2 u) const {
        const float c = 1.f + std::log1p(-u.x * (1.f - std::exp(-2.f * kappa))) / kappa;
        const float s = std::sqrt(std::max(0.f, 1.f - c * c)), phi = 2.f * kPi * u.y;
        return Frame(axis).to_world(vec3(s * std::cos(phi), s * std::sin(phi), c));
    }
};

// Trains one quadtree on the lobe as a guided integrator would: iterations of doubling length,
// each sampling the one-sample mixture of a uniform "BSDF" and the current guide, and recording
// radiance / mixture pdf (or, for the control, radiance alone).
Quadtree train_on_lobe(const Lobe& lobe, int iterations, int max_depth, bool divide_by_pdf = true,
                       DirectionalFilter filter = DirectionalFilter::Nearest) {
    const GuideMixture mix{0.5f};
    Quadtree guide, building = Quadtree::refined(guide, 0.01, max_depth, 1u << 20);
    PCG32 rng(3, 11);
    for (int k = 0; k < iterations; ++k) {
        for (int i = 0; i < (2048 << k); ++i) {
            float u = rng.next_float();
            const vec2 u2 = next_2d(rng);
            const vec3 d = mix.use_bsdf(u) ? square_to_uniform_sphere(u2) : guide.sample(u2, nullptr);
            const float pdf = mix.pdf(kInv4Pi, guide.pdf(d));
            building.record_direction(d, divide_by_pdf ? lobe.radiance(d) / pdf : lobe.radiance(d), filter);
        }
        guide = building;
        building = Quadtree::refined(guide, 0.01, max_depth, 1u << 20);
    }
    return guide;
}

// KL(target || guide) = E_target[log(target / guide)], by sampling the target.
double kl_divergence(const Lobe& lobe, const Quadtree& guide) {
    PCG32 rng(5, 9);
    double sum = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
        const vec3 d = lobe.sample(next_2d(rng));
        const double q = guide.pdf(d);
        if (!(q > 0)) return INFINITY;
        sum += std::log(lobe.density(d) / q);
    }
    return sum / n;
}

ChiSquareResult chi_square_of(const Quadtree& sampler, const Quadtree& density, int res) {
    ChiSquareSetup s;
    s.domain = sphere_domain();
    s.res_x = s.res_y = res;
    s.samples = 1000000;
    s.seed = 17;
    s.sample = [&](PCG32& rng) {
        DomainSample out;
        out.kind = DomainSample::Smooth;
        out.p = dvec3(sampler.sample(next_2d(rng), nullptr));
        return out;
    };
    s.pdf = [&](const dvec3& p) { return double(density.pdf(vec3(p))); };
    return chi_square_2d(s);
}

}  // namespace

// The quadtree's cells down to depth 6 coincide with the cells of a 64 x 64 histogram in the same
// (cos theta, phi) map, where the density is constant per cell: the expected counts are exact.
TEST(Guiding, QuadtreeSamplesItsPdf) {
    const Quadtree guide = train_on_lobe(Lobe{}, 4, 6);
    ASSERT_GE(guide.depth(), 5) << "the test tree should be refined";
    const ChiSquareResult r = chi_square_of(guide, guide, 64);
    EXPECT_GE(r.p_value, kAlpha) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-6);
    // Control: the same samples against the density of a tree that learned a different lobe.
    Lobe other;
    other.axis = glm::normalize(vec3(0.62f, -0.3f, 0.45f));
    const Quadtree wrong = train_on_lobe(other, 4, 6);
    EXPECT_LT(chi_square_of(guide, wrong, 64).p_value, 1e-6);
}

// A tree at the default depth (20): its cells are finer than any histogram, so the pdf's integral
// is checked by Monte Carlo (E over uniform directions of 4 pi pdf = 1) and exactly by its leaves.
TEST(Guiding, QuadtreePdfIntegratesToOne) {
    const Quadtree guide = train_on_lobe(Lobe{}, 6, 20);
    ASSERT_GE(guide.depth(), 7);
    // Exactly: every leaf cell's density times its area.
    double sum = 0;
    std::vector<std::tuple<uint32_t, vec2, float>> stack{{0u, vec2(0.f), 1.f}};
    while (!stack.empty()) {
        auto [n, o, size] = stack.back();
        stack.pop_back();
        for (int q = 0; q < 4; ++q) {
            const vec2 co = o + 0.5f * size * vec2(q & 1, q >> 1);
            if (guide.nodes()[n].child[q])
                stack.push_back({guide.nodes()[n].child[q], co, 0.5f * size});
            else
                sum += guide.pdf_square(co + 0.25f * size) * 0.25 * double(size) * double(size);
        }
    }
    EXPECT_NEAR(sum, 1.0, 1e-9);
    RunningStats mc;
    PCG32 rng(1, 2);
    for (int i = 0; i < 1000000; ++i) mc.add(4.0 * M_PI * guide.pdf(square_to_uniform_sphere(next_2d(rng))));
    const MeanTest t = z_test(mc, 1.0);
    EXPECT_GE(t.p_value, kAlpha) << t.describe();
    // An empty tree is the uniform sphere.
    const Quadtree empty;
    EXPECT_FLOAT_EQ(empty.pdf(normalize(vec3(0.3f, 0.2f, -0.9f))), kInv4Pi);
    float pdf = 0;
    empty.sample(vec2(0.3f, 0.7f), &pdf);
    EXPECT_FLOAT_EQ(pdf, kInv4Pi);
}

// The one-sample mixture of a BSDF (here the cosine hemisphere) and the guide samples the mixture
// density it reports.
TEST(Guiding, MixtureSamplesItsPdf) {
    const Quadtree guide = train_on_lobe(Lobe{}, 3, 6);
    const GuideMixture mix{0.3f};
    ChiSquareSetup s;
    s.domain = sphere_domain();
    s.res_x = s.res_y = 64;
    s.samples = 1000000;
    s.sample = [&](PCG32& rng) {
        float u = rng.next_float();
        const vec2 u2 = next_2d(rng);
        DomainSample out;
        out.kind = DomainSample::Smooth;
        out.p = dvec3(mix.use_bsdf(u) ? square_to_cosine_hemisphere(u2) : guide.sample(u2, nullptr));
        return out;
    };
    s.pdf = [&](const dvec3& p) {
        return double(mix.pdf(square_to_cosine_hemisphere_pdf(vec3(p)), guide.pdf(vec3(p))));
    };
    s.integration_points = 8;  // the cosine is smooth, the guide constant per cell
    const ChiSquareResult r = chi_square_2d(s);
    EXPECT_GE(r.p_value, kAlpha) << r.describe();
}

// Training on a known lobe learns it: the KL divergence from the lobe's density to the guide's
// falls from that of the uniform sphere to a small value, and the guide's samples concentrate in
// the lobe. Recording radiance without dividing by the sampling pdf (a biased target: radiance x
// guide) must end measurably further from the lobe. Both filters learn it.
TEST(Guiding, TrainingLearnsALobe) {
    const Lobe lobe;
    const double kl_uniform = kl_divergence(lobe, Quadtree{});
    const Quadtree guide = train_on_lobe(lobe, 7, 20);
    const double kl = kl_divergence(lobe, guide);
    const double kl_box = kl_divergence(lobe, train_on_lobe(lobe, 7, 20, true, DirectionalFilter::Box));
    const double kl_wrong = kl_divergence(lobe, train_on_lobe(lobe, 7, 20, false));
    std::printf("KL: uniform %.4f, learned %.4f (box filter %.4f), without 1/pdf %.4f\n", kl_uniform, kl, kl_box,
                kl_wrong);
    EXPECT_GT(kl_uniform, 1.5);
    EXPECT_LT(kl, 0.1);
    EXPECT_LT(kl_box, 0.1);
    EXPECT_GT(kl_wrong, 2 * kl);
    // Half the lobe's energy lies within acos(1 - ln 2 / kappa) of its axis (2.6% of the sphere).
    const float cos_half = 1.f - std::log(2.f) / lobe.kappa;
    PCG32 rng(8, 8);
    int inside = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) inside += glm::dot(guide.sample(next_2d(rng), nullptr), lobe.axis) > cos_half;
    EXPECT_NEAR(double(inside) / n, 0.5, 0.03);
}

// Refinement by energy share: no quadrant holding more than rho of the energy is left unsplit
// (below the maximum depth), and the tree is no finer than the budget given.
TEST(Guiding, QuadtreeRefinementAndBudget) {
    const Quadtree stats = train_on_lobe(Lobe{}, 5, 20);
    const Quadtree r = Quadtree::refined(stats, 0.01, 20, 1u << 20);
    // Record the lobe's exact energy per cell (by sampling it) to check the rule on the new tree.
    Quadtree energy = r;
    PCG32 rng(2, 4);
    for (int i = 0; i < 200000; ++i) energy.record_direction(Lobe{}.sample(next_2d(rng)), 1.0, DirectionalFilter::Nearest);
    int leaves_over = 0;
    for (const Quadtree::Node& n : energy.nodes())
        for (int q = 0; q < 4; ++q) leaves_over += !n.child[q] && n.sum[q] / energy.total() > 0.03;
    EXPECT_EQ(leaves_over, 0) << "a leaf quadrant holds several times rho";
    EXPECT_GT(r.node_count(), 40u);
    const Quadtree capped = Quadtree::refined(stats, 0.01, 20, 25);
    EXPECT_EQ(capped.node_count(), 25u);
    const Quadtree shallow = Quadtree::refined(stats, 0.01, 4, 1u << 20);
    EXPECT_EQ(shallow.depth(), 4);
    // An empty tree refines uniformly: quadrants of share 1/4, 1/16 and 1/64 > rho = 0.01 are split,
    // those of 1/256 are not (1 + 4 + 16 + 64 nodes, depth 4).
    const Quadtree uniform = Quadtree::refined(Quadtree{}, 0.01, 20, 1u << 20);
    EXPECT_EQ(uniform.node_count(), 85u);
    EXPECT_EQ(uniform.depth(), 4);
}

// Spatial splits: 10000 splats in iteration 0 at c = 1000 split the root until the halved counts
// are at most 1000 (four times: 16 leaves); 20000 splats in one corner in iteration 1 (threshold
// 1000 sqrt 2) split that corner's leaf four more times.
TEST(Guiding, SpatialSubdivisionCounts) {
    GuidingConfig cfg;
    cfg.spatial_threshold = 1000;
    cfg.spatial_filter = SpatialFilter::Nearest;
    SDTree tree(AABB(vec3(0.f), vec3(1.f)), cfg);
    PCG32 rng(4, 4);
    std::vector<SplatBuffer> units(1);
    for (int i = 0; i < 10000; ++i)
        units[0].add(vec3(rng.next_float(), rng.next_float(), rng.next_float()), vec3(0, 0, 1), 1.f, 1.f);
    tree.record(units);
    EXPECT_DOUBLE_EQ(tree.leaves()[0].weight, 10000.0);
    tree.end_iteration(0);
    EXPECT_EQ(tree.stats().leaves, 16u);
    EXPECT_EQ(tree.stats().max_spatial_depth, 4);
    units[0].clear();
    for (int i = 0; i < 20000; ++i)
        units[0].add(0.1f * vec3(rng.next_float(), rng.next_float(), rng.next_float()), vec3(0, 0, 1), 1.f, 1.f);
    tree.record(units);
    tree.end_iteration(1);
    EXPECT_EQ(tree.stats().leaves, 31u);
    EXPECT_EQ(tree.stats().max_spatial_depth, 8);
    EXPECT_FALSE(tree.stats().budget_reached);
    // The box filter shares each splat among the leaves its box overlaps: the weights still sum to
    // the number of splats, and a splat near a face reaches the neighbour.
    GuidingConfig box_cfg = cfg;
    box_cfg.spatial_filter = SpatialFilter::Box;
    SDTree box_tree(AABB(vec3(0.f), vec3(1.f)), box_cfg);
    box_tree.record(std::vector<SplatBuffer>(1, units[0]));
    box_tree.end_iteration(0);
    units[0].clear();
    units[0].add(vec3(0.49f, 0.3f, 0.3f), vec3(0, 0, 1), 1.f, 1.f);
    box_tree.record(units);
    double total = 0;
    int touched = 0;
    for (const SDTree::Leaf& l : box_tree.leaves()) {
        total += l.weight;
        touched += l.weight > 0;
    }
    EXPECT_NEAR(total, 1.0, 1e-6);
    EXPECT_GE(touched, 2);
}

// The node budget holds through many iterations of splats that want more (many spatial splits, a
// sharp lobe everywhere); the same training with a large budget exceeds it (the control).
TEST(Guiding, NodeBudgetHolds) {
    auto train = [](size_t budget) {
        GuidingConfig cfg;
        cfg.spatial_threshold = 50;
        cfg.node_budget = budget;
        SDTree tree(AABB(vec3(-1.f), vec3(1.f)), cfg);
        PCG32 rng(6, 1);
        const Lobe lobe;
        std::vector<SplatBuffer> units(4);
        for (int k = 0; k < 5; ++k) {
            for (SplatBuffer& u : units) {
                u.clear();
                for (int i = 0; i < (2000 << k); ++i) {
                    const vec3 p = 2.f * vec3(rng.next_float(), rng.next_float(), rng.next_float()) - 1.f;
                    const vec3 d = lobe.sample(next_2d(rng));
                    u.add(p, d, lobe.radiance(d), float(lobe.density(d)));
                }
            }
            tree.record(units);
            tree.end_iteration(k);
            const SDTreeStats s = tree.stats();
            EXPECT_LE(s.sampling_nodes + s.building_nodes, tree.config().node_budget);
        }
        return tree.stats();
    };
    const SDTreeStats small = train(4000), large = train(1u << 22);
    EXPECT_TRUE(small.budget_reached);
    EXPECT_FALSE(large.budget_reached);
    EXPECT_GT(large.sampling_nodes + large.building_nodes, 4000u);
    EXPECT_GT(large.leaves, small.leaves);
    EXPECT_LE(small.memory_bytes, 4000 * sizeof(Quadtree::Node) + small.leaves * (sizeof(SDTree::Leaf) + 24));
}

// The tree depends on the work units and their order, never on the thread count: recorded with
// 1, 2 and 5 threads, three training iterations give identical trees, bit for bit. Control: the
// same units merged in reverse order give a different tree, so the comparison can see order.
TEST(Guiding, MergedTreeIndependentOfThreads) {
    auto units_of = [](int k) {
        std::vector<SplatBuffer> units(12);
        const Lobe lobe;
        // Each unit draws from its own stream, as a tile does, whatever thread renders it.
        for (size_t t = 0; t < units.size(); ++t) {
            PCG32 rng(100 + t, uint64_t(k));
            for (int i = 0; i < 3000; ++i) {
                const vec3 p = vec3(rng.next_float(), rng.next_float(), rng.next_float());
                const vec3 d = lobe.sample(next_2d(rng));
                units[t].add(p, d, lobe.radiance(d) * (1.f + p.x), float(lobe.density(d)));
            }
        }
        return units;
    };
    auto train = [&](int threads, bool reverse) {
        GuidingConfig cfg;
        cfg.spatial_threshold = 3000;
        SDTree tree(AABB(vec3(0.f), vec3(1.f)), cfg);
        for (int k = 0; k < 3; ++k) {
            std::vector<SplatBuffer> units = units_of(k);
            if (reverse) std::reverse(units.begin(), units.end());
            tree.record(units, threads);
            tree.end_iteration(k);
        }
        return tree;
    };
    const SDTree one = train(1, false);
    ASSERT_GT(one.stats().leaves, 4u);
    EXPECT_TRUE(one == train(2, false));
    EXPECT_TRUE(one == train(5, false));
    EXPECT_FALSE(one == train(1, true));
}

TEST(Guiding, TrainingPlanDoubles) {
    const std::vector<TrainingIteration> plan = plan_training(16);
    ASSERT_EQ(plan.size(), 4u);
    EXPECT_EQ(plan[0].spp, 1);
    EXPECT_EQ(plan[1].spp, 2);
    EXPECT_EQ(plan[2].spp, 4);
    EXPECT_EQ(plan[3].spp, 9);
    EXPECT_FALSE(plan[3].training);
    for (int total : {1, 2, 3, 7, 64, 1000, 4096}) {
        const std::vector<TrainingIteration> p = plan_training(total);
        int sum = 0;
        for (size_t i = 0; i < p.size(); ++i) {
            sum += p[i].spp;
            EXPECT_EQ(p[i].training, i + 1 < p.size());
            if (p[i].training) {
                EXPECT_EQ(p[i].spp, 1 << i);
            }
        }
        EXPECT_EQ(sum, total);
        if (p.size() >= 2) {
            EXPECT_GE(p.back().spp, 2 * p[p.size() - 2].spp);
        }
    }
}

// The learned BSDF fraction moves towards the strategy that matches the integrand: towards the
// guide when the integrand is the lobe the guide learned (the "BSDF" uniform), towards the BSDF
// when the integrand is the BSDF's own cosine (the guide learned an unrelated lobe). The two
// cases are each other's control: the same learner must end on opposite sides of 1/2.
TEST(Guiding, LearnedFractionFindsTheBetterStrategy) {
    const Lobe lobe;
    const Quadtree guide = train_on_lobe(lobe, 5, 20);
    auto learn = [&](bool integrand_is_lobe) {
        FractionLearner learner;
        PCG32 rng(12, 3);
        for (int i = 0; i < 20000; ++i) {
            const GuideMixture mix = learner.mixture();
            float u = rng.next_float();
            const vec2 u2 = next_2d(rng);
            vec3 d;
            float bsdf_pdf;
            if (integrand_is_lobe) {
                d = mix.use_bsdf(u) ? square_to_uniform_sphere(u2) : guide.sample(u2, nullptr);
                bsdf_pdf = kInv4Pi;
            } else {
                d = mix.use_bsdf(u) ? square_to_cosine_hemisphere(u2) : guide.sample(u2, nullptr);
                bsdf_pdf = square_to_cosine_hemisphere_pdf(d);
            }
            const float guide_pdf = guide.pdf(d);
            const float f = integrand_is_lobe ? lobe.radiance(d) : std::max(d.z, 0.f) * kInvPi;
            learner.step(f, bsdf_pdf, guide_pdf, mix.pdf(bsdf_pdf, guide_pdf));
        }
        return learner.fraction();
    };
    const float towards_guide = learn(true), towards_bsdf = learn(false);
    std::printf("learned BSDF fraction: %.3f (integrand = the guide's lobe), %.3f (integrand = the cosine)\n",
                towards_guide, towards_bsdf);
    EXPECT_LT(towards_guide, 0.3f);
    EXPECT_GT(towards_bsdf, 0.7f);
}
