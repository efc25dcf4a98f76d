#include "accel/instances.h"
#include <algorithm>
#include "accel/with_analytic.h"

namespace candela {

namespace {
constexpr int kMaxDepth = 60;  // the traversal stack holds kMaxDepth + 2 entries
}

InstanceAccel::InstanceAccel(std::unique_ptr<Accel> base, const std::vector<ShapeGroup>& groups,
                             const std::vector<Instance>& instances, const std::string& accel_name)
    : base_(std::move(base)), instances_(&instances) {
    for (const ShapeGroup& g : groups) {
        std::unique_ptr<Accel> a = make_accel(accel_name, g.mesh);
        if (!g.analytic.empty()) a = std::make_unique<WithAnalyticAccel>(std::move(a), g.analytic);
        group_accels_.push_back(std::move(a));
    }
    order_.resize(instances.size());
    for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
    if (!order_.empty()) {
        nodes_.reserve(2 * order_.size());
        build(0, uint32_t(order_.size()), 0);
    }
}

// Binary SAH over the box centroids along their widest axis (sorted, then swept): cost of a split
// = SA(left) N(left) + SA(right) N(right), against SA(node) N(node) for a leaf.
uint32_t InstanceAccel::build(uint32_t begin, uint32_t end, int depth) {
    const std::vector<Instance>& inst = *instances_;
    uint32_t me = uint32_t(nodes_.size());
    nodes_.push_back(Node{});
    AABB box, cbox;
    for (uint32_t i = begin; i < end; ++i) {
        box.expand(inst[order_[i]].bounds);
        cbox.expand(inst[order_[i]].bounds.center());
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
        float ca = inst[a].bounds.center()[axis], cb = inst[b].bounds.center()[axis];
        return ca < cb || (ca == cb && a < b);
    });
    std::vector<float> right_area(n);
    AABB acc;
    for (uint32_t k = n; k-- > 1;) {
        acc.expand(inst[order_[begin + k]].bounds);
        right_area[k] = acc.surface_area();
    }
    acc = AABB();
    float best = kInfinity;
    uint32_t split = begin + n / 2;
    for (uint32_t k = 1; k < n; ++k) {
        acc.expand(inst[order_[begin + k - 1]].bounds);
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
    build(begin, split, depth + 1);
    uint32_t right = build(split, end, depth + 1);
    nodes_[me].index = right;
    nodes_[me].count = 0;
    return me;
}

template <bool Shadow>
bool InstanceAccel::trace(Ray& ray, Hit* hit) const {
    bool found = false;
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
            const uint32_t id = order_[k];
            const Instance& in = (*instances_)[id];
            if (node.count > 1 && !in.bounds.intersect(ray, inv_d, t0, t1)) continue;
            Ray local;
            local.o = vec3(in.to_object * glm::vec4(ray.o, 1.f));
            local.d = glm::mat3(in.to_object) * ray.d;
            local.tmin = ray.tmin;
            local.tmax = ray.tmax;
            const Accel& a = *group_accels_[in.group];
            if (Shadow) {
                if (a.occluded(local)) return true;
                continue;
            }
            Hit h;
            if (a.intersect(local, h)) {
                ray.tmax = local.tmax;
                h.instance = id;
                *hit = h;
                found = true;
            }
        }
    }
    return found;
}

bool InstanceAccel::intersect(Ray& ray, Hit& hit) const {
    bool found = base_ && base_->intersect(ray, hit);
    return trace<false>(ray, &hit) || found;
}

bool InstanceAccel::occluded(const Ray& ray) const {
    if (base_ && base_->occluded(ray)) return true;
    Ray r = ray;
    return trace<true>(r, nullptr);
}

size_t InstanceAccel::memory_bytes() const {
    size_t b = (base_ ? base_->memory_bytes() : 0) + nodes_.capacity() * sizeof(Node) +
               order_.capacity() * sizeof(uint32_t);
    for (const auto& a : group_accels_) b += a->memory_bytes();
    return b;
}

}  // namespace candela
