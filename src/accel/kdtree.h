#pragma once
// SAH k-d tree over the triangles of a Mesh.
//
// Build: Wald and Havran 2006, "On building fast kd-trees for ray tracing, and on doing that in
// O(N log N)". Split candidates are the bounds of each triangle clipped to the node ("perfect
// splits"); the events are sorted once at the root and each node sweeps its own sorted list, then
// splits it into the children's lists without re-sorting (only the few straddling triangles are
// clipped and their new events sorted and merged). Subtrees are built in parallel (OpenMP tasks).
//
// Traversal (kdtree_trace.cpp): 8-byte nodes, a fixed-size stack, a template <bool Shadow> for the
// any-hit variant, compiled per SIMD target (Highway) and chosen at run time. Leaves hold their
// triangles' vertices in blocks of eight, laid out for the triangle test's vector lanes (a copy
// per leaf reference): one 8-lane step on AVX2, two 4-lane steps on SSE4 and NEON. Every triangle
// test is the watertight intersect_triangle() on the mesh's own vertex values, so a hit has the
// same t, bit for bit, as the brute-force oracle. Zero-area triangles, which it never hits, are
// left out at build.
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
    size_t nodes = 0, leaves = 0, empty_leaves = 0, references = 0;
    int max_depth = 0;
};

// Traversal counters for tuning, compiled in only with -DCANDELA_KD_COUNTERS (per thread; the
// benchmark prints them per ray). Without the flag they stay zero and cost nothing.
struct KdTraceCounters {
    uint64_t rays = 0, nodes = 0, leaves = 0, tris = 0;
};
KdTraceCounters& kd_trace_counters();

// The tree itself, without the Accel vtable: the hybrid grid holds one per cell.
class KdTree {
public:
    static constexpr int kMaxDepth = 60;  // the traversal stack holds kMaxDepth + 4 entries
    static constexpr uint32_t kMaxNodes = 1u << 28;  // node indices have 28 bits

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

    // Compact node: an interior node keeps the split position and the index of its first child
    // ("below" the plane; the "above" child follows it: siblings are adjacent). A leaf keeps its
    // triangle count and `first`, the index of its first TriBlock.
    struct Node {
        union {
            float split;
            uint32_t first;
        };
        // Low 2 bits: axis 0-2, or 3 for a leaf. A leaf keeps its count in the high 30 bits; an
        // interior node keeps two flags, "below is an empty leaf" (bit 2) and "above is an empty
        // leaf" (bit 3), and its first child's index in the high 28 bits. The flags let a ray
        // skip an empty child without loading it or stacking it: about half of the leaves are
        // empty (the SAH cuts empty space off), and a ray leaving a surface crosses several.
        uint32_t bits;
        bool leaf() const { return (bits & 3u) == 3u; }
        int axis() const { return int(bits & 3u); }
        uint32_t children() const { return bits >> 4; }
        uint32_t empty_child(int k) const { return (bits >> (2 + k)) & 1u; }  // k: 0 below, 1 above
        uint32_t count() const { return bits >> 2; }
    };
    static_assert(sizeof(Node) == 8, "k-d tree nodes are 8 bytes");

    // Eight triangles of a leaf, vertex coordinates by axis and lane (v[vertex][axis][lane]), so
    // that the SIMD filter loads them as they are (8 lanes, or two halves of 4); a leaf holds
    // ceil(count / 8) blocks, the last triangle repeated to fill the last one.
    static constexpr int kBlockLanes = 8;
    struct alignas(32) TriBlock {
        float v[3][3][kBlockLanes];
        uint32_t prim[kBlockLanes];
    };
    static_assert(sizeof(TriBlock) == 320, "a block is 8 triangles");

private:
    void interrupted_build();

    std::vector<Node> nodes_;
    std::vector<TriBlock> blocks_;  // the leaves' triangles, leaf by leaf
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
