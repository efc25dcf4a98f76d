#include "film/exr_layers.h"
#include <tinyexr.h>
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <set>
#include "core/error.h"

namespace candela {

namespace {

std::string exr_message(const char* msg, int code) {
    std::string t = msg ? std::string(msg) : "tinyexr error " + std::to_string(code);
    std::replace(t.begin(), t.end(), '\n', ' ');
    return t;
}

}  // namespace

void write_exr_layers(const std::string& path, const Image& img, const std::vector<ExrLayer>& layers) {
    const size_t n = size_t(img.width) * size_t(img.height);
    std::vector<ExrLayer> all = layers;
    const char* rgb[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        ExrLayer l{rgb[c], std::vector<float>(n)};
        for (size_t i = 0; i < n; ++i) l.plane[i] = img.rgb[3 * i + size_t(c)];
        all.push_back(std::move(l));
    }
    // EXR readers expect the channel list sorted by name.
    std::sort(all.begin(), all.end(), [](const ExrLayer& a, const ExrLayer& b) { return a.name < b.name; });
    std::set<std::string> seen;
    for (const ExrLayer& l : all) {
        if (l.plane.size() != n) throw Error(path, 0, "internal error: channel '" + l.name + "' has the wrong size");
        if (l.name.empty() || l.name.size() >= 255) throw Error(path, 0, "EXR channel name '" + l.name + "' is empty or too long");
        if (!seen.insert(l.name).second) throw Error(path, 0, "two EXR channels named '" + l.name + "'");
    }
    const int nc = int(all.size());
    const size_t ncs = static_cast<size_t>(nc);
    std::vector<EXRChannelInfo> channels(ncs);
    std::vector<int> types(ncs, TINYEXR_PIXELTYPE_FLOAT), requested(ncs, TINYEXR_PIXELTYPE_FLOAT);
    std::vector<float*> planes(ncs);
    for (int c = 0; c < nc; ++c) {
        std::memset(&channels[size_t(c)], 0, sizeof(EXRChannelInfo));
        std::strncpy(channels[size_t(c)].name, all[size_t(c)].name.c_str(), sizeof(channels[size_t(c)].name) - 1);
        channels[size_t(c)].x_sampling = channels[size_t(c)].y_sampling = 1;
        planes[size_t(c)] = all[size_t(c)].plane.data();
    }
    EXRImage image;
    InitEXRImage(&image);
    image.images = reinterpret_cast<unsigned char**>(planes.data());
    image.width = img.width;
    image.height = img.height;
    image.num_channels = nc;
    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = nc;
    header.channels = channels.data();
    header.pixel_types = types.data();
    header.requested_pixel_types = requested.data();
    header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
    unsigned char* mem = nullptr;
    const char* err = nullptr;
    size_t size = SaveEXRImageToMemory(&image, &header, &mem, &err);
    std::unique_ptr<unsigned char, void (*)(void*)> owned(mem, std::free);
    if (size == 0 || !mem) {
        std::string msg = exr_message(err, 0);
        if (err) FreeEXRErrorMessage(err);
        throw Error(path, 0, "cannot encode EXR: " + msg);
    }
    write_file_atomic(path, mem, size);
}

std::map<std::string, std::vector<float>> read_exr_channels(const std::string& path, int* width, int* height) {
    EXRVersion version;
    int rc = ParseEXRVersionFromFile(&version, path.c_str());
    if (rc != TINYEXR_SUCCESS) throw Error(path, 0, "not an EXR file");
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    rc = ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err);
    auto fail = [&](int code) {
        std::string msg = exr_message(err, code);
        if (err) FreeEXRErrorMessage(err);
        FreeEXRHeader(&header);
        return Error(path, 0, "cannot read EXR: " + msg);
    };
    if (rc != TINYEXR_SUCCESS) throw fail(rc);
    for (int c = 0; c < header.num_channels; ++c) header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
    EXRImage image;
    InitEXRImage(&image);
    image.num_channels = header.num_channels;  // tinyexr frees the buffers on error (image_io.cpp, read_exr)
    rc = LoadEXRImageFromFile(&image, &header, path.c_str(), &err);
    if (rc != TINYEXR_SUCCESS) throw fail(rc);
    std::map<std::string, std::vector<float>> out;
    const size_t n = size_t(image.width) * size_t(image.height);
    if (!image.images) {
        FreeEXRImage(&image);
        FreeEXRHeader(&header);
        throw Error(path, 0, "tiled EXR files are not read here");
    }
    for (int c = 0; c < header.num_channels; ++c) {
        const float* p = reinterpret_cast<const float*>(image.images[c]);
        out[header.channels[c].name] = std::vector<float>(p, p + n);
    }
    if (width) *width = image.width;
    if (height) *height = image.height;
    FreeEXRImage(&image);
    FreeEXRHeader(&header);
    return out;
}

}  // namespace candela
