#include <cctype>
#include <cstdint>
#include "core/error.h"
#include "texture/decode.h"

// Binary PGM and PPM (netpbm's P5 and P6), read here rather than by stb_image, whose header parser
// overflows a signed int on a long number (a fuzzer finding).
namespace candela {

bool is_pnm(const std::vector<unsigned char>& f) {
    return f.size() >= 3 && f[0] == 'P' && (f[1] == '5' || f[1] == '6') && std::isspace(f[2]);
}

EncodedTexels decode_pnm(const std::string& path, const std::vector<unsigned char>& f) {
    if (!is_pnm(f)) throw Error(path, 0, "not a binary PGM or PPM file (expected \"P5\" or \"P6\")");
    size_t pos = 2;
    // The next header number: whitespace and comments (# to the end of the line) before it.
    auto number = [&](const char* what, long long most) {
        for (;;) {
            while (pos < f.size() && std::isspace(f[pos])) ++pos;
            if (pos < f.size() && f[pos] == '#') {
                while (pos < f.size() && f[pos] != '\n' && f[pos] != '\r') ++pos;
                continue;
            }
            break;
        }
        if (pos >= f.size() || !std::isdigit(f[pos])) throw Error(path, 0, std::string("bad PNM header: no ") + what);
        long long v = 0;
        while (pos < f.size() && std::isdigit(f[pos])) {
            v = v * 10 + (f[pos++] - '0');
            if (v > most) throw Error(path, 0, std::string("bad PNM header: ") + what + " above " + std::to_string(most));
        }
        return v;
    };
    EncodedTexels t;
    t.channels = f[1] == '5' ? 1 : 3;
    const long long w = number("width", 1 << 20), h = number("height", 1 << 20), maxval = number("maxval", 65535);
    if (w == 0 || h == 0 || maxval == 0) throw Error(path, 0, "bad PNM header: zero width, height or maxval");
    check_image_size(path, "image", w, h, f.size(), 0);  // the raster's length is checked below
    // Exactly one whitespace character separates the header from the raster.
    if (pos >= f.size() || !std::isspace(f[pos])) throw Error(path, 0, "truncated PNM header");
    ++pos;
    const size_t bytes = maxval < 256 ? 1 : 2;
    const size_t n = size_t(w) * size_t(h) * size_t(t.channels);
    if ((f.size() - pos) / bytes < n)
        throw Error(path, 0, "truncated PNM: " + std::to_string(f.size() - pos) + " bytes of raster, expected " +
                                 std::to_string(n * bytes));
    t.width = int(w);
    t.height = int(h);
    t.v.resize(n);
    const float scale = 1.f / float(maxval);
    for (size_t i = 0; i < n; ++i) {
        const unsigned char* p = &f[pos + i * bytes];
        const unsigned s = bytes == 1 ? p[0] : unsigned(p[0]) << 8 | p[1];
        // A sample above maxval is out of the format; clamped as netpbm's tools do.
        t.v[i] = float(s > unsigned(maxval) ? unsigned(maxval) : s) * scale;
    }
    return t;
}

}  // namespace candela
