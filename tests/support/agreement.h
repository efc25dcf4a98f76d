#pragma once
// Shared by the integrator agreement tests (tests/test_bdpt.cpp, test_ptracer.cpp,
// test_furnace.cpp): batch rendering with independent seeds, the block and whole-image z-tests of
// one integrator against another with the 3% brighter control, and the analytic furnace scene.
#include <memory>
#include <string>
#include <vector>
#include "render/renderer.h"
#include "scene/scene.h"
#include "support/stats.h"

namespace candela::test {

// K films of `spp` samples each of `scene` with the parameters `p` (integrator included), seeds
// base + 1 .. base + K, 2 threads; the estimate from the spread of the batch means.
stats::ImageEstimate render_batches(const Scene& scene, const SceneParams& p, int K, int spp, uint64_t base);

// Every mean scaled by s (variances by s^2): the controls.
stats::ImageEstimate scaled(stats::ImageEstimate e, double s);

// a against b: block z-test (4 x 4 blocks) and whole-image z-test at alpha Sidak-corrected over
// `tests`, printed; with `control`, the image a 3% brighter must be rejected by the whole-image test.
void expect_agreement(const stats::ImageEstimate& a, const stats::ImageEstimate& b, const std::string& what, int tests,
                      bool control, double alpha = 0.01);

// ---- the furnace ----------------------------------------------------------------------------
// The camera inside a closed sphere whose inside is diffuse with albedo kFurnaceAlbedo and emits
// Le = 1: L = Le (1 - a^(d+1)) / (1 - a) with at most d scattering events, Le / (1 - a) unbounded.
inline const glm::vec3 kFurnaceAlbedo(0.5f, 0.8f, 0.f);

// Unit icosphere with `subdiv` subdivisions, wound so that cross(p1-p0, p2-p0) points INTO the
// sphere: the diffuse BSDF and the emitter are one-sided and must face the camera inside.
void icosphere(int subdiv, std::vector<glm::dvec3>& v, std::vector<glm::uvec3>& f);

double furnace_exact(double a, double Le, int depth);

struct FurnaceConfig {
    IntegratorType integrator = IntegratorType::Path;
    SamplingMode mode = SamplingMode::Mis;
    int max_depth = -1;
    double radius = 1.0;
    glm::dvec3 center{0.0};
    int spp = 64;
    uint64_t seed = 0;
    int res = 16;
};

// The furnace (one subdivision, 16 x 16 by default, a 90 degree camera at the centre looking +z).
std::unique_ptr<SceneDescription> furnace_description(const FurnaceConfig& c);

// Renders the furnace (c.spp samples, 2 threads) and z-tests the mean over the pixel means of each
// channel against the exact value at `level`, with the 3%-off control rejected at the same level
// and the standard error below 1% of the value; printed. Returns the z statistics per channel.
glm::dvec3 expect_furnace_exact(const FurnaceConfig& c, double level);

// ---- a smooth-shaded emitter ----------------------------------------------------------------
// A 20-face ball light (the icosahedron, radius 0.7, radiance 4) with the vertex normals of the
// sphere it approximates, in a diffuse box open at the front and the top (floor, back wall, a red
// left wall, a green right wall), res x res pixels. The emitter's shading normals differ from its
// geometric ones by up to 37 degrees: what tells apart the normal conventions of the strategies
// that start or end on it (docs/bdpt.md).
SceneDescription smooth_ball_description(int res);
// The same box lit instead by a 1.2 x 1.2 square lamp under its open top (y = 4, facing down, the
// radiance 8), whose vertex normals are all tilted by 40 degrees towards +x: emission on the
// shading normals' side, but the surface is flat, so the emitted power follows the geometric
// cosine (what a ray hitting the lamp sees), not the shading one.
SceneDescription tilted_lamp_description(int res);

// ---- filtered splats ------------------------------------------------------------------------
// A diffuse wall filling the left half of the view of a camera at z = 4 (its edge, x = 0, on the
// image's middle column, a 4 x 4 block boundary when res is a multiple of 8), nothing on the
// right, lit by a small lamp in front of it (its black back in view) aimed at the edge. Near the
// edge BDPT's t = 1 strategies take most of the MIS weight (the lamp's density of reaching the
// wall, cos / (pi d^2), is above the camera's there); the light tracer's image is all splats.
SceneDescription lit_edge_description(int res);

// `type` against the path tracer on that wall (res 16) under the gaussian and the Mitchell
// filter: block and whole-image z-tests (expect_agreement); control: `type` under the box filter,
// its splats in the pixel they land in, against the path tracer under each filter, rejected by
// the block test (the filtered edges spill into the blocks outside the lamp).
void expect_filtered_splats_agree(IntegratorType type, int spp, uint64_t seed_base);

// A splatting integrator (`type`, max_depth scattering events) on `base` (res x res) under the box
// and the gaussian filter: the same film and splat sums bit for bit at 1, 2 and 3 threads and when
// the pass is split in four; splats made, one path per pixel sample.
void expect_splat_film_deterministic(const Scene& base, int res, IntegratorType type, int max_depth);

}  // namespace candela::test
