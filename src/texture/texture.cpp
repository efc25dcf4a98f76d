#include "texture/texture.h"
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
#include <stb/stb_image.h>
#include "core/error.h"
#include "film/image_io.h"

namespace candela {

UvTransform UvTransform::from_mat4(const mat4& t) {
    // Mitsuba's extract(): rows and columns 0, 1 and 3 of the 4x4 (the xy part and its translation).
    UvTransform u;
    const int idx[3] = {0, 1, 3};
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) u.m[c][r] = t[idx[c]][idx[r]];
    return u;
}

float srgb_to_linear(float v) {
    return v <= 0.04045f ? v * (1.f / 12.92f) : std::pow((v + 0.055f) * (1.f / 1.055f), 2.4f);
}

namespace {

// Debian 12's stb_image builds a JPEG Huffman table without checking that its code counts sum to at
// most 256 (fixed upstream later), and writes past the table for a corrupt file (found by
// tests/fuzz/fuzz_image.cpp). So every DHT segment is checked here first, walking the JPEG's
// markers, including those between the scans of a progressive file.
bool jpeg_huffman_tables_valid(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::string b((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    auto at = [&](size_t i) { return i < b.size() ? uint8_t(b[i]) : uint8_t(0); };
    // stb_image reads past the end of a file as zeros and skips fill bytes (0xFF) before a marker;
    // so does this walk.
    size_t i = 0;
    while (at(i) == 0xFF && at(i + 1) == 0xFF) ++i;
    if (at(i) != 0xFF || at(i + 1) != 0xD8) return true;  // not a JPEG
    i += 2;
    while (i + 4 <= b.size()) {
        if (at(i) != 0xFF) {  // entropy-coded data: skip to the next marker that is not a stuffed 0 or RSTn
            ++i;
            continue;
        }
        const uint8_t m = at(i + 1);
        if (m == 0x00 || m == 0xFF || (m >= 0xD0 && m <= 0xD7) || m == 0x01) {
            i += m == 0xFF ? 1 : 2;
            continue;
        }
        if (m == 0xD9) break;  // end of image
        const size_t len = size_t(at(i + 2)) << 8 | at(i + 3);
        if (len < 2) return false;
        if (m == 0xC4) {
            size_t k = i + 4, end = i + 2 + len;
            while (k < end && k < b.size()) {
                size_t n = 0;
                for (int c = 0; c < 16; ++c) n += at(k + 1 + size_t(c));
                if (n > 256) return false;
                k += 17 + n;
            }
        }
        i += 2 + len;
    }
    return true;
}

// Texel index `i` of a grid `n` texels wide, wrapped by the mode (Mitsuba's, for any integer).
int wrap_index(int i, int n, TextureWrap mode) {
    switch (mode) {
        case TextureWrap::Clamp: return std::clamp(i, 0, n - 1);
        case TextureWrap::Repeat: {
            int m = i % n;
            return m < 0 ? m + n : m;
        }
        case TextureWrap::Mirror: {
            const int period = 2 * n;
            int t = i % period;
            if (t < 0) t += period;
            return t < n ? t : period - 1 - t;
        }
    }
    return 0;
}

int floor_to_int(float x) {
    // Clamped so that uv far outside the unit square (or NaN) still gives a valid index.
    if (!(x > -1e9f)) return -1000000000;
    if (x > 1e9f) return 1000000000;
    return int(std::floor(x));
}

}  // namespace

vec3 BitmapTexture::eval(const TextureQuery& q) const {
    const TexelGrid& g = *texels;
    vec2 uv = to_uv.apply(q.uv);
    if (filter == TextureFilter::Nearest) {
        int x = wrap_index(floor_to_int(uv.x * float(g.width)), g.width, wrap);
        int y = wrap_index(floor_to_int(uv.y * float(g.height)), g.height, wrap);
        return g.texel(x, y);
    }
    // Texel centres at half integers: shift by half a texel, then weigh the four around.
    const float px = uv.x * float(g.width) - 0.5f, py = uv.y * float(g.height) - 0.5f;
    const int x0 = floor_to_int(px), y0 = floor_to_int(py);
    const float wx = px - float(x0), wy = py - float(y0);
    const int xa = wrap_index(x0, g.width, wrap), xb = wrap_index(x0 + 1, g.width, wrap);
    const int ya = wrap_index(y0, g.height, wrap), yb = wrap_index(y0 + 1, g.height, wrap);
    const vec3 v0 = (1.f - wx) * g.texel(xa, ya) + wx * g.texel(xb, ya);
    const vec3 v1 = (1.f - wx) * g.texel(xa, yb) + wx * g.texel(xb, yb);
    return (1.f - wy) * v0 + wy * v1;
}

float CheckerboardTexture::eval_1(const TextureQuery& q) const {
    vec2 uv = to_uv.apply(q.uv);
    const bool mu = uv.x - std::floor(uv.x) > 0.5f, mv = uv.y - std::floor(uv.y) > 0.5f;
    return mu == mv ? color1->eval_1(q) : color0->eval_1(q);
}

vec2 BitmapTexture::eval_1_grad(const TextureQuery& q) const {
    if (filter == TextureFilter::Nearest) return vec2(0.f);
    const TexelGrid& g = *texels;
    const vec2 uv = to_uv.apply(q.uv);
    const float px = uv.x * float(g.width) - 0.5f, py = uv.y * float(g.height) - 0.5f;
    const int x0 = floor_to_int(px), y0 = floor_to_int(py);
    const float wx = px - float(x0), wy = py - float(y0);
    const int xa = wrap_index(x0, g.width, wrap), xb = wrap_index(x0 + 1, g.width, wrap);
    const int ya = wrap_index(y0, g.height, wrap), yb = wrap_index(y0 + 1, g.height, wrap);
    const float f00 = luminance(g.texel(xa, ya)), f10 = luminance(g.texel(xb, ya));
    const float f01 = luminance(g.texel(xa, yb)), f11 = luminance(g.texel(xb, yb));
    // Per texel in x and y, then to (u, v): d(x, y)/d(u, v) = resolution * to_uv's linear part.
    const float dfx = (1.f - wy) * (f10 - f00) + wy * (f11 - f01);
    const float dfy = (1.f - wx) * (f01 - f00) + wx * (f11 - f10);
    const glm::mat3& m = to_uv.m;  // column-major: m[c][r]
    const float gx = dfx * float(g.width), gy = dfy * float(g.height);
    return vec2(m[0][0] * gx + m[0][1] * gy, m[1][0] * gx + m[1][1] * gy);
}

vec3 CheckerboardTexture::eval(const TextureQuery& q) const {
    vec2 uv = to_uv.apply(q.uv);
    const bool mu = uv.x - std::floor(uv.x) > 0.5f, mv = uv.y - std::floor(uv.y) > 0.5f;
    return mu == mv ? color0->eval(q) : color1->eval(q);
}

bool Texture::uses_vertex_colors() const {
    if (std::holds_alternative<MeshAttributeTexture>(v)) return true;
    if (const auto* c = std::get_if<CheckerboardTexture>(&v))
        return c->color0->uses_vertex_colors() || c->color1->uses_vertex_colors();
    return false;
}

std::shared_ptr<const TexelGrid> load_texels(const std::string& path, bool raw) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(path, 0, "texture file not found");
    auto g = std::make_shared<TexelGrid>();
    const std::string ext = file_extension(path);
    if (ext == ".exr" || ext == ".pfm") {
        Image img = read_linear_image(path);  // linear already; `raw` changes nothing
        g->width = img.width;
        g->height = img.height;
        g->channels = 3;
        g->data = std::move(img.rgb);
    } else {
        int w = 0, h = 0, n = 0;
        if (!jpeg_huffman_tables_valid(path)) throw Error(path, 0, "cannot decode image: corrupt JPEG Huffman table");
        if (!stbi_info(path.c_str(), &w, &h, &n))
            throw Error(path, 0, std::string("cannot read image: ") + stbi_failure_reason());
        // Images of more than 2^28 texels would need gigabytes as floats; refuse them before
        // decoding (stb_image would try).
        if (w <= 0 || h <= 0 || double(w) * double(h) > double(1 << 28))
            throw Error(path, 0, "image size " + std::to_string(w) + "x" + std::to_string(h) + " is not supported");
        const int want = (n == 1 || n == 2) ? 1 : 3;  // grey (+alpha) or colour (+alpha); alpha dropped
        g->width = w;
        g->height = h;
        g->channels = want;
        g->data.resize(size_t(w) * size_t(h) * size_t(want));
        if (stbi_is_hdr(path.c_str())) {
            float* px = stbi_loadf(path.c_str(), &w, &h, &n, want);
            if (!px) throw Error(path, 0, std::string("cannot decode image: ") + stbi_failure_reason());
            std::copy(px, px + g->data.size(), g->data.begin());
            stbi_image_free(px);
        } else {
            const bool sixteen = stbi_is_16_bit(path.c_str());
            const float scale = sixteen ? 1.f / 65535.f : 1.f / 255.f;
            void* px = sixteen ? static_cast<void*>(stbi_load_16(path.c_str(), &w, &h, &n, want))
                               : static_cast<void*>(stbi_load(path.c_str(), &w, &h, &n, want));
            if (!px) throw Error(path, 0, std::string("cannot decode image: ") + stbi_failure_reason());
            for (size_t i = 0; i < g->data.size(); ++i) {
                float v = float(sixteen ? static_cast<const uint16_t*>(px)[i] : static_cast<const uint8_t*>(px)[i]) * scale;
                g->data[i] = raw ? v : srgb_to_linear(v);
            }
            stbi_image_free(px);
        }
    }
    for (float v : g->data)
        if (!std::isfinite(v)) throw Error(path, 0, "image has a NaN or infinite texel");
    return g;
}

}  // namespace candela
