#pragma once
// EXR files with named channels beyond R, G, B: the layers of the aov integrator, named as
// Mitsuba names them ("dd.T", "nn.X", "albedo.R"...), which is what denoisers read.
#include <map>
#include <string>
#include <vector>
#include "film/image_io.h"

namespace candela {

struct ExrLayer {
    std::string name;          // full channel name
    std::vector<float> plane;  // width x height, row-major from the top-left
};

// Writes R, G, B from `img` plus the given channels, 32-bit float, ZIP, atomically. Throws Error
// naming the file (also for a duplicate or over-long channel name).
void write_exr_layers(const std::string& path, const Image& img, const std::vector<ExrLayer>& layers);

// Every channel of an EXR file as float planes, by name. Throws Error naming the file.
std::map<std::string, std::vector<float>> read_exr_channels(const std::string& path, int* width = nullptr,
                                                            int* height = nullptr);

}  // namespace candela
