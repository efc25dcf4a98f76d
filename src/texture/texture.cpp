#include "texture/texture.h"
#include <cmath>
#include <cstdint>
#include <filesystem>
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
