#pragma once
// Which integrator a scene renders with, as its <integrator> element says (Mitsuba 3's plugins and
// defaults; docs/scene-format.md). Plain data: the render settings carry it, make_integrator
// (integrator/integrator.h) turns it into the object that renders passes.
#include <string>
#include <vector>

namespace candela {

enum class IntegratorType {
    Path,    // path: integrator/path/
    Volpath, // volpath, volpathmis: integrator/volpath/ (the path tracer in a scene without media)
    Direct,  // direct: integrator/direct/
    Ptracer, // ptracer (light tracing, splats only): integrator/ptracer/
    Bdpt,    // bdpt (bidirectional path tracing, camera samples and splats): integrator/bdpt/
    Pssmlt,  // pssmlt (primary-sample-space Metropolis over the path tracer, splats only): integrator/mlt/
    Mmlt,    // mmlt (multiplexed Metropolis over BDPT's strategies, splats only): integrator/mlt/
};

// Metropolis light transport's parameters (docs/mlt.md has the reasons for the defaults).
struct MltParams {
    int bootstrap_samples = 100000;  // paths that estimate b and seed the chains (pbrt-v3)
    int chains = 1000;               // Markov chains (pbrt-v3): many short chains hide start-up bias
    float sigma = 0.01f;             // small-step standard deviation in primary sample space (pbrt-v3)
    float large_step_probability = 0.3f;  // pbrt-v3's default
    // The XML's mutations_per_pixel (0: not given): it becomes the scene's sample_count, the
    // render's total mutations per pixel (a pass of n "samples per pixel" is n x pixels mutations).
    int mutations_per_pixel = 0;
};

// Arbitrary output variables of Mitsuba's `aov` wrapper: values of the first surface the camera
// ray hits (zero where it hits nothing), filtered into the film like the radiance.
enum class AovType {
    Depth,      // distance from the camera's pinhole to the hit: 1 channel ".T"
    Position,   // world-space hit point: ".X" ".Y" ".Z"
    GeoNormal,  // geometric normal (world, unit, the triangle's winding side): ".X" ".Y" ".Z"
    ShNormal,   // shading normal (world, unit, interpolated where the mesh has normals): ".X" ".Y" ".Z"
    Albedo,     // the BSDF's diffuse reflectance, Mitsuba's eval_diffuse_reflectance: ".R" ".G" ".B"
    Uv,         // texture coordinates of the hit (the shape's parameterisation): ".U" ".V"
    DpDu,       // world-space dp/du at the hit (SurfaceInteraction::dpdu): ".X" ".Y" ".Z"
    DpDv,       // world-space dp/dv: ".X" ".Y" ".Z"
    PrimIndex,  // the triangle's index within its shape (0 on analytic shapes), as a float: ".I"
    ShapeIndex, // candela's shape index (Mitsuba writes an id of its own, not comparable): ".I"
    // The denoiser's auxiliary images (candela's own, added by --denoise and --aov; docs/denoising.md):
    // the camera ray followed through delta surfaces (mirrors, smooth glass) to the first surface
    // with a non-delta component, as Open Image Denoise asks.
    DenoiseAlbedo,  // that surface's albedo (as Albedo), clamped to [0, 1]: ".R" ".G" ".B"
    DenoiseNormal,  // its shading normal (world, unit, facing the incoming ray): ".X" ".Y" ".Z"
    // Not an aov type: the `moment` wrapper's channels, always last. The nested integrator's
    // radiance per sample as CIE XYZ, then its square (the per-sample second moment), both filtered
    // like the image: "<name>.X" ".Y" ".Z" "m2_<name>.X" ".Y" ".Z" (Mitsuba's moment.cpp).
    Moment,
};

struct AovSpec {
    std::string name;  // the <name> of "<name>:<type>"
    AovType type = AovType::Depth;
};

struct IntegratorDesc {
    IntegratorType type = IntegratorType::Path;
    // Camera rays pass through area emitters (Mitsuba 3's hide_emitters: skip_area_emitters on the
    // first segment), so that an emitter in view shows what lies behind it.
    bool hide_emitters = false;
    // volpath: Mitsuba's volpathmis, spectral MIS over the distance-sampling channel
    // (integrator/volpath/volpath.h). No effect in a scene without media.
    bool spectral_mis = false;
    // direct: samples per shading point of each strategy, combined by the power heuristic with the
    // sample counts in the weights (Mitsuba's direct.cpp).
    int emitter_samples = 1, bsdf_samples = 1;
    MltParams mlt;  // pssmlt, mmlt
    // aov wrapper: the layers written beside the nested integrator's image.
    std::vector<AovSpec> aovs;
};

// The integrator's name in files and on the command line ("path", "volpath", ...).
const char* integrator_type_name(IntegratorType t);

// Number of film channels and their EXR names ("dd.T", "nn.X", ...), in order.
int aov_channel_count(AovType t);
int aov_channel_count(const std::vector<AovSpec>& aovs);
std::vector<std::string> aov_channel_names(const std::vector<AovSpec>& aovs);
// Adds the denoiser's layers (DenoiseAlbedo "albedo", DenoiseNormal "normal"; "denoise_albedo" and
// "denoise_normal" when the scene's aov wrapper already has those names) before a moment spec,
// unless they are there already.
void add_denoise_aovs(std::vector<AovSpec>& aovs);
// "depth", "position", ... (Mitsuba's names); false when `s` names no AOV candela computes.
bool parse_aov_type(const std::string& s, AovType& out);

}  // namespace candela
