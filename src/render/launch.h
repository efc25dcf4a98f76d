#pragma once
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>
#include "scene/scene.h"

namespace candela {

// What the command line may override in a scene. Unset fields keep the scene file's values.
struct SceneOverrides {
    std::vector<std::pair<std::string, std::string>> defines;  // -D name=value
    std::optional<int> width, height, max_depth, rr_depth;
    std::optional<uint64_t> seed;
    std::optional<SamplingMode> sampling;
    std::optional<SamplerType> sampler;  // --sampler (jitter keeps the scene's)
    std::optional<int> sample_count;     // --sample-count: the scene's sample_count
    std::optional<IntegratorType> integrator;  // --integrator: replaces the scene's <integrator>
    std::string accel = "auto";
    // --denoise, --aov: render the denoiser's auxiliary layers (add_denoise_aovs) when the
    // integrator traces camera paths per pixel (path, direct); the others have none to follow, and
    // their images are denoised from the beauty alone.
    bool denoise_aux = false;
    // --denoise, and the viewer when it can denoise: render with the box reconstruction filter
    // (a warning says so when the scene asks for another). A wider filter spreads each sample over
    // several pixels, so that the noise is correlated between neighbours; Open Image Denoise takes
    // such noise for detail and keeps it (docs/denoising.md shows it on matpreview).
    bool denoise_box_filter = false;
};

// Loads `path` (or the built-in Cornell box when empty), applies the overrides and builds the
// scene (accelerator, lights, prepared materials). Throws Error with file:line on bad input.
std::shared_ptr<const Scene> prepare_scene(const std::string& path, const SceneOverrides& ov);

SamplingMode parse_sampling_mode(const std::string& s);  // light | bsdf | mis
IntegratorType parse_integrator_type(const std::string& s);  // path | direct | ptracer | bdpt | pssmlt | mmlt
const char* integrator_type_name(IntegratorType t);
const char* sampling_mode_name(SamplingMode m);
// --sampler NAME: a sampler_type_name; unknown names are errors.
SamplerType parse_sampler_name(const std::string& s);

}  // namespace candela
