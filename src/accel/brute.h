#pragma once
#include "accel/accel.h"

namespace candela {

// Tests every triangle: O(N) per ray. The oracle that the k-d tree and the grid are tested against.
class BruteForceAccel final : public Accel {
public:
    explicit BruteForceAccel(const Mesh& mesh) : mesh_(&mesh) {}
    bool intersect(Ray& ray, Hit& hit) const override;
    bool occluded(const Ray& ray) const override;
    std::string name() const override { return "brute"; }
    size_t memory_bytes() const override { return 0; }

private:
    const Mesh* mesh_;
};

}  // namespace candela
