#pragma once
// The triangle accelerator plus the scene's analytic shapes (spheres, disks, cylinders), queried
// after it: the triangles' closest hit shrinks ray.tmax, so a shape only wins when it is nearer.
// Built only for scenes that have analytic shapes; a scene of triangles gets the triangle
// accelerator itself and pays nothing. The shapes are tested one after the other: the published
// scenes hold a handful (a BVH over them is the next step when a scene holds hundreds).
#include <memory>
#include <vector>
#include "accel/accel.h"
#include "geometry/analytic.h"

namespace candela {

class WithAnalyticAccel final : public Accel {
public:
    // `shapes` must outlive the accelerator (both live in the scene's Geometry).
    WithAnalyticAccel(std::unique_ptr<Accel> triangles, const std::vector<AnalyticShape>& shapes)
        : tris_(std::move(triangles)), shapes_(&shapes) {}

    bool intersect(Ray& ray, Hit& hit) const override {
        bool found = tris_->intersect(ray, hit);
        if (found) hit.kind = PrimKind::Triangle;
        for (uint32_t i = 0; i < uint32_t(shapes_->size()); ++i)
            if (intersect_analytic((*shapes_)[i], ray, hit)) {
                hit.prim = i;
                found = true;
            }
        return found;
    }
    bool occluded(const Ray& ray) const override {
        for (const AnalyticShape& s : *shapes_)
            if (occluded_analytic(s, ray)) return true;
        return tris_->occluded(ray);
    }
    std::string name() const override { return tris_->name(); }
    size_t memory_bytes() const override { return tris_->memory_bytes(); }
    const Accel& triangles() const { return *tris_; }

private:
    std::unique_ptr<Accel> tris_;
    const std::vector<AnalyticShape>* shapes_;
};

}  // namespace candela
