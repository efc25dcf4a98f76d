// The display path: shaders (exposure, sRGB, NaN), the GL program in an OSMesa context, and PNG
// output. Runs without DISPLAY; every GL call goes through the OSMesa-loaded table.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

// A private PNG decoder for checking the files (static, so it cannot clash with any other copy).
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>

#include "core/error.h"
#include "display/display.h"
#include "display/display_program.h"
#include "display/gl_api.h"
#include "headless/headless.h"

namespace fs = std::filesystem;
using candela::DisplayFilter;
using candela::DisplayProgram;
using candela::DisplayRect;
using candela::DisplaySettings;
using candela::Error;
using candela::Image;

namespace {

// The reference transform in double precision: what the shader must produce.
int expected_byte(double v, double exposure) {
    if (std::isnan(v)) return 0;
    double c = std::clamp(v * std::exp2(exposure), 0.0, 1.0);
    double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return int(std::lround(255.0 * std::clamp(s, 0.0, 1.0)));
}

Image constant_image(int w, int h, float v) {
    Image img;
    img.width = w;
    img.height = h;
    img.rgb.assign(size_t(w) * size_t(h) * 3, v);
    return img;
}

const float kNaN = std::numeric_limits<float>::quiet_NaN();
const float kInf = std::numeric_limits<float>::infinity();

// An RGBA8 framebuffer object standing in for a window: bound on creation, cleared to blue.
struct TestTarget {
    const candela::GlApi& gl;
    int width, height;
    GLuint tex = 0, fbo = 0;
    TestTarget(const candela::GlApi& g, int w, int h) : gl(g), width(w), height(h) {
        gl.GenTextures(1, &tex);
        gl.BindTexture(GL_TEXTURE_2D, tex);
        gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
        gl.GenFramebuffers(1, &fbo);
        gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
        gl.Viewport(0, 0, w, h);
        clear();
    }
    ~TestTarget() {
        gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        gl.DeleteFramebuffers(1, &fbo);
        gl.DeleteTextures(1, &tex);
    }
    bool complete() const { return gl.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE; }
    void clear() {
        gl.ClearColor(0.f, 0.f, 1.f, 1.f);
        gl.Clear(GL_COLOR_BUFFER_BIT);
    }
    // RGBA8 pixels in GL order (bottom row first).
    std::vector<unsigned char> read() const {
        std::vector<unsigned char> px(size_t(width) * size_t(height) * 4);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
        gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
        return px;
    }
};

}  // namespace

TEST(Display, ConstantImagesMatchTheSrgbTransfer) {
    const float values[] = {0.f, 0.0031308f, 0.18f, 0.5f, 1.f, 4.f, kNaN};
    const float exposures[] = {0.f, 1.f, -2.f};
    for (float v : values)
        for (float e : exposures) {
            DisplaySettings ds;
            ds.exposure = e;
            const std::vector<unsigned char> px = candela::display_to_srgb8(constant_image(5, 3, v), ds);
            ASSERT_EQ(px.size(), size_t(5 * 3 * 4));
            const int want = expected_byte(v, e);
            for (size_t i = 0; i < px.size(); i += 4) {
                for (int c = 0; c < 3; ++c)
                    ASSERT_NEAR(int(px[i + size_t(c)]), want, 1) << "v=" << v << " exposure=" << e;
                ASSERT_EQ(px[i + 3], 255);
            }
        }
}

