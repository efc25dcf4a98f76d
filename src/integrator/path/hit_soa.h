#pragma once
// Hit reconstruction for a batch of triangle hits in SoA form (the wavefront's first SIMD stage,
// work in progress on the `wavefront` branch). Lane i gets what Scene::interaction() gives for
// hit (prim[i], b1[i], b2[i]) on the scene's own mesh, bit for bit: p, p_error, ng, ns and the
// shape. Not uv, dpdu, dpdv: the diffuse-only, untextured scenes the wavefront serves first use none.
#include <cstddef>
#include <cstdint>
#include "geometry/mesh.h"

namespace candela {

struct HitBatch {
    const uint32_t* prim;
    const float* b1;
    const float* b2;
};
struct SurfaceBatch {
    float* p[3];
    float* p_error[3];
    float* ng[3];
    float* ns[3];
    uint32_t* shape;
};

// `smooth`: per shape, 1 when its shading normals are interpolated (Shape::smooth), else 0.
// `n` lanes; every array holds n rounded up to a multiple of kHitBatchAlign (the input's padding
// lanes must name a valid triangle, e.g. prim 0). Needs mesh.face_normals (build_scene fills them).
constexpr size_t kHitBatchAlign = 16;
void reconstruct_triangle_hits(const Mesh& mesh, const int32_t* smooth, size_t n, const HitBatch& in,
                               const SurfaceBatch& out);

}  // namespace candela
