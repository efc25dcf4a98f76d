#pragma once
// Bidirectional path tracing (Veach 1997, ch. 10; issue 15; docs/bdpt.md).
//
// Per pixel sample: a camera subpath z_0..z_{nc-1} (z_0 on the camera) and a light subpath
// y_0..y_{nl-1} (y_0 on a light), then every strategy (s, t) that joins the first s light
// vertices to the first t camera vertices into a path of s + t - 2 scattering events, weighted by
// the power heuristic over all strategies that could have made that path (bdpt/mis.h):
//   s = 0       the camera path reaches an emitter (area light) or leaves the scene (infinite lights)
//   s = 1       next-event estimation from z_{t-1}: a fresh light sample (LightSet::sample_li)
//   t = 1       y_{s-1} connected to the camera (Camera::sample_wi), SPLATTED where it projects,
//               through the film's filter (as the light tracer, film/splat_filter.h); not for the
//               orthographic camera (a delta direction) nor to an infinite light
//   s, t >= 2   y_{s-1} and z_{t-1} joined by a shadow ray
// The camera sample's own value (t >= 2) goes to the film at its position (filtered as every camera
// sample); the splats are normalised by the light paths traced (film/film.h), one per pixel
// sample, and by the filter so that both estimate the same filtered image: the image is their sum.
//
// Densities: every vertex stores pdf_fwd and pdf_rev in AREA measure (solid angle x |cos| /
// dist^2 at the receiving vertex; a direction, y_0 of an infinite light or z where the camera
// path left, keeps solid angle, and the vertex after it gets the scene's bounding disk density x
// |cos|, as pbrt). Light origins: an area light's point has the density next-event estimation
// gives it from its neighbour (LightSet::pdf_li, in area measure), so that BDPT's s = 0 / s = 1
// weights are the path tracer's; delta lights their pmf; infinite lights the summed solid-angle
// density of every infinite light (directional: its pmf, a delta). Delta lobes: the vertex is
// flagged and its two pdfs of that step are 0 (mis.h). Masked surfaces crossed (pass-throughs,
// not vertices) multiply the densities of the segment by their pass probability, and a
// connection's shadow ray by its transmittance, so that the densities stay comparable.
//
// Depth as everywhere in candela: max_depth counts scattering events, s + t - 2 <= max_depth (-1
// unbounded: each subpath is cut at kMaxVertices, far past where Russian roulette ends paths).
// Russian roulette on each subpath as the path tracer and the light tracer do (after the BSDF
// sample at the k-th vertex, k >= rr_depth); it scales throughputs, not the MIS densities, which
// keeps the estimator unbiased (the weights still sum to one over the strategies of each path).
// hide_emitters: camera rays pass through area emitters (the path tracer's skip_area_emitters),
// so do the t = 1 connections to the camera, no light vertex on an emitter is connected to the
// camera, and the paths of zero scattering events are dropped.
// Sampler dimensions per pixel sample: jitter 2, [lens 2]; per camera vertex [mask 1], BSDF 1 + 2,
// [roulette 1]; light: 1 + 2 + 2 and per vertex the same; then for t = 1..nc, s = 0..nl in order:
// s = 1 takes 1 + 2 (light sample), t = 1 takes 2 (lens).
#include <memory>
#include <vector>
#include "integrator/bdpt/mis.h"
#include "integrator/integrator.h"
#include "integrator/path.h"

namespace candela {

constexpr int kBdptMaxVertices = 66;

struct BdptVertex {
    enum class Kind : uint8_t { Camera, Light, Surface, Escaped };
    Kind kind = Kind::Surface;
    bool delta = false;       // Surface sampled by a delta lobe; Camera with a delta direction
    bool delta_light = false; // Light: a delta position or direction (point, spot, directional)
    bool infinite = false;    // a direction (infinite light, or Escaped)
    bool emitter = false;     // Surface on an area emitter
    bool smooth = false;      // Surface whose BSDF has a non-delta part (connectible)
    vec3 p{0.f};
    vec3 n{0.f};              // geometric normal for the |cos| of densities; 0: a point (camera, point light)
    vec3 w{0.f};              // Escaped: the direction; Light infinite: the direction light travels
    SurfaceInteraction si;    // Surface and area-light points
    vec3 beta{0.f};
    float pdf_fwd = 0.f, pdf_rev = 0.f;
    float seg_T = 1.f;        // pass probability of the masks crossed on the segment from the previous vertex
    int32_t light = -1;       // Light: index into LightSet::light(i), -1 for an area light
    vec3 Le{0.f};             // Light: emitted radiance or intensity (as sample_le / sample_li give it)
};

// One strategy's contribution (for --bdpt-strategies): where it lands, weighted and unweighted.
struct StrategyRecord {
    int s, t;
    bool splat;   // t = 1: `raster` is the image position; else the pixel of the sample
    vec2 raster;
    vec3 weighted, unweighted;
};

class Bdpt {
public:
    // `camera` is set to the film's size.
    Bdpt(const Scene& scene, const Camera& camera, int width, int height);

