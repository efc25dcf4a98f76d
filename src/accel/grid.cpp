#include "accel/grid.h"
#include <omp.h>
#include <algorithm>
#include <cmath>
#include "core/interrupt.h"

namespace candela {
namespace {

// The same relative slack as the k-d tree's traversal: a hit within rounding of a cell face may
// still be beaten by a triangle in the next cell, so the walk continues past it.
constexpr float kSlack = 1.f / 65536.f;
inline float widen_down(float t) { return t - kSlack * std::fabs(t); }

}  // namespace

HybridGridAccel::HybridGridAccel(const Mesh& mesh, const GridOptions& opt) : mesh_(&mesh) {
    const size_t n = mesh.triangles.size();
    if (n == 0) return;
    for (uint32_t i = 0; i < n; ++i) bounds_.expand(mesh.triangle_bounds(i));

    // Cubic cells with about tris_per_cell triangles each on average. Flat extents get a floor
    // (a thousandth of the largest) so that a planar scene still has a non-zero volume.
    vec3 ext = bounds_.extent();
    const float floor_ext = std::max(max_component(ext) * 1e-3f, 1e-30f);
    ext = glm::max(ext, vec3(floor_ext));
    const double cells_wanted = std::max(1.0, double(n) / double(opt.tris_per_cell));
    const double side = std::cbrt(double(ext.x) * ext.y * ext.z / cells_wanted);
    for (int a = 0; a < 3; ++a) {
        res_[a] = std::clamp(int(std::lround(ext[a] / side)), 1, opt.max_res);
        if (bounds_.extent()[a] == 0.f) res_[a] = 1;
        cell_[a] = bounds_.extent()[a] / float(res_[a]);
        inv_cell_[a] = cell_[a] > 0.f ? 1.f / cell_[a] : 0.f;
    }

    // Bin triangles by their bounds into the cells they may overlap; each cell's tree then clips
    // them to the cell and drops those that miss it.
    const size_t ncells = size_t(res_[0]) * res_[1] * res_[2];
    std::vector<std::vector<uint32_t>> bins(ncells);
    auto cell_of = [&](float x, int a) {
        return std::clamp(int((x - bounds_.min[a]) * inv_cell_[a]), 0, res_[a] - 1);
    };
    for (uint32_t i = 0; i < n; ++i) {
        if (i % 4096 == 0) throw_if_interrupted();
        AABB b = mesh.triangle_bounds(i);
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            // One cell further on each side when a bound lies on a cell face: the clip decides.
            lo[a] = std::max(cell_of(b.min[a], a) - 1, 0);
            hi[a] = std::min(cell_of(b.max[a], a) + 1, res_[a] - 1);
        }
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x) {
                    AABB cb = cell_box(x, y, z);
                    if (b.min.x <= cb.max.x && b.max.x >= cb.min.x && b.min.y <= cb.max.y && b.max.y >= cb.min.y &&
                        b.min.z <= cb.max.z && b.max.z >= cb.min.z)
                        bins[(size_t(z) * res_[1] + y) * res_[0] + x].push_back(i);
                }
    }

    cells_.assign(ncells, -1);
    std::vector<size_t> occupied;
    for (size_t c = 0; c < ncells; ++c)
        if (!bins[c].empty()) occupied.push_back(c);
    trees_.resize(occupied.size());
    KdBuildOptions kd = opt.kd;
    kd.parallel = false;  // parallel over cells instead
#pragma omp parallel for schedule(dynamic, 1)
    for (int64_t k = 0; k < int64_t(occupied.size()); ++k) {
        if (interrupt_requested()) continue;
        const size_t c = occupied[size_t(k)];
        const int x = int(c % res_[0]), y = int((c / res_[0]) % res_[1]), z = int(c / (size_t(res_[0]) * res_[1]));
        AABB cb = cell_box(x, y, z);
        trees_[size_t(k)].build(mesh, &bins[c], &cb, kd);
        std::vector<uint32_t>().swap(bins[c]);
    }
    throw_if_interrupted();  // the cells' builds stop early and only return inside the loop
    // Drop cells whose triangles all missed them after clipping.
    std::vector<KdTree> kept;
    for (size_t k = 0; k < occupied.size(); ++k) {
        if (trees_[k].empty()) continue;
        cells_[occupied[k]] = int32_t(kept.size());
        kept.push_back(std::move(trees_[k]));
    }
    trees_ = std::move(kept);
}

