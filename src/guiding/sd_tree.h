#pragma once
// The SD-tree of "Practical Path Guiding" (Müller, Gross and Novák 2017): a binary tree over the
// scene's box (split at the middle, along x, y, z in turn) whose leaves each hold two directional
// quadtrees (guiding/quadtree.h): `sampling`, learned in the previous training iteration and
// read-only while rendering, and `building`, which collects this iteration's splats.
//
// Use, per training iteration k (guiding/schedule.h plans them):
//   1. while rendering, each work unit (tile) appends its splats to its own SplatBuffer; the guide
//      at a vertex is guide_at(position), read-only, shared by all threads;
//   2. after each pass, record(buffers) with the buffers in work-unit order (tile index): the tree
//      is then the same, bit for bit, whatever the number of threads and whatever order the units
//      finished in (see record());
//   3. after the iteration's last pass, end_iteration(k).
//
// Memory: the quadtree nodes of all leaves, sampling and building trees together, never exceed
// GuidingConfig::node_budget (half for each kind); spatial splits stop when a new leaf's copy would
// not fit, and each building tree is refined under budget / 2 / leaves nodes. stats() reports it.
#include <cstddef>
#include <cstdint>
#include <vector>
#include "core/aabb.h"
#include "guiding/quadtree.h"

namespace candela::guiding {

// Spreading a splat over space. Nearest: the leaf holding the vertex (2017). Box (Müller 2019): a
// box of that leaf's size centred on the vertex, clipped to the tree's box, shared among the leaves
// it overlaps by overlap volume (weights sum to 1).
enum class SpatialFilter { Nearest, Box };

struct GuidingConfig {
    double rho = 0.01;                // a quadrant is split when it holds more than this share of its leaf's energy
    int max_quadtree_depth = 20;      // deepest quadrant (the root's quadrants are depth 1)
    double spatial_threshold = 12000; // c: a leaf is split when it received more than c sqrt(2^k) splats in iteration k
    size_t node_budget = size_t(1) << 21;  // quadtree nodes (48 bytes each), all leaves and both trees together
    SpatialFilter spatial_filter = SpatialFilter::Box;
    DirectionalFilter directional_filter = DirectionalFilter::Box;
};

// One training sample: the vertex position, the world direction of the incident light, and the
// value to add: radiance / (solid-angle pdf of `direction`), one channel (e.g. luminance).
struct Splat {
    vec3 position;
    vec3 direction;
    float value;
};

class SplatBuffer {
public:
    // Vertices on delta lobes are not recorded (the guide never samples them); a zero radiance is
    // recorded (it counts towards the leaf's splat count); pdf must be > 0 and everything finite,
    // else the splat is dropped.
    void add(vec3 position, vec3 direction, float radiance, float pdf);
    void clear() { splats_.clear(); }
    size_t size() const { return splats_.size(); }
    const std::vector<Splat>& splats() const { return splats_; }

private:
    std::vector<Splat> splats_;
};

struct SDTreeStats {
    size_t spatial_nodes = 0, leaves = 0;
    size_t sampling_nodes = 0, building_nodes = 0;  // quadtree nodes summed over the leaves
    size_t memory_bytes = 0;                        // the tree's own storage, both kinds of nodes
    int max_spatial_depth = 0, max_quadtree_depth = 0;
    bool budget_reached = false;  // some split (spatial or directional) was refused for the budget
};

class SDTree {
public:
    struct Leaf {
        Quadtree sampling, building;
        double weight = 0;  // splats recorded into `building` (box-filtered splats count fractionally)
        uint32_t node = 0;  // the spatial node that is this leaf
    };

    // The tree covers the smallest cube around `scene_box`, centred on it (cubes keep the leaves'
    // aspect ratio bounded under alternating splits). An empty or flat box is widened to a unit cube.
    SDTree(const AABB& scene_box, const GuidingConfig& config = {});

    // The distribution to sample at a vertex (points outside the box use the nearest leaf).
    const Quadtree& guide_at(vec3 p) const { return leaves_[leaf_index(p)].sampling; }
    size_t leaf_index(vec3 p) const;
    AABB leaf_box(vec3 p) const;

    // Adds every splat of `units` to the building trees. The splats are first sorted into per-leaf
    // lists in the order (unit index, order within the unit); each leaf's list is then added by
    // one thread, in that order. Each sum therefore sees the same additions in the same order for
    // any `threads`, and depends only on how the splats are assigned to units, which the
    // integrator fixes by tile, not by thread.
    void record(const std::vector<SplatBuffer>& units, int threads = 0);

    // Ends training iteration k (0 for the first): every leaf's building tree becomes its sampling
    // tree; leaves that received more than c sqrt(2^k) splats are split (each child a copy, with
    // half the count, split again while above the threshold); every building tree is replaced by
    // the refinement of its sampling tree (rho, max depth, budget), with zero sums.
    void end_iteration(int k);
    int iterations() const { return iterations_; }

    SDTreeStats stats() const;
    const GuidingConfig& config() const { return config_; }
    const AABB& box() const { return box_; }
    const std::vector<Leaf>& leaves() const { return leaves_; }
    bool operator==(const SDTree& o) const;

private:
    // A spatial node: an inner node splits `axis` at the middle into child and child + 1; a leaf
    // (child == 0) is leaves_[leaf], and would split along `axis`.
    struct Node {
        uint32_t child = 0;
        uint32_t leaf = 0;
        uint8_t axis = 0;
        bool operator==(const Node& o) const { return child == o.child && leaf == o.leaf && axis == o.axis; }
    };
    void overlapping_leaves(uint32_t node, const AABB& node_box, const AABB& query, double volume,
                            std::vector<std::pair<uint32_t, double>>& out) const;

    GuidingConfig config_;
    AABB box_;
    std::vector<Node> nodes_;
    std::vector<Leaf> leaves_;
    int iterations_ = 0;
    bool budget_reached_ = false;
};

}  // namespace candela::guiding
