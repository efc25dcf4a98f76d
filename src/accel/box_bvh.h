#pragma once
// A BVH over a list of boxes, for the few-to-thousands of objects that are not triangles: the
// instances of the two-level accelerator (accel/instances.h) and the analytic shapes
// (accel/with_analytic.h). Each item is stored exactly once (boxes may overlap freely, which a
// k-d tree would handle by duplicating references), so memory is linear in the item count.
//
// Contract: traverse(ray, visit) calls visit(i) for each item i whose box the ray crosses within
// [ray.tmin, ray.tmax], reading ray.tmax at each test, so a visitor that shrinks the ray (a closest
// hit) prunes the rest; visit returns true to stop at once (a shadow ray that found a blocker), and
// traverse then returns true. The order of the visits is fixed by the tree, not the thread.
#include <cstdint>
#include <vector>
#include "core/aabb.h"
#include "core/ray.h"

namespace candela {

class BoxBvh {
public:
    void build(const std::vector<AABB>& boxes);
    bool empty() const { return nodes_.empty(); }
    size_t memory_bytes() const {
        return nodes_.capacity() * sizeof(Node) + order_.capacity() * sizeof(uint32_t) +
               leaf_boxes_.capacity() * sizeof(AABB);
    }

    template <class Visit>
    bool traverse(const Ray& ray, Visit&& visit) const {
        if (nodes_.empty()) return false;
        const vec3 inv_d = 1.f / ray.d;
        uint32_t stack[kMaxDepth + 2];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& node = nodes_[stack[--top]];
            float t0, t1;
            if (!node.box.intersect(ray, inv_d, t0, t1)) continue;
            if (node.count == 0) {
                stack[top++] = node.index;
                stack[top++] = uint32_t(&node - nodes_.data()) + 1;  // the first child, popped first
                continue;
            }
            for (uint32_t k = node.index; k < node.index + node.count; ++k) {
                if (node.count > 1 && !leaf_boxes_[k].intersect(ray, inv_d, t0, t1)) continue;
                if (visit(order_[k])) return true;
            }
        }
        return false;
    }

    struct Node {
        AABB box;
        uint32_t index;  // leaf: first entry of order_; interior: the second child (the first is next)
        uint32_t count;  // items in a leaf, 0 for an interior node
    };

private:
    static constexpr int kMaxDepth = 60;  // the traversal stack holds kMaxDepth + 2 entries
    uint32_t build(const std::vector<AABB>& boxes, uint32_t begin, uint32_t end, int depth);

    std::vector<Node> nodes_;
    std::vector<uint32_t> order_;   // item indices, leaf by leaf
    std::vector<AABB> leaf_boxes_;  // their boxes, in the same order (no indirection in a leaf)
};

}  // namespace candela
