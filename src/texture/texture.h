#pragma once
// Textures: parameters that vary over a surface (Mitsuba 3 `bitmap`, `checkerboard`,
// `mesh_attribute`; a constant is a texture too). A closed set dispatched by std::visit, evaluated at
// a TextureQuery: the surface point's uv (after the shape's own uv conventions) and, for
// mesh_attribute, the interpolated vertex colour. Values are linear RGB; eval_1 is the scalar a
// float parameter reads (the luminance of an RGB texture, as Mitsuba's eval_1).
#include <memory>
#include <string>
#include <variant>
#include <vector>
#include "core/math.h"

namespace candela {

struct TextureQuery {
    vec2 uv{0.f};
    vec3 vertex_color{0.f};
};

// An affine map of uv (Mitsuba's `to_uv`: a 3x3 transform, or the upper-left 3x3 of a 4x4 without
// its third row and column, i.e. the xy part and the translation).
struct UvTransform {
    glm::mat3 m{1.f};
    vec2 apply(vec2 uv) const { return vec2(m * vec3(uv, 1.f)); }
    static UvTransform from_mat4(const mat4& t);
};

// Texels as loaded: row-major from the top row (v = 0 is the image's top, as Mitsuba), linear
// values, 1 or 3 channels.
struct TexelGrid {
    int width = 0, height = 0, channels = 3;
    std::vector<float> data;
    vec3 texel(int x, int y) const {
        const float* p = &data[(size_t(y) * size_t(width) + size_t(x)) * size_t(channels)];
        return channels == 3 ? vec3(p[0], p[1], p[2]) : vec3(p[0]);
    }
};

enum class TextureFilter { Bilinear, Nearest };
enum class TextureWrap { Repeat, Mirror, Clamp };

struct ConstantTexture {
    vec3 value{0.f};
};

// Mitsuba's `bitmap`: the texel grid looked up at to_uv(uv) * resolution, texel centres at half
// integers; bilinear between the four nearest texels (each wrapped) or the nearest one.
struct BitmapTexture {
    std::shared_ptr<const TexelGrid> texels;
    TextureFilter filter = TextureFilter::Bilinear;
    TextureWrap wrap = TextureWrap::Repeat;
    UvTransform to_uv;
    std::string name;  // file name, for messages and the viewer

    vec3 eval(const TextureQuery& q) const;
    // d eval_1 / d(u, v), as Mitsuba's bitmap eval_1_grad: the derivative of the bilinear
    // interpolation of the luminance within the texel cell around uv (times the resolution and
    // through to_uv); 0 for nearest filtering (piecewise constant).
    vec2 eval_1_grad(const TextureQuery& q) const;
};

struct Texture;

// Mitsuba's `checkerboard`: color0 where the fractional parts of u and v are both above or both
// below 1/2, color1 elsewhere. Either colour may itself be a texture.
struct CheckerboardTexture {
    std::shared_ptr<const Texture> color0, color1;
    UvTransform to_uv;

    vec3 eval(const TextureQuery& q) const;
    // The scalar a float parameter (blendbsdf weight, mask opacity, bump height) reads. Mitsuba
    // 3.9.1's checkerboard eval_1 has the two colours the other way round from its eval (color1
    // where eval gives color0; checked with its Python bindings): candela follows it, so that a
    // checkerboard weight or opacity means what it means in Mitsuba scenes.
    float eval_1(const TextureQuery& q) const;
};

// Mitsuba's `mesh_attribute` with name "vertex_color": the mesh's interpolated vertex colours.
struct MeshAttributeTexture {
    std::string name = "vertex_color";
    vec3 eval(const TextureQuery& q) const { return q.vertex_color; }
};

struct Texture {
    std::variant<ConstantTexture, BitmapTexture, CheckerboardTexture, MeshAttributeTexture> v;

    vec3 eval(const TextureQuery& q) const {
        return std::visit([&](const auto& t) -> vec3 {
            if constexpr (std::is_same_v<std::decay_t<decltype(t)>, ConstantTexture>) return t.value;
            else return t.eval(q);
        }, v);
    }
    float eval_1(const TextureQuery& q) const {
        if (const CheckerboardTexture* c = std::get_if<CheckerboardTexture>(&v)) return c->eval_1(q);
        return luminance(eval(q));
    }
    // The gradient of eval_1 in uv (bumpmap's height slope). Only a bitmap varies smoothly; a
    // constant, a checkerboard (piecewise constant) and vertex colours (not a function of uv)
    // give 0.
    vec2 eval_1_grad(const TextureQuery& q) const {
        if (const BitmapTexture* b = std::get_if<BitmapTexture>(&v)) return b->eval_1_grad(q);
        return vec2(0.f);
    }
    bool is_constant() const { return std::holds_alternative<ConstantTexture>(v); }
    // Whether it reads the mesh's vertex colours (the mesh must then store them).
    bool uses_vertex_colors() const;
};

inline Texture constant_texture(vec3 c) { return Texture{ConstantTexture{c}}; }

// Images of more than 2^28 texels would need gigabytes as floats: refused before decoding.
constexpr long long kMaxTexels = 1LL << 28;

// Reads an image for a bitmap texture, by its contents (not its extension), as Mitsuba 3 reads
// them: PNG, JPEG, BMP, TGA, PPM/PGM (8 or 16 bit, decoded from sRGB unless `raw`), Radiance HDR,
// and EXR or PFM (linear float). Grey images keep one channel; alpha is dropped. Throws Error
// naming the file for a missing, unreadable, corrupt, truncated, empty or unsupported image (GIF,
// PSD and PIC are refused: Mitsuba does not read them either).
std::shared_ptr<const TexelGrid> load_texels(const std::string& path, bool raw);

// The sRGB transfer function, decoded (IEC 61966-2-1, as Mitsuba's Bitmap conversion).
float srgb_to_linear(float v);

}  // namespace candela
