// libFuzzer target: image decoding as textures and environment maps reach it (load_texels:
// stb_image for PNG, JPEG, HDR, ...; tinyexr and the PFM reader for .exr/.pfm). The decoders read
// files, so the input goes to a temporary file; its first byte picks the extension (which selects
// the decoder) and the `raw` flag. Any input must decode or throw candela::Error; a crash, a
// sanitizer report, another exception, a leak or a hang is a finding.
#include <unistd.h>
#include <cstdint>
#include <cstdio>
#include <string>
#include "core/error.h"
#include "texture/texture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    static const char* const kExt[] = {".png", ".jpg", ".hdr", ".exr", ".pfm", ".bmp", ".tga", ".ppm"};
    const std::string path = "/tmp/candela-fuzz-image-" + std::to_string(getpid()) + kExt[(data[0] >> 1) % 8];
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return 0;
    std::fwrite(data + 1, 1, size - 1, f);
    std::fclose(f);
    try {
        candela::load_texels(path, (data[0] & 1) != 0);
    } catch (const candela::Error&) {
    }
    std::remove(path.c_str());
    return 0;
}
