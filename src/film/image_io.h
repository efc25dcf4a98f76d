#pragma once
#include <string>
#include <vector>

namespace candela {

// Linear RGB float images, row-major from the top-left, 3 floats per pixel.
struct Image {
    int width = 0, height = 0;
    std::vector<float> rgb;
    std::vector<float> alpha;  // empty, or 1 float per pixel: written to EXR as channel A
};

// Writes .exr (tinyexr, 32-bit float RGB, plus A when the image has alpha) or .pfm (little-endian, bottom-up as the format says)
// by the file's extension. The file is written to a temporary name beside the target and renamed,
// so a crash or kill never leaves a truncated image. Throws Error naming the file on failure.
void write_linear_image(const std::string& path, const Image& img);

// Reads .exr or .pfm (any channel count; returned as RGB). Throws Error naming the file.
Image read_linear_image(const std::string& path);

// The whole file as bytes. Throws Error naming the file when it cannot be read.
std::vector<unsigned char> read_whole_file(const std::string& path);

// Lower-case extension including the dot (".png"), or "" when there is none.
std::string file_extension(const std::string& path);

// Writes bytes to `path` atomically (temporary file + rename). Throws Error naming the file.
void write_file_atomic(const std::string& path, const void* data, size_t size);

}  // namespace candela
