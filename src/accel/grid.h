#pragma once
// The hybrid: a uniform grid over the scene whose non-empty cells each hold a k-d tree of the
// triangles overlapping the cell (clipped to it, so each tree covers only its cell). A ray walks
// the cells front to back with a 3D-DDA and asks each cell's tree; it stops at the first cell
// whose closest hit lies inside the cell. The grid skips empty space in O(1) per cell, which pays
// when a few dense objects sit far apart in a large, sparse scene; docs/accel.md has the numbers.
#include <vector>
#include "accel/kdtree.h"

namespace candela {

struct GridOptions {
    // Resolution: cells of equal size, about tris_per_cell triangles per cell on average (from the
    // triangle count and the bounds), at most max_res cells per axis.
    float tris_per_cell = 2048.f;
    int max_res = 64;
    KdBuildOptions kd;
};

class HybridGridAccel final : public Accel {
public:
    explicit HybridGridAccel(const Mesh& mesh, const GridOptions& opt = {});
    bool intersect(Ray& ray, Hit& hit) const override;
    bool occluded(const Ray& ray) const override;
    std::string name() const override { return "hybrid"; }
    size_t memory_bytes() const override;
    const int* resolution() const { return res_; }
    size_t occupied_cells() const { return trees_.size(); }

private:
    template <bool Shadow>
    bool trace(Ray& ray, Hit* hit) const;
    AABB cell_box(int x, int y, int z) const;

    const Mesh* mesh_;
    AABB bounds_;
    int res_[3] = {0, 0, 0};
    float cell_[3] = {0.f, 0.f, 0.f};      // cell size per axis
    float inv_cell_[3] = {0.f, 0.f, 0.f};
    std::vector<int32_t> cells_;           // index into trees_, or -1 for an empty cell
    std::vector<KdTree> trees_;
};

}  // namespace candela
