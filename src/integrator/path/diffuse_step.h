#pragma once
// A bounce on a diffuse surface for a batch of paths in SIMD lanes (the staged loop, wavefront.h):
// the shading, the light sample (area_light_step), the BSDF sample (cosine hemisphere), the
// throughput update, the next ray (spawn_ray) and Russian roulette. Lane i makes the float
// operations of the scalar loop (PathIntegrator::Li with shade, DiffuseBsdf::sample, Frame,
// offset_ray_origin, the roulette) in the same order, so every result is the same bit for bit. The
// MIS weight, the light sample's scale and the roulette's survival are the per-path bounce's own
// rules (path/rules.inc, compiled here per target).
#include <cstddef>
#include <cstdint>

namespace candela {

// The shading of a hit on a diffuse, untextured material (shade() in integrator/shading.h): wo
// from the ray's direction, the frame's normal turned to wo's side for a two-sided material (and
// the geometric normal with it), wo.z in that frame and the albedo.
struct ShadeDiffuseBatch {
    // In: the ray's direction (any length), the hit's shading and geometric normals and its shape.
    const float* ray_d[3];
    const float* ns[3];
    const float* ng[3];
    const uint32_t* shape;
    // Out: the frame's normal, the geometric normal turned with it, wo.z and the albedo.
    float* n[3];
    float* ng_out[3];
    float* wo_z;
    float* albedo[3];
};
// Per shape: `albedo` (3 floats) of its material and `two_sided` (1/0).
void shade_diffuse(size_t n, const float* albedo, const int32_t* two_sided, const ShadeDiffuseBatch& b);

struct DiffuseStepBatch {
    // In: the shading frame's normal (the frame is Frame(n), frame.h), wo.z, the albedo, the BSDF
    // sample's u2, the roulette's number, the surface point, its error and geometric normal.
    const float* n[3];
    const float* wo_z;
    const float* albedo[3];
    const float* u[2];
    const float* u_rr;
    bool rr;  // whether roulette applies (the same for every lane: one depth per round)
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
