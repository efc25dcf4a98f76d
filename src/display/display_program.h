#pragma once
// The GL side of the display: the shaders of shaders/ compiled into one program, the image as a
// float texture, and a draw call. The viewer window and headless OSMesa both use this class.
#include <memory>
#include <string>
#include <vector>

#include "display/display.h"
#include "film/image_io.h"

namespace candela {

struct GlApi;

// Where display.vert / display.frag come from: the files in `shader_dir` when readable (edit and
// rerun without rebuilding), else the copies embedded in the binary at build time (an installed
// binary works without the source tree). Pass "" to use the embedded copies only.
struct ShaderSource {
    std::string origin;  // the file path, or "<embedded>/display.frag"
    std::string text;
};
ShaderSource load_display_shader(const std::string& shader_dir, const std::string& name);
// The source tree's shaders/ folder, as configured (compiled into display_program.cpp alone).
const char* default_shader_dir();

class DisplayProgram {
public:
    // Compiles and links the shaders in the context current on this thread (GL 3.3 core or later)
    // using `gl`, a table loaded for that context. Throws Error with the shader file and the GL
    // info log on failure. The table is copied.
    explicit DisplayProgram(const GlApi& gl, const std::string& shader_dir = default_shader_dir());
    // Deletes the GL objects: the same context must still be current.
    ~DisplayProgram();
    DisplayProgram(const DisplayProgram&) = delete;
    DisplayProgram& operator=(const DisplayProgram&) = delete;

    // Uploads a linear RGB float image (row-major from the top-left, 3 floats per pixel) as a
    // GL_RGB32F texture. Storage is reallocated only when the size changes, so uploading the film
    // every frame is cheap. Throws Error when the size exceeds GL_MAX_TEXTURE_SIZE.
    void upload(int width, int height, const float* rgb);
    void upload(const Image& img) { upload(img.width, img.height, img.rgb.data()); }
    int width() const { return width_; }
    int height() const { return height_; }

    // Draws the uploaded image stretched over `rect` of the currently bound draw framebuffer
    // (its size need not match the image's: fit_image_rect keeps the aspect ratio). The pixels
    // outside `rect` are untouched. GL state it changes (program, VAO, texture unit 0, viewport,
    // blend/depth/cull/scissor/sRGB enables) is restored before it returns, so an ImGui frame
    // can follow. Does nothing before the first upload.
    void draw(const DisplayRect& rect, const DisplaySettings& ds,
              DisplayFilter filter = DisplayFilter::Nearest) const;

    // Draws the image at its own size into an off-screen RGBA8 framebuffer and reads it back:
    // sRGB bytes, 4 per pixel, top row first. Used for PNG output (headless, or "save" in the
    // viewer without leaving its context). Restores the framebuffer bindings and viewport.
    std::vector<unsigned char> read_srgb8(const DisplaySettings& ds) const;

    // Where the shaders came from (file paths or <embedded>/...), for diagnostics.
    const std::string& shader_origin() const { return origin_; }

private:
    std::unique_ptr<GlApi> gl_;
    unsigned program_ = 0, vao_ = 0, texture_ = 0;
    int loc_image_ = -1, loc_exposure_ = -1, loc_linear_ = -1;
    int width_ = 0, height_ = 0;
    std::string origin_;
};

}  // namespace candela