    // Per-thread storage: the vertices and their BSDFs (ShadingT points into itself: never moved).
    struct Workspace {
        std::vector<BdptVertex> cam, light;
        std::unique_ptr<ShadingT<false>[]> cam_sh, light_sh;
        std::vector<MisVertex> mc, ml;
        Workspace();
    };

    // One pixel sample: returns the camera sample's radiance (strategies with t >= 2), appends the
    // t = 1 splats to `out`. `covered`: the camera ray hit a surface. `record` (may be null)
    // receives every strategy's contribution.
    template <class S>
    vec3 sample(S& sampler, ivec2 px, Workspace& ws, SplatTile& out, PathStats& stats, bool& covered, vec2& jitter,
                std::vector<StrategyRecord>* record) const;

    // MMLT (integrator/mlt/): one strategy (s, t) of paths of `depth` scattering events, chosen
    // uniformly among the depth's strategies by the sampler's stream 2 (which also gives the
    // connection's numbers), the camera subpath of t vertices from stream 0 (its first two numbers:
    // the film position, returned in `raster`, or the t = 1 splat's position), the light subpath
    // of s vertices from stream 1. Returns the strategy's MIS-weighted contribution times the
    // number of strategies: summed over the strategies, its expectation is the depth's image.
    template <class S>
    vec3 sample_strategy(S& sampler, int depth, Workspace& ws, PathStats& stats, vec2& raster) const;

private:
    template <class S>
    int camera_subpath(S& sampler, ivec2 px, vec2 jitter, Workspace& ws, int max_cam, PathStats& stats) const;
    template <class S>
    int light_subpath(S& sampler, Workspace& ws, int max_light, PathStats& stats) const;

    const Scene& scene_;
    const Camera& camera_;
    int width_, height_;
    bool masks_;
    float disk_pdf_;  // 1 / (pi r^2) of the scene's bounding sphere: where infinite lights' rays start

    template <class S>
    int walk(S& sampler, Ray ray, vec3 beta, float pdf_sa, BdptVertex* path, ShadingT<false>* sh, int count, int max,
             TransportMode mode, PathStats& stats, bool camera_ray, bool infinite_start) const;
    vec3 connect(const Workspace& ws, int s, int t, float u_l, vec2 u_p, vec2 u_lens, PathStats& stats, float& weight,
                 vec2& raster, bool& splat) const;

    // Area density with which `next` is sampled from `cur` (prev: the vertex before cur on the
    // side walking towards next, or null when cur is an endpoint).
    float pdf(const BdptVertex* prev, const BdptVertex& cur, const ShadingT<false>* cur_sh, const BdptVertex& next,
              TransportMode mode) const;
    float pdf_light(const BdptVertex& light, const BdptVertex& next) const;
    float pdf_light_origin(const BdptVertex& light, const BdptVertex& next) const;
    float infinite_density(vec3 w_escape) const;
    static float convert(float pdf_sa, vec3 from, const BdptVertex& to);
    // The t = 1 shadow ray (through hidden emitters with hide_emitters).
    float camera_visibility(const SurfaceInteraction& from, vec3 cam_p, PathStats& stats) const;
};

class BdptPass final : public Integrator {
public:
    PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                          const std::atomic<bool>* cancel) const override;
};

// --bdpt-strategies: one image per strategy (s, t) with s + t - 2 <= max_length, weighted and
// unweighted, over `spp` samples (each a film's resolved mean, unfiltered: the weighted ones sum
// to the BDPT image under the box filter). Returned per strategy in order of (length, s).
struct StrategyImage {
    int s, t;
    std::vector<float> weighted, unweighted;  // RGB, row-major
};
std::vector<StrategyImage> render_bdpt_strategies(const Scene& scene, int width, int height, int spp, int threads,
                                                  int max_length);

}  // namespace candela

#include "integrator/bdpt/bdpt_impl.h"
