#pragma once
// The end of a bounce on a diffuse surface for a batch of paths in SIMD lanes (wavefront branch,
// work in progress): the BSDF sample (cosine hemisphere), the throughput update, the next ray
// (spawn_ray) and Russian roulette. Lane i makes the float operations of the scalar loop
// (PathIntegrator::Li with DiffuseBsdf::sample, Frame::to_world, offset_ray_origin, the roulette)
// in the same order, so every result is the same bit for bit.
#include <cstddef>
#include <cstdint>

namespace candela {

struct DiffuseStepBatch {
    // In: the shading frame (s, t, n), wo.z, the albedo, the BSDF sample's u2, the roulette's
    // number and whether roulette applies (1/0), the surface point, its error and geometric normal.
    const float* s[3];
    const float* t[3];
    const float* n[3];
    const float* wo_z;
    const float* albedo[3];
    const float* u[2];
    const float* u_rr;
    const int32_t* rr;
    const float* eta_scale;
    const float* p[3];
    const float* p_error[3];
    const float* ng[3];
    // In and out: the throughput. Out: the BSDF pdf, the next ray's origin and direction, and
    // whether the path goes on (1/0).
    float* beta[3];
    float* pdf;
    float* o[3];
    float* d[3];
    int32_t* alive;
};

// `n` lanes; every array holds n rounded up to a multiple of kDiffuseStepAlign (padding lanes are
// computed and ignored: any finite values).
constexpr size_t kDiffuseStepAlign = 16;
void diffuse_step(size_t n, const DiffuseStepBatch& b);

}  // namespace candela
