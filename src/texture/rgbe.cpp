#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include "core/error.h"
#include "texture/decode.h"

// Radiance RGBE (.hdr), read here rather than by Debian 12's stb_image, which loops forever on a
// run-length scanline cut short (it reads the missing bytes as zero-length runs; CVE-2021-42715).
namespace candela {

bool is_rgbe(const std::vector<unsigned char>& f) {
    // "#?" and a program name (RADIANCE, RGBE, ...), as Walter's reader in Mitsuba accepts.
    return f.size() >= 3 && f[0] == '#' && f[1] == '?' && std::isalpha(f[2]);
}

std::vector<float> decode_rgbe(const std::string& path, const std::vector<unsigned char>& f, int& width, int& height) {
    if (!is_rgbe(f)) throw Error(path, 0, "not a Radiance HDR file (expected \"#?RADIANCE\")");
    size_t pos = 0;
    auto line = [&]() {
        std::string s;
        while (pos < f.size() && f[pos] != '\n') {
            if (s.size() > 4096) throw Error(path, 0, "Radiance HDR header line longer than 4096 bytes");
            s += char(f[pos++]);
        }
        if (pos >= f.size()) throw Error(path, 0, "truncated Radiance HDR header");
        ++pos;
        return s;
    };
    line();  // the magic
    // Header lines up to an empty one; FORMAT may be left out (RGBE is the default).
    for (std::string s = line(); !s.empty(); s = line())
        if (s.rfind("FORMAT=", 0) == 0 && s.compare(0, 22, "FORMAT=32-bit_rle_rgbe") != 0)
            throw Error(path, 0, "unsupported Radiance HDR " + s.substr(0, 64));
    const std::string res = line();
    long w = 0, h = 0;
    if (std::sscanf(res.c_str(), "-Y %ld +X %ld", &h, &w) != 2)
        throw Error(path, 0, "unsupported Radiance HDR resolution line (only \"-Y height +X width\" is read): " +
                                 res.substr(0, 64));
    // Run-length data codes at most 127 values of a channel in 2 bytes, 4 channels a texel.
    check_image_size(path, "image", w, h, f.size(), 16.0);
    width = int(w);
    height = int(h);
    std::vector<float> rgb(size_t(w) * size_t(h) * 3);
    auto truncated = [&] { return Error(path, 0, "truncated Radiance HDR pixel data"); };
    // Walter's rgbe.c, as Mitsuba and stb_image convert: mantissa * 2^(e - 136), 0 when e is 0.
    auto put = [&](size_t texel, const unsigned char* e) {
        const float s = e[3] ? std::ldexp(1.f, int(e[3]) - 136) : 0.f;
        for (int c = 0; c < 3; ++c) rgb[3 * texel + size_t(c)] = float(e[c]) * s;
    };
    std::vector<unsigned char> scan(size_t(w) * 4);
    for (long y = 0; y < h; ++y) {
        const size_t row = size_t(y) * size_t(w);
        // A scanline is run-length coded when it starts 2, 2, then the width (below 32768) in
        // two bytes; otherwise it and every line after it are flat RGBE quadruples.
        const bool rle = w >= 8 && w < 32768 && f.size() - pos >= 4 && f[pos] == 2 && f[pos + 1] == 2 &&
                         !(f[pos + 2] & 0x80);
        if (!rle) {
            const size_t n = (size_t(h) - size_t(y)) * size_t(w);
            if ((f.size() - pos) / 4 < n) throw truncated();
            for (size_t i = 0; i < n; ++i) put(row + i, &f[pos + 4 * i]);
            return rgb;
        }
        if ((size_t(f[pos + 2]) << 8 | f[pos + 3]) != size_t(w))
            throw Error(path, 0, "corrupt Radiance HDR: scanline " + std::to_string(y) + " has the wrong width");
        pos += 4;
        for (int c = 0; c < 4; ++c) {
            for (long x = 0; x < w;) {
                if (pos >= f.size()) throw truncated();
                int count = f[pos++];
                const bool run = count > 128;
                if (run) count -= 128;
                if (count == 0 || count > w - x)
                    throw Error(path, 0, "corrupt Radiance HDR: bad run in scanline " + std::to_string(y));
                if (f.size() - pos < (run ? 1u : size_t(count))) throw truncated();
                for (int k = 0; k < count; ++k, ++x) scan[size_t(x) * 4 + size_t(c)] = f[run ? pos : pos + size_t(k)];
                pos += run ? 1 : size_t(count);
            }
        }
        for (long x = 0; x < w; ++x) put(row + size_t(x), &scan[size_t(x) * 4]);
    }
    return rgb;
}

}  // namespace candela