// Many values in one image, one context: a dense check of the curve, the linear segment around
// the 0.0031308 knee, and the non-finite inputs.
TEST(Display, ValueStripMatchesTheSrgbTransfer) {
    std::vector<float> values = {0.f,     1e-6f,  0.001f, 0.003f,  0.0031308f, 0.0032f, 0.01f, 0.05f,
                                 0.1f,    0.18f,  0.2f,   0.214f,  0.3f,       0.5f,    0.7f,  0.9f,
                                 0.99f,   1.f,    1.5f,   100.f,   3e38f,      kInf,    -kInf, -0.5f,
                                 kNaN,    -kNaN};
    for (int i = 0; i <= 64; ++i) values.push_back(float(i) / 64.f);
    Image img;
    img.width = int(values.size());
    img.height = 1;
    for (float v : values) img.rgb.insert(img.rgb.end(), {v, v, v});

    candela::HeadlessGlContext context;
    DisplayProgram program(context.gl());
    program.upload(img);
    for (float e : {0.f, 1.f, -2.f, 0.5f}) {
        DisplaySettings ds;
        ds.exposure = e;
        const std::vector<unsigned char> px = program.read_srgb8(ds);
        for (size_t i = 0; i < values.size(); ++i) {
            const double v = values[i];
            const int want = std::isinf(v) ? (v > 0 ? 255 : 0) : expected_byte(v, e);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(int(px[4 * i + size_t(c)]), want, 1) << "v=" << v << " exposure=" << e;
        }
    }
}

TEST(Display, NaNDoesNotSpreadToNeighbours) {
    // One NaN channel in the middle of a bright image: only that channel of that pixel goes dark.
    Image img = constant_image(3, 3, 0.5f);
    img.rgb[3 * 4 + 1] = kNaN;
    const int bright = expected_byte(0.5, 0);
    const std::vector<unsigned char> px = candela::display_to_srgb8(img, {});
    for (int i = 0; i < 9; ++i)
        for (int c = 0; c < 3; ++c) {
            const int want = (i == 4 && c == 1) ? 0 : bright;
            EXPECT_NEAR(int(px[4 * size_t(i) + size_t(c)]), want, 1) << "pixel " << i << " channel " << c;
        }

    // Scaled up with bilinear filtering, the NaN texel counts as 0: its neighbours blend towards
    // it but never turn black (a NaN inside the filter would make the whole footprint 0), and the
    // other channels are untouched.
    candela::HeadlessGlContext context;
    DisplayProgram program(context.gl());
    program.upload(img);
    TestTarget target(context.gl(), 30, 30);
    ASSERT_TRUE(target.complete());
    program.draw({0, 0, 30, 30}, {}, DisplayFilter::Linear);
    const std::vector<unsigned char> up = target.read();
    for (size_t i = 0; i < up.size(); i += 4) {
        ASSERT_NEAR(int(up[i]), bright, 1) << "pixel " << i / 4;
        ASSERT_GT(int(up[i + 1]), 0) << "NaN spread to pixel " << i / 4;
        ASSERT_NEAR(int(up[i + 2]), bright, 1) << "pixel " << i / 4;
    }
}

TEST(Display, GradientKeepsOrientationAndOddSizesWork) {
    // Red grows to the right, green grows downwards; 37x19 has rows that are not a multiple of
    // 4 floats, catching pack/unpack alignment and row-flip mistakes.
    const int w = 37, h = 19;
    Image img;
    img.width = w;
    img.height = h;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) img.rgb.insert(img.rgb.end(), {float(x) / (w - 1), float(y) / (h - 1), 0.25f});
    const std::vector<unsigned char> px = candela::display_to_srgb8(img, {});
    ASSERT_EQ(px.size(), size_t(w * h * 4));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const unsigned char* p = &px[4 * (size_t(y) * w + size_t(x))];
            ASSERT_NEAR(int(p[0]), expected_byte(double(float(x) / (w - 1)), 0), 1) << x << "," << y;
            ASSERT_NEAR(int(p[1]), expected_byte(double(float(y) / (h - 1)), 0), 1) << x << "," << y;
            ASSERT_NEAR(int(p[2]), expected_byte(0.25, 0), 1) << x << "," << y;
        }
    EXPECT_EQ(px[0], 0);                         // top-left: black-ish red and green
    EXPECT_EQ(px[4 * size_t(w - 1)], 255);       // top-right: full red
    EXPECT_EQ(px[4 * size_t((h - 1) * w) + 1], 255);  // bottom-left: full green
}

