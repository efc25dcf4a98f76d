#pragma once
#include <string>
#include "display/display.h"
#include "film/image_io.h"

namespace candela {

// Renders the linear image through the display shaders in an off-screen OSMesa GL 3.3+ core
// context and returns 8-bit sRGB RGBA pixels, top row first. Needs no DISPLAY. Throws Error when
// OSMesa or the shaders fail (with the GL info log).
std::vector<unsigned char> display_to_srgb8(const Image& img, const DisplaySettings& ds);

// display_to_srgb8, then an atomic PNG write (stb_image_write).
void write_png_headless(const std::string& path, const Image& img, const DisplaySettings& ds);

}  // namespace candela
