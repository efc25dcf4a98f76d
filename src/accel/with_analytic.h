#pragma once
// The triangle accelerator plus the scene's analytic shapes (spheres, disks, cylinders), queried
// after it: the triangles' closest hit shrinks ray.tmax, so a shape only wins when it is nearer.
// Built only for scenes that have analytic shapes; a scene of triangles gets the triangle
// accelerator itself and pays nothing. The shapes sit in a BVH over their boxes (accel/box_bvh.h),
// so a scene of thousands of spheres costs a few box tests per ray, not a test per sphere.
#include <memory>
#include <vector>
#include "accel/accel.h"
#include "accel/box_bvh.h"
#include "geometry/analytic.h"

namespace candela {

class WithAnalyticAccel final : public Accel {
public:
    // `shapes` must outlive the accelerator (both live in the scene's Geometry).
    WithAnalyticAccel(std::unique_ptr<Accel> triangles, const std::vector<AnalyticShape>& shapes)
        : tris_(std::move(triangles)), shapes_(&shapes) {
        std::vector<AABB> boxes;
        boxes.reserve(shapes.size());
        for (const AnalyticShape& s : shapes) boxes.push_back(s.bounds());
        bvh_.build(boxes);
    }

    bool intersect(Ray& ray, Hit& hit) const override {
        bool found = tris_->intersect(ray, hit);
        if (found) hit.kind = PrimKind::Triangle;
        bvh_.traverse(ray, [&](uint32_t i) {
            if (intersect_analytic((*shapes_)[i], ray, hit)) {  // shrinks ray.tmax
                hit.prim = i;
                found = true;
            }
            return false;
        });
        return found;
    }
    bool occluded(const Ray& ray) const override {
        if (bvh_.traverse(ray, [&](uint32_t i) { return occluded_analytic((*shapes_)[i], ray); })) return true;
        return tris_->occluded(ray);
    }
    std::string name() const override { return tris_->name(); }
    size_t memory_bytes() const override { return tris_->memory_bytes() + bvh_.memory_bytes(); }
    const Accel& triangles() const { return *tris_; }

private:
    std::unique_ptr<Accel> tris_;
    const std::vector<AnalyticShape>* shapes_;
    BoxBvh bvh_;
};

}  // namespace candela