TEST(Display, BadImagesThrow) {
    Image img = constant_image(2, 2, 1.f);
    img.rgb.pop_back();
    EXPECT_THROW(candela::display_to_srgb8(img, {}), Error);
    EXPECT_THROW(candela::display_to_srgb8(Image{}, {}), Error);
}

TEST(Display, FitImageRect) {
    using candela::fit_image_rect;
    auto eq = [](DisplayRect a, DisplayRect b) {
        return a.x == b.x && a.y == b.y && a.width == b.width && a.height == b.height;
    };
    EXPECT_TRUE(eq(fit_image_rect(200, 100, {0, 0, 200, 100}), {0, 0, 200, 100}));
    EXPECT_TRUE(eq(fit_image_rect(100, 100, {10, 20, 300, 100}), {110, 20, 100, 100}));  // pillarbox
    EXPECT_TRUE(eq(fit_image_rect(200, 100, {0, 0, 100, 300}), {0, 125, 100, 50}));    // letterbox
    EXPECT_TRUE(eq(fit_image_rect(50, 25, {0, 0, 400, 200}), {0, 0, 400, 200}));       // upscaled preview
    EXPECT_EQ(fit_image_rect(0, 10, {0, 0, 10, 10}).width, 0);
    EXPECT_EQ(fit_image_rect(10, 10, {0, 0, 0, 10}).width, 0);
}

// draw() into a sub-rectangle of a larger framebuffer, the way the viewer shows the image beside
// its panel: pixels outside stay as they were, the image is scaled up, and GL state is restored.
TEST(Display, DrawsIntoSubRectangleAndRestoresState) {
    candela::HeadlessGlContext context;
    const candela::GlApi& gl = context.gl();
    DisplayProgram program(gl);

    // A 2x2 image: top row (1, 0), bottom row (0.18, 0.5) in red; green/blue zero.
    Image img;
    img.width = 2;
    img.height = 2;
    img.rgb = {1.f, 0, 0, 0, 0, 0, 0.18f, 0, 0, 0.5f, 0, 0};
    program.upload(img);

    const int fw = 64, fh = 48;
    TestTarget target(gl, fw, fh);
    ASSERT_TRUE(target.complete());
    gl.Enable(GL_BLEND);
    gl.Enable(GL_SCISSOR_TEST);  // ImGui leaves these on; draw() must not be affected by them
    gl.ActiveTexture(GL_TEXTURE3);

    const DisplayRect rect{10, 8, 20, 16};  // GL coordinates: origin bottom-left
    program.draw(rect, {}, DisplayFilter::Nearest);

    // State is as we left it.
    GLint viewport[4], active = 0, prog = 0;
    gl.GetIntegerv(GL_VIEWPORT, viewport);
    gl.GetIntegerv(GL_ACTIVE_TEXTURE, &active);
    gl.GetIntegerv(GL_CURRENT_PROGRAM, &prog);
    EXPECT_EQ(viewport[0], 0);
    EXPECT_EQ(viewport[2], fw);
    EXPECT_EQ(viewport[3], fh);
    EXPECT_EQ(active, GL_TEXTURE3);
    EXPECT_EQ(prog, 0);
    EXPECT_TRUE(gl.IsEnabled(GL_BLEND));
    EXPECT_TRUE(gl.IsEnabled(GL_SCISSOR_TEST));
    gl.Disable(GL_BLEND);
    gl.Disable(GL_SCISSOR_TEST);
    gl.ActiveTexture(GL_TEXTURE0);

    std::vector<unsigned char> px = target.read();
    ASSERT_EQ(gl.GetError(), GLenum(GL_NO_ERROR));
    auto at = [&](int x, int y) { return &px[4 * (size_t(y) * fw + size_t(x))]; };  // GL rows, bottom-up

    for (int y = 0; y < fh; ++y)
        for (int x = 0; x < fw; ++x) {
            const unsigned char* p = at(x, y);
            const bool inside = x >= rect.x && x < rect.x + rect.width && y >= rect.y && y < rect.y + rect.height;
            if (!inside) {
                ASSERT_EQ(p[2], 255) << "outside pixel " << x << "," << y << " was overwritten";
                continue;
            }
            // Each image pixel covers a 10x8 block; the top image row is at the top of the rect.
            const int ix = (x - rect.x) / 10;
            const int iy_top_down = 1 - (y - rect.y) / 8;
            const double v = img.rgb[3 * size_t(iy_top_down * 2 + ix)];
            ASSERT_NEAR(int(p[0]), expected_byte(v, 0), 1) << x << "," << y;
            ASSERT_EQ(p[1], 0);
            ASSERT_EQ(p[2], 0);
        }

    // Linear filtering of a black|white image scaled up: a monotone ramp between the two.
    Image bw;
    bw.width = 2;
    bw.height = 1;
    bw.rgb = {0, 0, 0, 1, 1, 1};
    program.upload(bw);
    target.clear();
    program.draw({0, 0, 16, 1}, {}, DisplayFilter::Linear);
    px = target.read();
    EXPECT_EQ(at(0, 0)[0], 0);
    EXPECT_EQ(at(15, 0)[0], 255);
    for (int x = 1; x < 16; ++x) EXPECT_GE(at(x, 0)[0], at(x - 1, 0)[0]);
    EXPECT_GT(at(8, 0)[0], 100);
    EXPECT_LT(at(8, 0)[0], 230);
}

