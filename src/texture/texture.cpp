#include "texture/texture.h"
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <type_traits>
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
// JPEG goes to libjpeg-turbo, PGM/PPM to decode_pnm and Radiance HDR to decode_rgbe
// (texture/decode.h); GIF, PSD and PIC are refused before decoding.
#define STBI_NO_JPEG
#define STBI_NO_PNM
#define STBI_NO_HDR
#define STBI_NO_GIF
#define STBI_NO_PSD
#define STBI_NO_PIC
#include <stb/stb_image.h>
#include "core/error.h"
#include "film/image_io.h"
#include "texture/decode.h"

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

namespace {

enum class ImageKind { Png, Jpeg, Pnm, Rgbe, Refused, Other };

// By magic number, as stb_image and libjpeg recognise them; TGA has none and falls in Other.
ImageKind image_kind(const std::vector<unsigned char>& b) {
    auto starts = [&](const char* m, size_t n) { return b.size() >= n && std::equal(m, m + n, b.begin(), [](char c, unsigned char u) { return uint8_t(c) == u; }); };
    if (starts("\x89PNG\r\n\x1a\n", 8)) return ImageKind::Png;
    if (starts("\xFF\xD8\xFF", 3)) return ImageKind::Jpeg;
    if (is_pnm(b)) return ImageKind::Pnm;
    if (is_rgbe(b)) return ImageKind::Rgbe;
    if (starts("GIF8", 4) || starts("8BPS", 4) || starts("\x53\x80\xF6\x34", 4)) return ImageKind::Refused;
    return ImageKind::Other;
}

// The most texels a byte of a file stb_image reads can hold (check_image_size). PNG: deflate
// expands at most 1032:1, times 8 one-bit texels a byte. BMP and TGA expand at most 64:1 (a TGA
// run of 128 one-byte texels in 2 bytes).
double texels_per_byte(ImageKind kind) { return kind == ImageKind::Png ? 1032.0 * 8.0 : 64.0; }

}  // namespace

bool image_size_ok(long long w, long long h, size_t bytes, double texels_per_byte) {
    const double texels = double(w) * double(h);
    return w > 0 && h > 0 && texels <= double(kMaxTexels) && (texels_per_byte <= 0 || texels <= texels_per_byte * double(bytes));
}

void check_image_size(const std::string& path, const char* format, long long w, long long h, size_t bytes,
                      double texels_per_byte) {
    if (image_size_ok(w, h, bytes, texels_per_byte)) return;
    const std::string size = std::to_string(w) + "x" + std::to_string(h);
    if (!image_size_ok(w, h, bytes, 0)) throw Error(path, 0, "image size " + size + " is not supported");
    throw Error(path, 0, std::string(format) + " claims " + size + " texels, more than its " + std::to_string(bytes) +
                             " bytes can hold (truncated or corrupt)");
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
        const std::vector<unsigned char> file = read_whole_file(path);
        const ImageKind kind = image_kind(file);
        if (kind == ImageKind::Refused)
            throw Error(path, 0, "unsupported image format (GIF, PSD and PIC are not read; use PNG, JPEG or EXR)");
        // A decoded 8- or 16-bit image, to floats: sRGB-decoded unless `raw`.
        auto to_floats = [&](const auto* px, float scale) {
            g->data.resize(size_t(g->width) * size_t(g->height) * size_t(g->channels));
            for (size_t i = 0; i < g->data.size(); ++i) {
                const float v = float(px[i]) * scale;
                g->data[i] = raw ? v : srgb_to_linear(v);
            }
        };
        if (kind == ImageKind::Jpeg || kind == ImageKind::Pnm) {
            const EncodedTexels t = kind == ImageKind::Jpeg ? decode_jpeg(path, file) : decode_pnm(path, file);
            g->width = t.width;
            g->height = t.height;
            g->channels = t.channels;
            to_floats(t.v.data(), 1.f);
        } else if (kind == ImageKind::Rgbe) {
            g->channels = 3;
            g->data = decode_rgbe(path, file, g->width, g->height);  // linear already
        } else {
            const stbi_uc* bytes = file.data();
            const int len = file.size() > size_t(INT32_MAX) ? INT32_MAX : int(file.size());
            int w = 0, h = 0, n = 0;
            if (!stbi_info_from_memory(bytes, len, &w, &h, &n))
                throw Error(path, 0, std::string("cannot read image: ") + stbi_failure_reason());
            check_image_size(path, "image", w, h, file.size(), texels_per_byte(kind));
            const int want = (n == 1 || n == 2) ? 1 : 3;  // grey (+alpha) or colour (+alpha); alpha dropped
            g->width = w;
            g->height = h;
            g->channels = want;
            auto fail = [&] { return Error(path, 0, std::string("cannot decode image: ") + stbi_failure_reason()); };
            auto owned = [&](auto* px) {
                if (!px) throw fail();
                return std::unique_ptr<std::remove_pointer_t<decltype(px)>, void (*)(void*)>(px, stbi_image_free);
            };
            if (stbi_is_16_bit_from_memory(bytes, len)) {
                to_floats(owned(stbi_load_16_from_memory(bytes, len, &w, &h, &n, want)).get(), 1.f / 65535.f);
            } else {
                to_floats(owned(stbi_load_from_memory(bytes, len, &w, &h, &n, want)).get(), 1.f / 255.f);
            }
        }
    }
    for (float v : g->data)
        if (!std::isfinite(v)) throw Error(path, 0, "image has a NaN or infinite texel");
    return g;
}

}  // namespace candela
