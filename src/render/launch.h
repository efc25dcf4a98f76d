#pragma once
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>
#include "core/error.h"
#include "scene/scene.h"

namespace candela {

// A command-line request that cannot be honoured as given (an option the scene's integrator does not
// read, a value out of range): the program exits with status 2, as for CLI11's parse errors.
class UsageError : public Error {
public:
    using Error::Error;
};

// What the command line may override in a scene. Unset fields keep the scene file's values.
struct SceneOverrides {
    std::vector<std::pair<std::string, std::string>> defines;  // -D name=value
    std::optional<int> width, height;
    // Mitsuba's max_depth (path segments: 1 emitters only, 2 direct light, -1 unbounded) and
    // rr_depth, as in scene files (integrator/depth.h); checked by the files' rules.
    std::optional<int> max_depth, rr_depth;
    std::optional<uint64_t> seed;
    std::optional<SamplingMode> sampling;
    std::optional<SamplerType> sampler;  // --sampler (jitter keeps the scene's)
    std::optional<int> sample_count;     // --sample-count: the scene's sample_count
    std::optional<IntegratorType> integrator;  // --integrator: replaces the scene's <integrator>
    bool spectral_mis = false;                 // --integrator volpathmis (volpath with spectral MIS)
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
// scene (accelerator, lights, prepared materials). Throws Error with file:line on bad input, and
// UsageError for an override out of range or one the scene's integrator does not read
// (integrator/caps.h); a value of the scene's own that its integrator ignores becomes a warning.
std::shared_ptr<const Scene> prepare_scene(const std::string& path, const SceneOverrides& ov);

// Features of a render around the integrator. check_run_features throws UsageError naming the
// option and the integrator when the scene's integrator lacks one that is asked for.
struct RunFeatures {
    bool mpi = false;         // under mpirun / srun
    bool adaptive = false;    // --target-error
    bool checkpoint = false;  // --checkpoint or --resume
    bool time_limit = false;  // --time-limit
};
void check_run_features(const RenderSettings& st, const RunFeatures& f);
// The integrator and the settings it reads, for summary lines: "path (max_depth -1, rr_depth 5, mis)",
// depths in Mitsuba's convention.
std::string integrator_summary(const RenderSettings& st);

SamplingMode parse_sampling_mode(const std::string& s);  // light | bsdf | mis
IntegratorType parse_integrator_type(const std::string& s);  // path | volpath | volpathmis | direct | ptracer | bdpt | pssmlt | mmlt
const char* sampling_mode_name(SamplingMode m);
// --sampler NAME: a sampler_type_name; unknown names are errors.
SamplerType parse_sampler_name(const std::string& s);

}  // namespace candela