TEST(Display, EmbeddedShadersMatchTheSourceTree) {
    for (const char* name : {"display.vert", "display.frag"}) {
        const auto file = candela::load_display_shader(candela::default_shader_dir(), name);
        const auto embedded = candela::load_display_shader("", name);
        EXPECT_EQ(file.origin, std::string(candela::default_shader_dir()) + "/" + name);
        EXPECT_EQ(embedded.origin, std::string("<embedded>/") + name);
        EXPECT_EQ(file.text, embedded.text) << "rerun cmake: the embedded copy of " << name << " is stale";
        // A missing shader directory falls back to the embedded copy.
        EXPECT_EQ(candela::load_display_shader("/nonexistent/candela", name).origin, embedded.origin);
    }
    // The embedded program renders the same as the one from files.
    candela::HeadlessGlContext context;
    DisplayProgram from_files(context.gl());
    DisplayProgram embedded(context.gl(), "");
    const Image img = constant_image(4, 4, 0.3f);
    from_files.upload(img);
    embedded.upload(img);
    EXPECT_EQ(from_files.read_srgb8({}), embedded.read_srgb8({}));
}

TEST(Display, ShaderErrorsNameTheFileAndCarryTheLog) {
    const fs::path dir = fs::temp_directory_path() / ("candela_bad_shader_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::ofstream(dir / "display.vert") << candela::load_display_shader("", "display.vert").text;
    std::ofstream(dir / "display.frag") << "#version 330 core\nout vec4 o;\nvoid main() { o = undefined_thing; }\n";
    candela::HeadlessGlContext context;
    try {
        DisplayProgram program(context.gl(), dir.string());
        FAIL() << "a broken shader compiled";
    } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find((dir / "display.frag").string()), std::string::npos) << msg;
        EXPECT_NE(msg.find("undefined_thing"), std::string::npos) << msg;  // the GL info log
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
    fs::remove_all(dir);
}

