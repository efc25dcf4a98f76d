#include "headless/headless.h"

#include <GL/osmesa.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

// The one stb_image_write implementation of the whole program lives here: do not define
// STB_IMAGE_WRITE_IMPLEMENTATION in any other file (include <stb/stb_image_write.h> and link
// candela_display instead).
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#include "core/error.h"
#include "display/display_program.h"
#include "display/gl_api.h"

namespace candela {

HeadlessGlContext::HeadlessGlContext() {
    // A test hook (documented in docs/reliability.md): the fallback of a failed PNG is tested
    // without breaking Mesa.
    if (std::getenv("CANDELA_TEST_FAIL_GL"))
        throw Error("OSMesa: cannot create an OpenGL context (CANDELA_TEST_FAIL_GL is set)");
    // Core profile 3.3: the display shaders are GLSL 330 core. llvmpipe answers with 4.5.
    const int attribs[] = {OSMESA_FORMAT,                OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,            0,
                           OSMESA_STENCIL_BITS,          0,
                           OSMESA_PROFILE,               OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 3,
                           OSMESA_CONTEXT_MINOR_VERSION, 3,
                           0};
    OSMesaContext ctx = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!ctx)
        throw Error("OSMesa: cannot create an OpenGL 3.3 core profile context "
                    "(OSMesaCreateContextAttribs failed; is Mesa's llvmpipe/softpipe available?)");
    ctx_ = ctx;
    // OSMesa needs a colour buffer to make the context current; we render into FBOs, so 1x1 will do.
    buffer_.assign(4, 0);
    if (!OSMesaMakeCurrent(ctx, buffer_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
        OSMesaDestroyContext(ctx);
        throw Error("OSMesa: cannot make the context current");
    }
    try {
        // OSMesaGetProcAddress returns OSMESAproc, the same shape as GlProc.
        gl_ = std::make_unique<GlApi>(load_gl_api(&OSMesaGetProcAddress));
    } catch (...) {
        OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
        OSMesaDestroyContext(ctx);
        throw;
    }
}

HeadlessGlContext::~HeadlessGlContext() {
    OSMesaContext ctx = static_cast<OSMesaContext>(ctx_);
    if (OSMesaGetCurrentContext() == ctx) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(ctx);
}

std::string HeadlessGlContext::description() const {
    auto str = [&](GLenum name) {
        const GLubyte* s = gl_->GetString(name);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
    };
    return str(GL_RENDERER) + ", " + str(GL_VERSION);
}

std::vector<unsigned char> display_to_srgb8(const Image& img, const DisplaySettings& ds, int max_tile) {
    if (img.width <= 0 || img.height <= 0 || img.rgb.size() != size_t(img.width) * size_t(img.height) * 3)
        throw Error("display: bad image (" + std::to_string(img.width) + "x" + std::to_string(img.height) +
                    ", " + std::to_string(img.rgb.size()) + " floats)");
    // A fresh context per call: OSMesa contexts must not be shared between threads, and PNG
    // output is rare enough that the setup cost (a few ms on llvmpipe) does not matter.
    HeadlessGlContext context;
    const GlApi& gl = context.gl();
    DisplayProgram program(gl);
    // Tiles no larger than the texture and viewport limits (16384 on llvmpipe), so that any image
    // the film allows gets its PNG. Each pixel's byte depends only on its own texel (nearest, at
    // the image's own size), so the tiles assemble into exactly the untiled result.
    GLint max_texture = 0, max_viewport[2] = {0, 0};
    gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture);
    gl.GetIntegerv(GL_MAX_VIEWPORT_DIMS, max_viewport);
    int tile = std::min({int(max_texture), int(max_viewport[0]), int(max_viewport[1])});
    if (max_tile > 0) tile = std::min(tile, max_tile);
    if (tile <= 0) throw Error("display: GL reports no texture or viewport size");
    if (img.width <= tile && img.height <= tile) {
        program.upload(img);
        return program.read_srgb8(ds);
    }
    std::vector<unsigned char> out(size_t(img.width) * size_t(img.height) * 4);
    std::vector<float> part;
    for (int y0 = 0; y0 < img.height; y0 += tile)
        for (int x0 = 0; x0 < img.width; x0 += tile) {
            const int tw = std::min(tile, img.width - x0), th = std::min(tile, img.height - y0);
            part.resize(size_t(tw) * size_t(th) * 3);
            for (int y = 0; y < th; ++y)
                std::memcpy(part.data() + size_t(y) * size_t(tw) * 3,
                            img.rgb.data() + (size_t(y0 + y) * size_t(img.width) + size_t(x0)) * 3,
                            size_t(tw) * 3 * sizeof(float));
            program.upload(tw, th, part.data());
            const std::vector<unsigned char> rgba = program.read_srgb8(ds);
            for (int y = 0; y < th; ++y)
                std::memcpy(out.data() + (size_t(y0 + y) * size_t(img.width) + size_t(x0)) * 4,
                            rgba.data() + size_t(y) * size_t(tw) * 4, size_t(tw) * 4);
        }
    return out;
}

namespace {
void append_bytes(void* context, void* data, int size) {
    auto* out = static_cast<std::vector<unsigned char>*>(context);
    const auto* bytes = static_cast<const unsigned char*>(data);
    out->insert(out->end(), bytes, bytes + size);
}
}  // namespace

void write_png_srgb8(const std::string& path, int width, int height, const std::vector<unsigned char>& rgba) {
    if (width <= 0 || height <= 0 || rgba.size() != size_t(width) * size_t(height) * 4)
        throw Error(path, 0, "bad RGBA8 buffer for a " + std::to_string(width) + "x" + std::to_string(height) + " PNG");
    // The alpha channel is always opaque: drop it, the file is a quarter smaller.
    std::vector<unsigned char> rgb(size_t(width) * size_t(height) * 3);
    for (size_t i = 0, n = size_t(width) * size_t(height); i < n; ++i)
        for (int c = 0; c < 3; ++c) rgb[3 * i + c] = rgba[4 * i + c];
    std::vector<unsigned char> png;
    if (!stbi_write_png_to_func(append_bytes, &png, width, height, 3, rgb.data(), width * 3) || png.empty())
        throw Error(path, 0, "PNG encoding failed");
    write_file_atomic(path, png.data(), png.size());
}

void write_png_headless(const std::string& path, const Image& img, const DisplaySettings& ds) {
    std::vector<unsigned char> rgba;
    try {
        rgba = display_to_srgb8(img, ds);
    } catch (const Error& e) {
        throw Error(path, 0, e.what());  // name the file the caller asked for
    }
    write_png_srgb8(path, img.width, img.height, rgba);
}

}  // namespace candela
