#pragma once
#include <memory>
#include <string>
#include <vector>
#include "display/display.h"
#include "film/image_io.h"

namespace candela {

struct GlApi;

// Renders the linear image through the display shaders in an off-screen OSMesa GL 3.3+ core
// context and returns 8-bit sRGB RGBA pixels, top row first. Needs no DISPLAY. Images larger
// than GL's texture or viewport limit are drawn in tiles (at most `max_tile` pixels a side when
// > 0, for tests) and assembled on the CPU: the bytes equal those of one untiled draw. Throws
// Error when OSMesa or the shaders fail (with the GL info log), or when CANDELA_TEST_FAIL_GL is
// set in the environment (a test hook).
std::vector<unsigned char> display_to_srgb8(const Image& img, const DisplaySettings& ds, int max_tile = 0);

// display_to_srgb8, then an atomic PNG write (stb_image_write).
void write_png_headless(const std::string& path, const Image& img, const DisplaySettings& ds);

// Encodes RGBA8 pixels (top row first, as display_to_srgb8 and DisplayProgram::read_srgb8 return
// them) as an RGB PNG and writes it atomically. The viewer saves its PNGs through this too.
void write_png_srgb8(const std::string& path, int width, int height, const std::vector<unsigned char>& rgba);

// An OSMesa GL 3.3+ core profile context, current on the creating thread for its lifetime, with
// its GL table loaded through OSMesaGetProcAddress. Rendering goes to framebuffer objects (the
// OSMesa buffer itself is 1x1). Not thread-safe: create, use and destroy it on one thread.
// Making it current replaces whatever context the thread had; a GLFW window must call
// glfwMakeContextCurrent again afterwards.
class HeadlessGlContext {
public:
    HeadlessGlContext();  // throws Error when OSMesa cannot make a 3.3 core context
    ~HeadlessGlContext();  // destroys the context; no OSMesa context is current afterwards
    HeadlessGlContext(const HeadlessGlContext&) = delete;
    HeadlessGlContext& operator=(const HeadlessGlContext&) = delete;

    const GlApi& gl() const { return *gl_; }
    // GL_RENDERER and GL_VERSION, for logs ("llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa").
    std::string description() const;

private:
    void* ctx_ = nullptr;  // OSMesaContext, kept opaque so that <GL/osmesa.h> stays out of here
    std::vector<unsigned char> buffer_;
    std::unique_ptr<GlApi> gl_;
};

}  // namespace candela
