#pragma once
// Two-level accelerator for instancing: the scene's own accelerator (triangles, and analytic shapes
// when there are any), one accelerator per shapegroup built once in group space (the k-d tree, or
// whatever --accel names), and a BVH over the instances' world boxes on top.
//
// Why a BVH on top and not a second k-d tree: instance boxes overlap freely (a forest, a row of
// chairs), and a k-d tree references an overlapping box in every cell it straddles, where a BVH
// stores each instance exactly once, so the top level's memory is linear in the instance count and
// a ray tests each instance at most once. The top level is small (one node per one or two
// instances) and its cost per ray is a few box tests; the group trees do the real work.
//
// Contract: a ray is carried into group space as o' = to_object o, d' = to_object d (d' is not
// renormalised), so t means the same thing in both spaces and a group's hit shrinks the world
// ray's tmax directly. A hit inside an instance has Hit::instance set and prim/kind/local in
// group space (Scene::interaction takes them to world space).
// Built only for scenes that have instances: a scene without them never sees this class.
#include <memory>
#include <vector>
#include "accel/accel.h"
#include "accel/box_bvh.h"
#include "geometry/instance.h"

namespace candela {

class InstanceAccel final : public Accel {
public:
    // `base` may be null (a scene of instances only). `groups` and `instances` must outlive the
    // accelerator (they live in the scene's Geometry). Group accelerators are made by `accel_name`.
    InstanceAccel(std::unique_ptr<Accel> base, const std::vector<ShapeGroup>& groups,
                  const std::vector<Instance>& instances, const std::string& accel_name);

    bool intersect(Ray& ray, Hit& hit) const override;
    bool occluded(const Ray& ray) const override;
    std::string name() const override { return base_ ? base_->name() : group_accels_.empty() ? "none" : group_accels_[0]->name(); }
    // The base and group accelerators plus the top-level BVH (not the meshes).
    size_t memory_bytes() const override;

private:
    // The ray carried into instance `id`'s group space.
    Ray to_group(const Ray& ray, uint32_t id) const;

    std::unique_ptr<Accel> base_;
    std::vector<std::unique_ptr<Accel>> group_accels_;
    const std::vector<Instance>* instances_;
    BoxBvh bvh_;  // over the instances' world boxes
};

}  // namespace candela
