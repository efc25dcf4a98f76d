// --screenshot-after N FILE: the window's framebuffer, panel included, as a PNG.
#include <cstdio>
#include "headless/headless.h"
#include "viewer/window.h"

namespace candela {

bool Viewer::write_screenshot() {
    // The window's own framebuffer, before the swap.
    std::vector<unsigned char> rgba(size_t(fb_w_) * size_t(fb_h_) * 4), flipped(rgba.size());
    gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl_.ReadPixels(0, 0, fb_w_, fb_h_, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    check_gl_error(gl_, "screenshot");
    const size_t row = size_t(fb_w_) * 4;
    for (int y = 0; y < fb_h_; ++y)  // GL rows run bottom-up
        std::copy_n(&rgba[size_t(fb_h_ - 1 - y) * row], row, &flipped[size_t(y) * row]);
    write_png_srgb8(opt_.screenshot, fb_w_, fb_h_, flipped);
    // The layout in image coordinates (top-left origin), for tests that inspect the picture.
    const int top = fb_h_ - image_rect_.y - image_rect_.height;
    const int panel_x = area_.width;
    std::printf("candela: screenshot %s: window %dx%d, image %d,%d %dx%d, panel %d,%d %dx%d, %.0f spp\n",
                opt_.screenshot.c_str(), fb_w_, fb_h_, image_rect_.x, top, image_rect_.width, image_rect_.height,
                panel_x, 0, fb_w_ - panel_x, fb_h_, fe_->stats().spp);
    std::fflush(stdout);
    return true;
}

}  // namespace candela
