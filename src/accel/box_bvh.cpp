#include "accel/box_bvh.h"
#include <algorithm>

namespace candela {

void BoxBvh::build(const std::vector<AABB>& boxes) {
    nodes_.clear();
    order_.resize(boxes.size());
    for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
    if (!order_.empty()) {
        nodes_.reserve(2 * order_.size());
        build(boxes, 0, uint32_t(order_.size()), 0);
    }
    leaf_boxes_.resize(order_.size());
    for (size_t k = 0; k < order_.size(); ++k) leaf_boxes_[k] = boxes[order_[k]];
}

// Binary SAH over the box centroids along their widest axis (sorted, then swept): cost of a split
// = SA(left) N(left) + SA(right) N(right), against SA(node) N(node) for a leaf.
uint32_t BoxBvh::build(const std::vector<AABB>& boxes, uint32_t begin, uint32_t end, int depth) {
    uint32_t me = uint32_t(nodes_.size());
    nodes_.push_back(Node{});
    AABB box, cbox;
    for (uint32_t i = begin; i < end; ++i) {
        box.expand(boxes[order_[i]]);
        cbox.expand(boxes[order_[i]].center());
    }
    nodes_[me].box = box;
    const uint32_t n = end - begin;
    vec3 ext = cbox.extent();
    int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    if (n <= 2 || depth >= kMaxDepth || !(ext[axis] > 0.f)) {
        nodes_[me].index = begin;
        nodes_[me].count = n;
        return me;
    }
    // Sort by centroid, ties by index: the tree (and so the image) does not depend on std::sort's
    // choices.
    std::sort(order_.begin() + begin, order_.begin() + end, [&](uint32_t a, uint32_t b) {
        float ca = boxes[a].center()[axis], cb = boxes[b].center()[axis];
        return ca < cb || (ca == cb && a < b);
    });
    std::vector<float> right_area(n);
    AABB acc;
    for (uint32_t k = n; k-- > 1;) {
        acc.expand(boxes[order_[begin + k]]);
        right_area[k] = acc.surface_area();
    }
    acc = AABB();
    float best = kInfinity;
    uint32_t split = begin + n / 2;
    for (uint32_t k = 1; k < n; ++k) {
        acc.expand(boxes[order_[begin + k - 1]]);
        float cost = acc.surface_area() * float(k) + right_area[k] * float(n - k);
        if (cost < best) {
            best = cost;
            split = begin + k;
        }
    }
    if (n <= 4 && best >= box.surface_area() * float(n)) {
        nodes_[me].index = begin;
        nodes_[me].count = n;
        return me;
    }
    build(boxes, begin, split, depth + 1);
    uint32_t right = build(boxes, split, end, depth + 1);
    nodes_[me].index = right;
    nodes_[me].count = 0;
    return me;
}

}  // namespace candela
