// The tonemapped image in the window, and PNGs saved through the same display program.
#include <algorithm>
#include "core/error.h"
#include "viewer/window.h"

namespace candela {

void ensure_color_target(const GlApi& gl, unsigned& fbo, unsigned& tex, int& cur_w, int& cur_h, int w, int h) {
    if (w == cur_w && h == cur_h && fbo && tex) return;
    if (!tex) gl.GenTextures(1, &tex);
    if (!fbo) gl.GenFramebuffers(1, &fbo);
    gl.BindTexture(GL_TEXTURE_2D, tex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE) throw Error("viewer: the display cache framebuffer is incomplete");
    cur_w = w;
    cur_h = h;
}

void Viewer::release_gl() {
    saver_.reset();
    program_.reset();  // GL objects die with the context still current
    if (cache_fbo_) gl_.DeleteFramebuffers(1, &cache_fbo_);
    if (cache_tex_) gl_.DeleteTextures(1, &cache_tex_);
    if (small_fbo_) gl_.DeleteFramebuffers(1, &small_fbo_);
    if (small_tex_) gl_.DeleteTextures(1, &small_tex_);
}

void Viewer::update_display_cache() {
    const SessionImage& image = fe_->image();
    const int w = image_rect_.width, h = image_rect_.height;
    if (image.rgb.empty() || w <= 0 || h <= 0) return;
    if (cache_valid_ && w == cache_w_ && h == cache_h_ && display_.exposure == cache_exposure_) return;
    ensure_color_target(gl_, cache_fbo_, cache_tex_, cache_w_, cache_h_, w, h);
    if (image.preview && image.width < w && image.height < h) {
        // A preview is tonemapped at its own size (1/16 of the pixels), then scaled up by a
        // bilinear blit: in a software GL a full-size shader pass per preview would cost more than
        // the preview itself. (Filtering after the display transform, not before as for the full
        // image; it is a stand-in until the full pass.)
        ensure_color_target(gl_, small_fbo_, small_tex_, small_w_, small_h_, image.width, image.height);
        gl_.BindFramebuffer(GL_FRAMEBUFFER, small_fbo_);
        program_->draw({0, 0, image.width, image.height}, display_, DisplayFilter::Nearest);
        gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, small_fbo_);
        gl_.BindFramebuffer(GL_DRAW_FRAMEBUFFER, cache_fbo_);
        gl_.BlitFramebuffer(0, 0, image.width, image.height, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_LINEAR);
    } else {
        gl_.BindFramebuffer(GL_FRAMEBUFFER, cache_fbo_);
        program_->draw({0, 0, w, h}, display_, image.preview ? DisplayFilter::Linear : DisplayFilter::Nearest);
    }
    gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
    check_gl_error(gl_, "display cache");
    cache_valid_ = true;
    cache_exposure_ = display_.exposure;
}

void Viewer::save_png(const std::string& path) {
    SessionImage img = fe_->session().latest_full_image();
    if (img.rgb.empty()) return fe_->set_status("nothing to save yet: no full pass has finished", true);
    try {
        // Through the display program, as headless PNGs; a second program keeps the on-screen
        // texture untouched. Encoding and writing happen off the window's thread.
        if (!saver_) saver_ = std::make_unique<DisplayProgram>(gl_);
        saver_->upload(img.width, img.height, img.rgb.data());
        fe_->save_png(path, img, saver_->read_srgb8(display_));
    } catch (const std::exception& e) {
        fe_->set_status(e.what(), true);
    }
}

}  // namespace candela