TEST(Display, PngIsWrittenAtomicallyAndDecodesToTheDisplayedPixels) {
    const fs::path dir = fs::temp_directory_path() / ("candela_png_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string path = (dir / "out.png").string();

    Image img;
    img.width = 7;
    img.height = 5;
    for (int i = 0; i < 35; ++i) img.rgb.insert(img.rgb.end(), {float(i) / 34.f, 0.5f, i == 3 ? kNaN : 0.1f});
    DisplaySettings ds;
    ds.exposure = 0.5f;
    candela::write_png_headless(path, img, ds);

    int w = 0, h = 0, n = 0;
    unsigned char* decoded = stbi_load(path.c_str(), &w, &h, &n, 3);
    ASSERT_NE(decoded, nullptr) << stbi_failure_reason();
    ASSERT_EQ(w, 7);
    ASSERT_EQ(h, 5);
    const std::vector<unsigned char> want = candela::display_to_srgb8(img, ds);
    for (int i = 0; i < 35; ++i)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(decoded[3 * i + c], want[4 * size_t(i) + size_t(c)]);
    stbi_image_free(decoded);

    size_t entries = 0;
    for (const auto& e : fs::directory_iterator(dir)) entries += e.path().filename() == "out.png" ? 1 : 100;
    EXPECT_EQ(entries, 1u) << "temporary file left behind";

    const std::string missing = (dir / "no/such/dir/x.png").string();
    try {
        candela::write_png_headless(missing, img, ds);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}

TEST(Display, HeadlessContextIsCoreProfile33OrLater) {
    candela::HeadlessGlContext context;
    GLint major = 0, minor = 0, profile = 0;
    context.gl().GetIntegerv(GL_MAJOR_VERSION, &major);
    context.gl().GetIntegerv(GL_MINOR_VERSION, &minor);
    context.gl().GetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    EXPECT_TRUE(major > 3 || (major == 3 && minor >= 3)) << context.description();
    EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT) << context.description();
    // Contexts come and go on one thread (a fresh one per PNG).
    for (int i = 0; i < 3; ++i) candela::display_to_srgb8(constant_image(2, 2, 0.5f), {});
}

// Tiles assemble into exactly the untiled image: random values (NaN, Inf, negative, large
// included), uneven tile sizes with partial tiles at the right and bottom, two exposures.
TEST(Display, TiledEqualsUntiledByteForByte) {
    const int w = 53, h = 37;
    Image img{w, h, std::vector<float>(size_t(w) * h * 3)};
    uint32_t state = 12345;
    for (float& v : img.rgb) {
        state = state * 1664525u + 1013904223u;
        v = float(state >> 8) * 0x1p-24f * 1.5f - 0.1f;
    }
    img.rgb[7] = std::numeric_limits<float>::quiet_NaN();
    img.rgb[100] = std::numeric_limits<float>::infinity();
    img.rgb[2000] = -std::numeric_limits<float>::infinity();
    for (float exposure : {0.f, 1.5f}) {
        DisplaySettings ds;
        ds.exposure = exposure;
        const std::vector<unsigned char> whole = candela::display_to_srgb8(img, ds);
        for (int tile : {1, 7, 16, 36, 52}) {
            const std::vector<unsigned char> tiled = candela::display_to_srgb8(img, ds, tile);
            ASSERT_EQ(tiled.size(), whole.size());
            EXPECT_TRUE(tiled == whole) << "tile " << tile << ", exposure " << exposure;
        }
    }
}

// Wider than GL's texture limit (16384 on llvmpipe): drawn in tiles, every pixel right.
TEST(Display, WiderThanTheGlLimit) {
    const int w = 20000, h = 2;
    Image img{w, h, std::vector<float>(size_t(w) * h * 3)};
    for (int x = 0; x < w; ++x)
        for (int y = 0; y < h; ++y)
            for (int c = 0; c < 3; ++c) img.rgb[(size_t(y) * w + x) * 3 + c] = float(x % 256) / 255.f;
    const std::vector<unsigned char> px = candela::display_to_srgb8(img, {});
    ASSERT_EQ(px.size(), size_t(w) * h * 4);
    for (int x = 0; x < w; x += 97)
        ASSERT_NEAR(int(px[4 * size_t(x)]), expected_byte(double(float(x % 256) / 255.f), 0), 1) << x;
    EXPECT_EQ(px[4 * size_t(w - 1)], px[4 * size_t(2 * w - 1)]);
}

TEST(Display, ForcedGlFailureThrows) {
    setenv("CANDELA_TEST_FAIL_GL", "1", 1);
    EXPECT_THROW(candela::display_to_srgb8(constant_image(4, 4, 0.5f), {}), Error);
    unsetenv("CANDELA_TEST_FAIL_GL");
    EXPECT_NO_THROW(candela::display_to_srgb8(constant_image(4, 4, 0.5f), {}));
}
