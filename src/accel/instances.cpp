#include "accel/instances.h"
#include "accel/with_analytic.h"

namespace candela {

InstanceAccel::InstanceAccel(std::unique_ptr<Accel> base, const std::vector<ShapeGroup>& groups,
                             const std::vector<Instance>& instances, const std::string& accel_name)
    : base_(std::move(base)), instances_(&instances) {
    for (const ShapeGroup& g : groups) {
        std::unique_ptr<Accel> a = make_accel(accel_name, g.mesh);
        if (!g.analytic.empty()) a = std::make_unique<WithAnalyticAccel>(std::move(a), g.analytic);
        group_accels_.push_back(std::move(a));
    }
    std::vector<AABB> boxes;
    boxes.reserve(instances.size());
    for (const Instance& in : instances) boxes.push_back(in.bounds);
    bvh_.build(boxes);
}

Ray InstanceAccel::to_group(const Ray& ray, uint32_t id) const {
    const Instance& in = (*instances_)[id];
    Ray local;
    local.o = vec3(in.to_object * glm::vec4(ray.o, 1.f));
    local.d = glm::mat3(in.to_object) * ray.d;
    local.tmin = ray.tmin;
    local.tmax = ray.tmax;
    return local;
}

bool InstanceAccel::intersect(Ray& ray, Hit& hit) const {
    bool found = base_ && base_->intersect(ray, hit);
    bvh_.traverse(ray, [&](uint32_t id) {
        Ray local = to_group(ray, id);
        Hit h;
        if (group_accels_[(*instances_)[id].group]->intersect(local, h)) {
            ray.tmax = local.tmax;  // t is the same in both spaces (d' is not renormalised)
            h.instance = id;
            hit = h;
            found = true;
        }
        return false;
    });
    return found;
}

bool InstanceAccel::occluded(const Ray& ray) const {
    if (base_ && base_->occluded(ray)) return true;
    return bvh_.traverse(ray, [&](uint32_t id) {
        return group_accels_[(*instances_)[id].group]->occluded(to_group(ray, id));
    });
}

size_t InstanceAccel::memory_bytes() const {
    size_t b = (base_ ? base_->memory_bytes() : 0) + bvh_.memory_bytes();
    for (const auto& a : group_accels_) b += a->memory_bytes();
    return b;
}

}  // namespace candela
