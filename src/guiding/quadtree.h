#pragma once
// The directional half of the SD-tree (Müller, Gross and Novák 2017, "Practical Path Guiding",
// section 3): an adaptive quadtree over the square [0,1)^2 that square_to_uniform_sphere maps onto
// the sphere of directions, u = ((1 - cos theta) / 2, phi / 2pi) in the WORLD frame (theta from +z).
// The map is equal-area (the square's area 1 is the sphere's 4 pi steradians), so a density that is
// piecewise constant on the square is piecewise constant per steradian too.
//
// Math contract.
//   * What is recorded: a splat adds a non-negative value to the quadrant(s) where its direction
//     lands. The integrator splats radiance / pdf (the solid-angle pdf its direction was sampled
//     with), so that the expected sum in a cell is the integral of the incident radiance over the
//     cell's solid angle, times the number of splats.
//   * What is sampled: a direction with probability proportional to a cell's sum, uniformly inside
//     the cell. pdf() is per steradian and integrates to 1 over the sphere; a tree whose sums are
//     all zero is the uniform sphere (1 / 4pi).
//   * Cells the tree never saw light in have pdf 0: the guide is one strategy of a mixture with the
//     BSDF (guiding/mixture.h), never sampled alone.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>
#include "core/math.h"

namespace candela::guiding {

// How a splat is spread over the quadrants. Nearest: the one leaf cell it lands in (2017). Box
// (Müller 2019, "Practical Path Guiding in Production"): a square of the landing leaf's size
// centred on the point, spread over every cell it overlaps by overlap area; it wraps around in phi
// and is clipped at the poles (the clipped part is renormalised, so no energy is lost).
enum class DirectionalFilter { Nearest, Box };

class Quadtree {
public:
    // One node holds its four quadrants: quadrant q = (x >= half) + 2 (y >= half) of the node's
    // square. child[q] == 0 marks a leaf quadrant (node 0 is the root, nobody's child).
    struct Node {
        std::array<double, 4> sum{};
        std::array<uint32_t, 4> child{};
    };

    Quadtree() : nodes_(1) {}

    // The sum over the whole sphere; the tree's node count and deepest quadrant (the root's four
    // quadrants are depth 1).
    double total() const;
    size_t node_count() const { return nodes_.size(); }
    size_t memory_bytes() const { return nodes_.size() * sizeof(Node); }
    int depth() const;
    const std::vector<Node>& nodes() const { return nodes_; }

    // Add `value` (>= 0, finite) at point p of the square.
    void record(vec2 p, double value, DirectionalFilter filter);
    void record_direction(vec3 dir, double value, DirectionalFilter filter);

    // A direction with density pdf(dir) per steradian, from two uniform numbers in [0,1) (both are
    // reused down the tree, rescaled in double). `pdf_out` receives that density.
    vec3 sample(vec2 u, float* pdf_out) const;
    vec2 sample_square(vec2 u, double* pdf_square) const;
    float pdf(vec3 dir) const;
    double pdf_square(vec2 p) const;  // density per unit area of the square = 4 pi * pdf(dir)

    // A tree with zero sums whose cells are refined where `stats` holds energy: a quadrant is split
    // when its share of stats' total exceeds rho (quadrants that stats did not split are assumed
    // uniform: each child gets a quarter), down to max_depth. With more candidates than `max_nodes`
    // allows, the most energetic are split first (ties by the order found), so the cut drops the
    // least light. A stats tree with zero total refines uniformly (share 4^-depth).
    static Quadtree refined(const Quadtree& stats, double rho, int max_depth, size_t max_nodes);

    // The same tree, its sums scaled (a split spatial leaf gives each child half).
    void scale(double factor);
    bool operator==(const Quadtree& o) const;

private:
    void add_box(uint32_t node, glm::dvec2 origin, double size, glm::dvec2 lo, glm::dvec2 hi, double density);
    int depth_at(vec2 p) const;

    std::vector<Node> nodes_;
};

}  // namespace candela::guiding
