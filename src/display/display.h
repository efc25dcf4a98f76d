#pragma once
// The display transform, shared by the viewer window and headless PNG output: the film's linear
// RGB goes to a float texture, and the shaders in shaders/ apply exposure (2^stops) and the sRGB
// transfer function. There is one tonemap implementation, in GLSL; C++ never re-implements it.
namespace candela {

struct DisplaySettings {
    float exposure = 0.f;  // stops: the image is multiplied by 2^exposure before encoding
};

// How a texel is picked when the image is drawn larger or smaller than its size (a reduced-
// resolution preview scaled up to the window, say).
enum class DisplayFilter { Nearest, Linear };

// A rectangle of the framebuffer in GL window coordinates: pixels, origin at the bottom-left.
// (ImGui and GLFW count y from the top: y_gl = framebuffer_height - y_top - height.)
struct DisplayRect {
    int x = 0, y = 0, width = 0, height = 0;
};

// The largest rectangle with the image's aspect ratio that fits in `area`, centred in it
// (letterboxed). Empty when the image or the area is empty.
DisplayRect fit_image_rect(int image_width, int image_height, const DisplayRect& area);

}  // namespace candela
