// Hit reconstruction in SIMD lanes (see hit_soa.h). Each lane makes triangle_interaction()'s
// (scene/scene.cpp) float operations in its order: Mul then Add, never MulAdd (the build has
// -ffp-contract=off), abs as clearing the sign bit, and ns = n / sqrt(dot(n, n)) as glm divides.
#include "integrator/path/hit_soa.h"

// As in accel/kdtree_trace.cpp: no AVX-512 code (8 lanes of AVX2 suffice for these gathers).
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_AVX3 | HWY_AVX3_DL)
#endif
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "integrator/path/hit_soa.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace candela {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

void ReconstructTriangleHits(const Mesh& mesh, const int32_t* smooth, size_t n, const HitBatch& in,
                             const SurfaceBatch& out) {
    const hn::ScalableTag<float> d;
    const hn::RebindToSigned<decltype(d)> di;
    using VF = hn::Vec<decltype(d)>;
    using VI = hn::Vec<decltype(di)>;
    const size_t lanes = hn::Lanes(d);
    const float* pos = &mesh.positions[0].x;
    const float* fn = &mesh.face_normals[0].x;
    const float* nrm = mesh.normals.empty() ? nullptr : &mesh.normals[0].x;
    const int32_t* tri = reinterpret_cast<const int32_t*>(&mesh.triangles[0].x);
    const int32_t* tri_shape = reinterpret_cast<const int32_t*>(mesh.tri_shape.data());
    const VI three = hn::Set(di, 3);
    const VF one = hn::Set(d, 1.f), zero = hn::Zero(d);
    const VF gamma7 = hn::Set(d, gamma_bound(7));
    for (size_t i = 0; i < n; i += lanes) {
        const VI prim = hn::BitCast(di, hn::LoadU(hn::RebindToUnsigned<decltype(d)>(), in.prim + i));
        const VI t3 = hn::Mul(prim, three);
        const VI v3[3] = {hn::Mul(hn::GatherIndex(di, tri, t3), three),
                          hn::Mul(hn::GatherIndex(di, tri + 1, t3), three),
                          hn::Mul(hn::GatherIndex(di, tri + 2, t3), three)};
        const VF b1 = hn::LoadU(d, in.b1 + i), b2 = hn::LoadU(d, in.b2 + i);
        const VF b0 = hn::Sub(hn::Sub(one, b1), b2);
        VF ng[3];
        for (int k = 0; k < 3; ++k) {
            const VF a = hn::Mul(b0, hn::GatherIndex(d, pos + k, v3[0]));
            const VF b = hn::Mul(b1, hn::GatherIndex(d, pos + k, v3[1]));
            const VF c = hn::Mul(b2, hn::GatherIndex(d, pos + k, v3[2]));
            hn::StoreU(hn::Add(hn::Add(a, b), c), d, out.p[k] + i);
            hn::StoreU(hn::Mul(gamma7, hn::Add(hn::Add(hn::Abs(a), hn::Abs(b)), hn::Abs(c))), d, out.p_error[k] + i);
            ng[k] = hn::GatherIndex(d, fn + k, t3);
            hn::StoreU(ng[k], d, out.ng[k] + i);
        }
        const VI shape = hn::GatherIndex(di, tri_shape, prim);
        hn::StoreU(hn::BitCast(hn::RebindToUnsigned<decltype(d)>(), shape), hn::RebindToUnsigned<decltype(d)>(),
                   out.shape + i);
        const auto is_smooth = hn::RebindMask(d, hn::Ne(hn::GatherIndex(di, smooth, shape), hn::Zero(di)));
        if (nrm && !hn::AllFalse(d, is_smooth)) {
            VF nv[3];
            for (int k = 0; k < 3; ++k) {
                const VF a = hn::Mul(b0, hn::GatherIndex(d, nrm + k, v3[0]));
                const VF b = hn::Mul(b1, hn::GatherIndex(d, nrm + k, v3[1]));
                const VF c = hn::Mul(b2, hn::GatherIndex(d, nrm + k, v3[2]));
                nv[k] = hn::Add(hn::Add(a, b), c);
            }
            const VF l2 = hn::Add(hn::Add(hn::Mul(nv[0], nv[0]), hn::Mul(nv[1], nv[1])), hn::Mul(nv[2], nv[2]));
            const auto ok = hn::And(is_smooth, hn::And(hn::Gt(l2, zero), hn::IsFinite(l2)));
            const VF len = hn::Sqrt(l2);
            for (int k = 0; k < 3; ++k) hn::StoreU(hn::IfThenElse(ok, hn::Div(nv[k], len), ng[k]), d, out.ns[k] + i);
        } else {
            for (int k = 0; k < 3; ++k) hn::StoreU(ng[k], d, out.ns[k] + i);
        }
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace candela
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace candela {

HWY_EXPORT(ReconstructTriangleHits);

void reconstruct_triangle_hits(const Mesh& mesh, const int32_t* smooth, size_t n, const HitBatch& in,
                               const SurfaceBatch& out) {
    HWY_DYNAMIC_DISPATCH(ReconstructTriangleHits)(mesh, smooth, n, in, out);
}

}  // namespace candela
#endif  // HWY_ONCE
