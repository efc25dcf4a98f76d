#pragma once
// Checkpoints of a headless render: the film's raw state at a pass boundary, so that a render
// killed after hours continues where it was saved and ends bit for bit as if never interrupted.
//
// This works because a render's whole state is the film plus the number of samples per pixel
// taken: the sampler is seeded from (pixel, sample index, seed) and each pixel's samples are summed
// in sample order, so continuing at sample index N reproduces the rest of the uninterrupted run.
#include <cstdint>
#include <string>
#include "film/film.h"
#include "scene/scene.h"

namespace candela {

// A 64-bit hash of everything that decides the image a finalized scene renders: the geometry, the
// shapes, the materials (probed through eval/pdf/sample at fixed arguments, so that every BSDF
// type is covered without knowing its fields), the emitters, the camera (probed by its rays), the
// render settings (size, seed, depths, sampling) and the accelerator's name. The thread count and
// the samples per pass do not change the image and are not part of it.
uint64_t scene_fingerprint(const Scene& scene);

struct CheckpointInfo {
    int width = 0, height = 0;
    uint32_t spp = 0;           // samples per pixel taken: the next sample index of every pixel
    uint64_t nonfinite = 0;
    uint64_t fingerprint = 0;
};

// Writes the film (sums, counts, non-finite count) and `spp` atomically: a temporary file beside
// `path`, fsync, rename. Every pixel must have exactly `spp` samples (a whole number of passes).
// Streams from the film's buffers, so saving needs no extra memory. Throws Error naming the file.
void save_checkpoint(const std::string& path, const Film& film, uint32_t spp, uint64_t fingerprint);

// Reads a checkpoint into `film` after checking it against the render about to continue: the
// format, the size, the checksum, that every pixel has `spp` samples, and the fingerprint.
// Sizes are validated against the file's length before anything is allocated. Throws Error with a
// one-line reason (missing, truncated, corrupt, other scene or settings) naming the file.
CheckpointInfo load_checkpoint(const std::string& path, Film& film, uint64_t fingerprint);

}  // namespace candela
