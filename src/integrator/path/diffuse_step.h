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

// The light sample of a bounce on a diffuse surface, with area lights that are emissive triangles
// only (LightSet::area_triangle_tables): the light sample (LightSet::sample_li), the BSDF's value
// and pdf there, the MIS weight against BSDF sampling (`mis`; else 1), the shadow ray
// (spawn_ray_to) and what the sample adds when nothing is in the way, as Li computes them.
struct AreaLightStepBatch {
    // In: the light sample's numbers (u_l chooses the triangle, u picks the point), the surface
    // point, its error and geometric normal, the shading normal, wo.z, the albedo, the throughput.
    const float* u_l;
    const float* u[2];
    const float* p[3];
    const float* p_error[3];
    const float* ng[3];
    const float* n[3];  // the shading normal: the diffuse BSDF needs only cos theta of wi
    const float* wo_z;
    const float* albedo[3];
    const float* beta[3];
    // Out: whether there is a shadow ray (1/0), its origin and direction (tmax 1 - kShadowEpsilon),
    // and the radiance it adds when unoccluded.
    int32_t* shadow;
    float* o[3];
    float* d[3];
    float* L[3];
};
// The tables: LightSet::AreaTriangleTables (light/area.h), passed as plain pointers.
void area_light_step(size_t n, const float* cdf, const float* tri, const float* radiance, size_t entries, bool mis,
                     const AreaLightStepBatch& b);

}  // namespace candela
