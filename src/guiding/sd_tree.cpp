#include "guiding/sd_tree.h"
#include <omp.h>
#include <queue>
#include <utility>

namespace candela::guiding {

namespace {

// The smallest leaf allowance: a leaf's building tree may always reach the uniform refinement of
// an empty tree (at rho = 0.01: quadrants of share 1/4, 1/16, 1/64 split, 1 + 4 + 16 + 64 nodes).
constexpr size_t kMinNodesPerLeaf = 85;

AABB child_box(const AABB& b, int axis, int which) {
    AABB c = b;
    const float mid = 0.5f * (b.min[axis] + b.max[axis]);
    (which == 0 ? c.max : c.min)[axis] = mid;
    return c;
}

double volume(const AABB& b) {
    const glm::dvec3 e = glm::max(glm::dvec3(b.max) - glm::dvec3(b.min), glm::dvec3(0.0));
    return e.x * e.y * e.z;
}

}  // namespace

void SplatBuffer::add(vec3 position, vec3 direction, float radiance, float pdf) {
    const float value = radiance / pdf;
    if (!(pdf > 0) || !(radiance >= 0) || !std::isfinite(value) || !std::isfinite(position.x + position.y + position.z) ||
        !std::isfinite(direction.x + direction.y + direction.z))
        return;
    splats_.push_back({position, direction, value});
}

SDTree::SDTree(const AABB& scene_box, const GuidingConfig& config) : config_(config) {
    config_.node_budget = std::max(config_.node_budget, 2 * kMinNodesPerLeaf);
    vec3 c(0.f), half(0.5f);
    if (!scene_box.empty()) {
        c = scene_box.center();
        const float e = max_component(scene_box.extent());
        // A little margin so that vertices on the box's faces are inside after rounding.
        if (e > 0 && std::isfinite(e)) half = vec3(0.5f * e * 1.001f);
    }
    box_ = AABB(c - half, c + half);
    nodes_.push_back(Node{});
    leaves_.push_back(Leaf{});
    leaves_[0].building =
        Quadtree::refined(leaves_[0].sampling, config_.rho, config_.max_quadtree_depth, config_.node_budget / 2);
}

size_t SDTree::leaf_index(vec3 p) const {
    AABB b = box_;
    uint32_t n = 0;
    while (nodes_[n].child) {
        const int a = nodes_[n].axis;
        const float mid = 0.5f * (b.min[a] + b.max[a]);
        const int which = p[a] < mid ? 0 : 1;
        b = child_box(b, a, which);
        n = nodes_[n].child + which;
    }
    return nodes_[n].leaf;
}

AABB SDTree::leaf_box(vec3 p) const {
    AABB b = box_;
    uint32_t n = 0;
    while (nodes_[n].child) {
        const int a = nodes_[n].axis;
        const int which = p[a] < 0.5f * (b.min[a] + b.max[a]) ? 0 : 1;
        b = child_box(b, a, which);
        n = nodes_[n].child + which;
    }
    return b;
}

void SDTree::overlapping_leaves(uint32_t node, const AABB& node_box, const AABB& query, double vol,
                                std::vector<std::pair<uint32_t, double>>& out) const {
    const AABB overlap(glm::max(node_box.min, query.min), glm::min(node_box.max, query.max));
    if (overlap.empty()) return;
    if (!nodes_[node].child) {
        const double v = volume(overlap);
        if (v > 0) out.push_back({nodes_[node].leaf, v / vol});
        return;
    }
    const int a = nodes_[node].axis;
    for (int which = 0; which < 2; ++which)
        overlapping_leaves(nodes_[node].child + which, child_box(node_box, a, which), query, vol, out);
}

void SDTree::record(const std::vector<SplatBuffer>& units, int threads) {
    // 1. Per-leaf lists in (unit, splat) order, sequentially: this fixes the order of additions.
    struct Entry {
        const Splat* splat;
        double weight;
    };
    std::vector<std::vector<Entry>> per_leaf(leaves_.size());
    std::vector<std::pair<uint32_t, double>> hits;
    for (const SplatBuffer& unit : units)
        for (const Splat& s : unit.splats()) {
            if (config_.spatial_filter == SpatialFilter::Nearest) {
                per_leaf[leaf_index(s.position)].push_back({&s, 1.0});
                continue;
            }
            const AABB lb = leaf_box(s.position);
            const vec3 h = 0.5f * lb.extent();
            const AABB query(glm::max(s.position - h, box_.min), glm::min(s.position + h, box_.max));
            const double vol = volume(query);
            hits.clear();
            if (vol > 0) overlapping_leaves(0, box_, query, vol, hits);
            if (hits.empty()) hits.push_back({uint32_t(leaf_index(s.position)), 1.0});  // a flat box: no volume
            for (const auto& [leaf, w] : hits) per_leaf[leaf].push_back({&s, w});
        }
    // 2. Each leaf by one thread, in list order.
    const int n = int(leaves_.size());
    const int t = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(t)
    for (int l = 0; l < n; ++l) {
        Leaf& leaf = leaves_[size_t(l)];
        for (const Entry& e : per_leaf[size_t(l)]) {
            leaf.weight += e.weight;
            leaf.building.record_direction(e.splat->direction, double(e.splat->value) * e.weight, config_.directional_filter);
        }
    }
}

void SDTree::end_iteration(int k) {
    const size_t half_budget = config_.node_budget / 2;
    // 1. What was learned becomes the guide.
    size_t sampling_nodes = 0;
    for (Leaf& leaf : leaves_) {
        leaf.sampling = std::move(leaf.building);
        sampling_nodes += leaf.sampling.node_count();
    }
    // 2. Spatial splits, the busiest leaves first (ties: lower leaf index).
    const double threshold = config_.spatial_threshold * std::sqrt(std::ldexp(1.0, k));
    using Item = std::pair<double, int64_t>;  // (weight, -leaf index): the max is the busiest, then the first
    std::priority_queue<Item> heap;
    for (size_t i = 0; i < leaves_.size(); ++i) heap.push({leaves_[i].weight, -int64_t(i)});
    while (!heap.empty() && heap.top().first > threshold) {
        const size_t li = size_t(-heap.top().second);
        heap.pop();
        const size_t copy_nodes = leaves_[li].sampling.node_count();
        if (sampling_nodes + copy_nodes > half_budget || (leaves_.size() + 1) * kMinNodesPerLeaf > half_budget) {
            budget_reached_ = true;
            break;
        }
        const uint32_t node = leaves_[li].node, child = uint32_t(nodes_.size());
        const uint8_t axis = nodes_[node].axis, next_axis = uint8_t((axis + 1) % 3);
        const uint32_t new_leaf = uint32_t(leaves_.size());
        leaves_[li].weight *= 0.5;
        leaves_[li].node = child;
        Leaf copy = leaves_[li];
        leaves_.push_back(std::move(copy));
        leaves_[new_leaf].node = child + 1;
        nodes_[node].child = child;
        nodes_.push_back(Node{0, uint32_t(li), next_axis});
        nodes_.push_back(Node{0, new_leaf, next_axis});
        sampling_nodes += copy_nodes;
        heap.push({leaves_[li].weight, -int64_t(li)});
        heap.push({leaves_[new_leaf].weight, -int64_t(new_leaf)});
    }
    // 3. Fresh building trees, refined from the guide, each within its share of the budget.
    const size_t cap = half_budget / leaves_.size();
    for (Leaf& leaf : leaves_) {
        leaf.building = Quadtree::refined(leaf.sampling, config_.rho, config_.max_quadtree_depth, cap);
        if (leaf.building.node_count() >= cap) budget_reached_ = true;
        leaf.weight = 0;
    }
    ++iterations_;
}

SDTreeStats SDTree::stats() const {
    SDTreeStats s;
    s.spatial_nodes = nodes_.size();
    s.leaves = leaves_.size();
    for (const Leaf& l : leaves_) {
        s.sampling_nodes += l.sampling.node_count();
        s.building_nodes += l.building.node_count();
        s.max_quadtree_depth = std::max(s.max_quadtree_depth, l.sampling.depth());
    }
    s.memory_bytes = nodes_.size() * sizeof(Node) + leaves_.size() * sizeof(Leaf) +
                     (s.sampling_nodes + s.building_nodes) * sizeof(Quadtree::Node);
    // Depth of the spatial tree: walk it.
    std::vector<std::pair<uint32_t, int>> stack{{0u, 0}};
    while (!stack.empty()) {
        auto [n, d] = stack.back();
        stack.pop_back();
        s.max_spatial_depth = std::max(s.max_spatial_depth, d);
        if (nodes_[n].child) {
            stack.push_back({nodes_[n].child, d + 1});
            stack.push_back({nodes_[n].child + 1, d + 1});
        }
    }
    s.budget_reached = budget_reached_;
    return s;
}

bool SDTree::operator==(const SDTree& o) const {
    if (!(nodes_ == o.nodes_) || leaves_.size() != o.leaves_.size()) return false;
    for (size_t i = 0; i < leaves_.size(); ++i) {
        const Leaf &a = leaves_[i], &b = o.leaves_[i];
        if (!(a.sampling == b.sampling) || !(a.building == b.building) || a.weight != b.weight || a.node != b.node)
            return false;
    }
    return true;
}

}  // namespace candela::guiding