AABB HybridGridAccel::cell_box(int x, int y, int z) const {
    const int c[3] = {x, y, z};
    AABB b;
    for (int a = 0; a < 3; ++a) {
        // The last cell ends exactly at the bounds, whatever the rounding of res * cell size.
        b.min[a] = bounds_.min[a] + float(c[a]) * cell_[a];
        b.max[a] = c[a] + 1 == res_[a] ? bounds_.max[a] : bounds_.min[a] + float(c[a] + 1) * cell_[a];
    }
    return b;
}

size_t HybridGridAccel::memory_bytes() const {
    size_t bytes = cells_.capacity() * sizeof(int32_t) + trees_.capacity() * sizeof(KdTree);
    for (const KdTree& t : trees_) bytes += t.memory_bytes();
    return bytes;
}

template <bool Shadow>
bool HybridGridAccel::trace(Ray& ray, Hit* hit) const {
    if (trees_.empty()) return false;
    const float o[3] = {ray.o.x, ray.o.y, ray.o.z}, d[3] = {ray.d.x, ray.d.y, ray.d.z};
    const vec3 inv_d(1.f / ray.d.x, 1.f / ray.d.y, 1.f / ray.d.z);
    float t0, t1;
    if (!bounds_.intersect(ray, inv_d, t0, t1)) return false;

    // 3D-DDA (Amanatides and Woo): the cell of the entry point, then the ray parameter at which
    // the ray crosses the next cell face on each axis.
    int cell[3], step[3], stop[3];
    float next[3], delta[3];
    for (int a = 0; a < 3; ++a) {
        const float p = o[a] + t0 * d[a];
        cell[a] = std::clamp(int((p - bounds_.min[a]) * inv_cell_[a]), 0, res_[a] - 1);
        if (d[a] > 0.f) {
            step[a] = 1;
            stop[a] = res_[a];
            next[a] = (bounds_.min[a] + float(cell[a] + 1) * cell_[a] - o[a]) * inv_d[a];
            delta[a] = cell_[a] * inv_d[a];
        } else if (d[a] < 0.f) {
            step[a] = -1;
            stop[a] = -1;
            next[a] = (bounds_.min[a] + float(cell[a]) * cell_[a] - o[a]) * inv_d[a];
            delta[a] = -cell_[a] * inv_d[a];
        } else {
            step[a] = 0;
            stop[a] = -2;
            next[a] = kInfinity;
            delta[a] = 0.f;
        }
        if (res_[a] == 1) next[a] = kInfinity;  // a single slab: the box test already bounds it
    }

    bool found = false;
    for (;;) {
        const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
        const float exit = next[a];
        const int32_t ti = cells_[(size_t(cell[2]) * res_[1] + cell[1]) * res_[0] + cell[0]];
        if (ti >= 0) {
            if constexpr (Shadow) {
                if (trees_[size_t(ti)].occluded(ray)) return true;
            } else {
                if (trees_[size_t(ti)].intersect(ray, *hit)) found = true;
                if (found && ray.tmax < widen_down(exit)) return true;
            }
        }
        // Left the grid, or the next cell starts (within rounding) beyond tmax or the closest hit.
        if (!(exit < t1) || widen_down(exit) >= ray.tmax) return found;
        cell[a] += step[a];
        if (cell[a] == stop[a]) return found;
        next[a] += delta[a];
    }
}

bool HybridGridAccel::intersect(Ray& ray, Hit& hit) const { return trace<false>(ray, &hit); }

bool HybridGridAccel::occluded(const Ray& ray) const {
    Ray r = ray;
    return trace<true>(r, nullptr);
}

template bool HybridGridAccel::trace<false>(Ray&, Hit*) const;
template bool HybridGridAccel::trace<true>(Ray&, Hit*) const;

}  // namespace candela
