#pragma once
// Denoising with Intel Open Image Denoise (OIDN), loaded at run time (docs/denoising.md).
//
// What goes in: the film's mean radiance (linear RGB, HDR), and optionally the auxiliary images of
// the aov wrapper's denoiser layers (AovType::DenoiseAlbedo, DenoiseNormal: the albedo in [0, 1]
// and the unit-or-shorter normal of the first non-specular surface, averaged like the radiance).
// The auxiliaries are noisy themselves where a pixel sees several surfaces (edges, glass, depth of
// field), so they are denoised first and the beauty is filtered with cleanAux on (OIDN's
// "prefiltering" route): noise in them would otherwise be copied into the result.
//
// The library is found, in this order: the file named by the environment variable
// CANDELA_OIDN_LIBRARY (only that one, when set), the copy scripts/setup-oidn.sh installs under
// ${XDG_CACHE_HOME:-$HOME/.cache}/candela/oidn-2.5.1/lib, then libOpenImageDenoise.so.2 on the
// system's library path. It is loaded once per process and never unloaded (its thread pool lives
// until exit). A build with CANDELA_OIDN=OFF has none of this: every call says so.
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>
#include "film/film.h"
#include "integrator/desc.h"

namespace candela {

enum class DenoiseQuality { Fast, Balanced, High };
bool parse_denoise_quality(const std::string& s, DenoiseQuality& out);  // fast | balanced | high
const char* denoise_quality_name(DenoiseQuality q);

// A failure of denoising: the library is missing or failed. what() is one line.
class DenoiseError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Empty when the library can be loaded here, else one line saying why not. Loads it (once).
std::string denoiser_unavailable_reason();

// The images a denoise takes, row-major from the top-left, 3 floats per pixel. albedo and normal
// may be empty (then the beauty is filtered alone); when given they have the beauty's size.
struct DenoiseImages {
    int width = 0, height = 0;
    std::vector<float> color, albedo, normal;
};

// The film's mean radiance and, when the scene's aovs hold the denoiser layers, the albedo and
// normal images interleaved.
DenoiseImages denoise_inputs(const Film& film, const std::vector<AovSpec>& aovs);

// An OIDN device and its filters, kept between calls of the same size and quality (creating and
// committing a filter costs more than a small image's denoise). One thread at a time.
class Denoiser {
public:
    explicit Denoiser(DenoiseQuality q = DenoiseQuality::High);
    ~Denoiser();
    Denoiser(const Denoiser&) = delete;
    Denoiser& operator=(const Denoiser&) = delete;

    void set_quality(DenoiseQuality q);
    DenoiseQuality quality() const { return quality_; }
    // The denoised beauty (width x height x 3) into `out`. Throws DenoiseError.
    void denoise(const DenoiseImages& in, std::vector<float>& out);

private:
    struct State;
    DenoiseQuality quality_;
    std::unique_ptr<State> state_;
};

}  // namespace candela
