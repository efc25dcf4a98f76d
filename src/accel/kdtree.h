#pragma once
// SAH k-d tree over the triangles of a Mesh.
//
// Build: Wald and Havran 2006, "On building fast kd-trees for ray tracing, and on doing that in
// O(N log N)". Split candidates are the bounds of each triangle clipped to the node ("perfect
// splits"); the events are sorted once at the root and each node sweeps its own sorted list, then
// splits it into the children's lists without re-sorting (only the few straddling triangles are
// clipped and their new events sorted and merged). Subtrees are built in parallel (OpenMP tasks).
//
// Layout and traversal (kdtree_trace.cpp): the binary tree is collapsed into nodes of up to eight
// children, each boxed by what it holds, so that one vector step (8 lanes on AVX2, two of 4 on
// SSE4 and NEON) tests all of a node's children and a ray takes a few wide steps instead of one
// binary step per level; the SAH build, the leaves and the exact triangle test are the k-d
// tree's. Empty leaves vanish; a large leaf's triangles are split into groups that take the lanes
// left free, each under its own box, and a tree that is one leaf (a small scene) may be grouped
// into lanes as a BVH would group it. Traversal keeps a fixed stack, visits the children hit nearest first and skips
// those beyond the closest hit; a template <bool Shadow> is the any-hit variant. It is compiled
// per SIMD target (Highway) and chosen at run time. Leaves hold their triangles' vertices in
// blocks of eight, laid out for the triangle test's lanes (a copy per leaf reference). Every
// triangle test is the watertight intersect_triangle() on the mesh's own vertex values, so a hit
// has the same t, bit for bit, as the brute-force oracle. Zero-area triangles, which it never
// hits, are left out at build.
#include <cstdint>
#include <vector>
#include "accel/accel.h"
#include "core/aabb.h"
#include "core/interrupt.h"

namespace candela {

struct KdBuildOptions {
    // Surface area heuristic: cost = traversal + intersection * (P_left N_left + P_right N_right),
    // times (1 - empty_bonus) when one side is empty. Units: one triangle test = intersection.
    // A triangle costs a tenth of a node step: leaves are tested eight at a time by the SIMD
    // filter, while a node step is a dependent load and a branch (sweep in docs/accel.md: 0.3 suited
    // blocks of four; with eight, 0.06-0.15 are within a few percent of each other).
    float traversal_cost = 1.f;
    float intersection_cost = 0.1f;
    float empty_bonus = 0.1f;
    int max_stalls = 3;        // consecutive splits that keep all triangles on one side (see .cpp)
    int max_depth = -1;        // -1: 8 + 1.3 log2(N), capped by the traversal stack
    bool parallel = true;      // OpenMP tasks (ignored when already inside a parallel region)
};

struct KdTreeStats {
    size_t nodes = 0, leaves = 0, empty_leaves = 0, references = 0;  // of the binary tree built
    size_t wide_nodes = 0;                                             // after collapsing it
    size_t leaf_lanes = 0;  // wide-node lanes holding leaf triangles: a leaf split into groups takes several
    int max_depth = 0;
};

// Traversal counters for tuning (`nodes` counts wide nodes), compiled in only with
// -DCANDELA_KD_COUNTERS (per thread; the benchmark prints them per ray). Without the flag they
// stay zero and cost nothing.
struct KdTraceCounters {
    uint64_t rays = 0, nodes = 0, leaves = 0, tris = 0;
};
KdTraceCounters& kd_trace_counters();

// The tree itself, without the Accel vtable: the hybrid grid holds one per cell.
class KdTree {
public:
    static constexpr int kMaxDepth = 60;  // of the binary tree; bounds the traversal stack
    static constexpr uint32_t kMaxNodes = 1u << 31;  // wide nodes, and triangle blocks

    KdTree() = default;
    // Builds over triangles `tris` of `mesh` (all of them when tris is null). When `clip` is given,
    // every triangle is clipped to it first: the tree then covers only the part of space inside
    // `clip` (used by the grid, whose cells each hold a tree). Polls interrupt_requested()
    // (core/interrupt.h) per node: once it is set the build stops and leaves the tree empty. It
    // never throws Interrupted itself (it may run inside an OpenMP region, which an exception
    // must not leave): the caller calls throw_if_interrupted() afterwards.
    void build(const Mesh& mesh, const std::vector<uint32_t>* tris = nullptr, const AABB* clip = nullptr,
               const KdBuildOptions& opt = {});

    // Closest hit in (ray.tmin, ray.tmax); shrinks ray.tmax. Same contract as Accel::intersect.
    bool intersect(Ray& ray, Hit& hit) const;
    bool occluded(const Ray& ray) const;

    const AABB& bounds() const { return bounds_; }
    bool empty() const { return nodes_.empty(); }
    size_t memory_bytes() const;
    const KdTreeStats& stats() const { return stats_; }

    // Eight triangles of a leaf, vertex coordinates by axis and lane (v[vertex][axis][lane]), so
    // that the SIMD filter loads them as they are (8 lanes, or two halves of 4); a leaf holds
    // ceil(count / 8) blocks, the last triangle repeated to fill the last one.
    static constexpr int kBlockLanes = 8;
    struct alignas(64) TriBlock {
        float v[3][3][kBlockLanes];
        uint32_t prim[kBlockLanes];
    };
    static_assert(sizeof(TriBlock) == 320, "a block is 8 triangles");

    // Up to eight subtrees (or leaves) of the binary tree as one node, each child boxed by what
    // it holds: the union over its leaves of the part of their triangles inside their cells
    // (clipped, rounded outwards). Boxes by axis and lane (lo[axis][lane]), so that one 8-lane
    // step (two of 4) tests them all; an unused lane has an empty box (+inf, -inf), which no ray
    // enters. Node 0 is the root.
    static constexpr uint32_t kWideInterior = 0xffffffffu;
    struct alignas(64) WideNode {
        float lo[3][kBlockLanes], hi[3][kBlockLanes];
        uint32_t child[kBlockLanes];  // a WideNode index, or a leaf's first TriBlock
        uint32_t count[kBlockLanes];  // kWideInterior, or the leaf's triangle count (0: unused lane)
    };
    static_assert(sizeof(WideNode) == 256, "a wide node is four cache lines");

private:
    void interrupted_build();

    std::vector<WideNode> nodes_;
    std::vector<TriBlock> blocks_;  // the leaves' triangles, leaf by leaf
    bool root_leaf_ = false;        // the tree is one leaf: its box test is the root box's
    AABB bounds_;
    KdTreeStats stats_;
};

class KdTreeAccel final : public Accel {
public:
    explicit KdTreeAccel(const Mesh& mesh, const KdBuildOptions& opt = {}) : mesh_(&mesh) {
        tree_.build(mesh, nullptr, nullptr, opt);
        throw_if_interrupted();
    }
    bool intersect(Ray& ray, Hit& hit) const override { return tree_.intersect(ray, hit); }
    bool occluded(const Ray& ray) const override { return tree_.occluded(ray); }
    std::string name() const override { return "kdtree"; }
    size_t memory_bytes() const override { return tree_.memory_bytes(); }
    const KdTree& tree() const { return tree_; }

private:
    const Mesh* mesh_;
    KdTree tree_;
};

}  // namespace candela
