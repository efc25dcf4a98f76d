// Linear image files (EXR, PFM) and the atomic file write they share.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <tinyexr.h>

#include "core/error.h"
#include "film/image_io.h"

namespace fs = std::filesystem;
using candela::Error;
using candela::Image;

namespace {

// A fresh directory per test, removed afterwards.
class ImageIoTest : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("candela_image_io_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    std::vector<std::string> listing() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }
    fs::path dir_;
};

// Values chosen to catch channel swaps, row flips and any lossy conversion (not representable in
// half, denormal, huge, negative).
Image test_image(int w, int h) {
    Image img;
    img.width = w;
    img.height = h;
    img.rgb.resize(size_t(w) * size_t(h) * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = &img.rgb[3 * (size_t(y) * size_t(w) + size_t(x))];
            p[0] = 0.1f + float(x) * 1.0001f;
            p[1] = -0.3f + float(y) * 3.14159f;
            p[2] = float(x * 1000 + y) * 1e-7f;
        }
    img.rgb[0] = std::numeric_limits<float>::denorm_min();
    img.rgb[1] = 3.0e38f;
    img.rgb[2] = std::numeric_limits<float>::infinity();
    return img;
}

void expect_bit_equal(const Image& a, const Image& b) {
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    for (size_t i = 0; i < a.rgb.size(); ++i) {
        uint32_t ua, ub;
        std::memcpy(&ua, &a.rgb[i], 4);
        std::memcpy(&ub, &b.rgb[i], 4);
        ASSERT_EQ(ua, ub) << "float " << i << ": " << a.rgb[i] << " vs " << b.rgb[i];
    }
}

std::string read_bytes(const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_bytes(const std::string& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary);
    out << bytes;
}

// Expects `f` to throw candela::Error whose message names `file`.
template <typename F>
void expect_error_naming(const std::string& file, F f) {
    try {
        f();
        FAIL() << "no Error thrown for " << file;
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "multi-line: " << e.what();
    }
}

// Writes an EXR with the given channels (each a plane of w*h floats) through tinyexr directly,
// the way other tools would, stored as `stored_type` (half or float).
void write_exr_channels(const std::string& p, int w, int h, const std::vector<std::string>& names,
                        std::vector<std::vector<float>> planes, int stored_type) {
    const int n = int(names.size());
    std::vector<EXRChannelInfo> ch(static_cast<size_t>(n));
    std::vector<int> in_types(size_t(n), TINYEXR_PIXELTYPE_FLOAT), out_types(size_t(n), stored_type);
    std::vector<unsigned char*> ptrs;
    for (int c = 0; c < n; ++c) {
        std::memset(&ch[size_t(c)], 0, sizeof(EXRChannelInfo));
        std::strncpy(ch[size_t(c)].name, names[size_t(c)].c_str(), 255);
        ptrs.push_back(reinterpret_cast<unsigned char*>(planes[size_t(c)].data()));
    }
    EXRImage image;
    InitEXRImage(&image);
    image.images = ptrs.data();
    image.width = w;
    image.height = h;
    image.num_channels = n;
    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = n;
    header.channels = ch.data();
    header.pixel_types = in_types.data();
    header.requested_pixel_types = out_types.data();
    header.compression_type = TINYEXR_COMPRESSIONTYPE_NONE;
    const char* err = nullptr;
    int rc = SaveEXRImageToFile(&image, &header, p.c_str(), &err);
    if (err) FreeEXRErrorMessage(err);
    ASSERT_EQ(rc, TINYEXR_SUCCESS);
}

}  // namespace

TEST(ImageIo, FileExtension) {
    EXPECT_EQ(candela::file_extension("out.png"), ".png");
    EXPECT_EQ(candela::file_extension("/a/b/IMAGE.EXR"), ".exr");
    EXPECT_EQ(candela::file_extension("dir.d/noext"), "");
    EXPECT_EQ(candela::file_extension("archive.tar.Pfm"), ".pfm");
    EXPECT_EQ(candela::file_extension(".hidden"), "");
    EXPECT_EQ(candela::file_extension("trailingdot."), "");
    EXPECT_EQ(candela::file_extension(""), "");
}

TEST_F(ImageIoTest, ExrRoundTripIsBitExact) {
    const Image img = test_image(37, 19);
    candela::write_linear_image(path("a.exr"), img);
    expect_bit_equal(img, candela::read_linear_image(path("a.exr")));
}

TEST_F(ImageIoTest, ExrStoresRgbChannelsSortedAsFloat) {
    candela::write_linear_image(path("a.exr"), test_image(4, 3));
    EXRVersion version;
    ASSERT_EQ(ParseEXRVersionFromFile(&version, path("a.exr").c_str()), TINYEXR_SUCCESS);
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    ASSERT_EQ(ParseEXRHeaderFromFile(&header, &version, path("a.exr").c_str(), &err), TINYEXR_SUCCESS);
    ASSERT_EQ(header.num_channels, 3);
    EXPECT_STREQ(header.channels[0].name, "B");
    EXPECT_STREQ(header.channels[1].name, "G");
    EXPECT_STREQ(header.channels[2].name, "R");
    for (int c = 0; c < 3; ++c) EXPECT_EQ(header.pixel_types[c], TINYEXR_PIXELTYPE_FLOAT);
    FreeEXRHeader(&header);
}

TEST_F(ImageIoTest, ExrNaNSurvives) {
    Image img = test_image(3, 2);
    img.rgb[4] = std::numeric_limits<float>::quiet_NaN();
    candela::write_linear_image(path("nan.exr"), img);
    EXPECT_TRUE(std::isnan(candela::read_linear_image(path("nan.exr")).rgb[4]));
}

TEST_F(ImageIoTest, ExrWithAlphaAndHalfReadsAsRgb) {
    const int w = 5, h = 3;
    // Values exactly representable in half, so the widened result is exact.
    std::vector<float> a(w * h, 1.f), b(w * h), g(w * h), r(w * h);
    for (int i = 0; i < w * h; ++i) {
        r[size_t(i)] = 0.25f * float(i);
        g[size_t(i)] = 0.5f + float(i);
        b[size_t(i)] = -2.f * float(i);
    }
    write_exr_channels(path("rgba.exr"), w, h, {"A", "B", "G", "R"}, {a, b, g, r}, TINYEXR_PIXELTYPE_HALF);
    const Image img = candela::read_linear_image(path("rgba.exr"));
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    ASSERT_EQ(img.rgb.size(), size_t(w * h * 3));
    for (int i = 0; i < w * h; ++i) {
        EXPECT_EQ(img.rgb[3 * size_t(i) + 0], r[size_t(i)]);
        EXPECT_EQ(img.rgb[3 * size_t(i) + 1], g[size_t(i)]);
        EXPECT_EQ(img.rgb[3 * size_t(i) + 2], b[size_t(i)]);
    }
}

TEST_F(ImageIoTest, ExrLuminanceOnlyReadsAsGrey) {
    std::vector<float> y = {0.f, 0.5f, 1.f, 7.f};
    write_exr_channels(path("y.exr"), 2, 2, {"Y"}, {y}, TINYEXR_PIXELTYPE_FLOAT);
    const Image img = candela::read_linear_image(path("y.exr"));
    ASSERT_EQ(img.rgb.size(), 12u);
    for (size_t i = 0; i < 4; ++i)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(img.rgb[3 * i + size_t(c)], y[i]);
}

TEST_F(ImageIoTest, PfmRoundTripIsBitExact) {
    const Image img = test_image(37, 19);
    candela::write_linear_image(path("a.pfm"), img);
    expect_bit_equal(img, candela::read_linear_image(path("a.pfm")));
}

TEST_F(ImageIoTest, PfmLayoutIsLittleEndianBottomUp) {
    const Image img = test_image(3, 2);
    candela::write_linear_image(path("a.pfm"), img);
    const std::string bytes = read_bytes(path("a.pfm"));
    const std::string header = "PF\n3 2\n-1.0\n";
    ASSERT_EQ(bytes.substr(0, header.size()), header);
    ASSERT_EQ(bytes.size(), header.size() + 3 * 2 * 3 * 4);
    // The first stored pixel is the bottom-left one, i.e. row 1 of our top-down image.
    auto f32 = [&](size_t offset) {
        uint32_t u = 0;
        for (int k = 0; k < 4; ++k) u |= uint32_t(uint8_t(bytes[header.size() + offset + size_t(k)])) << (8 * k);
        float f;
        std::memcpy(&f, &u, 4);
        return f;
    };
    EXPECT_EQ(f32(0), img.rgb[3 * 3 + 0]);
    EXPECT_EQ(f32(4), img.rgb[3 * 3 + 1]);
    EXPECT_EQ(f32(3 * 3 * 4), img.rgb[0]);  // second stored row = top row
}

TEST_F(ImageIoTest, PfmReadsBigEndianAndGreyscale) {
    // Hand-made files: "PF" with a positive scale (big-endian), and a one-channel "Pf".
    auto be = [](float f) {
        uint32_t u;
        std::memcpy(&u, &f, 4);
        std::string s;
        for (int k = 3; k >= 0; --k) s.push_back(char((u >> (8 * k)) & 0xff));
        return s;
    };
    std::string rgb = "PF\n1 2\n1.0\n";
    for (float f : {1.f, 2.f, 3.f, 4.f, 5.f, 6.f}) rgb += be(f);  // bottom row first
    write_bytes(path("be.pfm"), rgb);
    Image img = candela::read_linear_image(path("be.pfm"));
    ASSERT_EQ(img.width, 1);
    ASSERT_EQ(img.height, 2);
    EXPECT_EQ(img.rgb, (std::vector<float>{4.f, 5.f, 6.f, 1.f, 2.f, 3.f}));

    std::string grey = "Pf\n2 1\n-1.0\n";
    for (float f : {0.5f, 8.f}) {
        uint32_t u;
        std::memcpy(&u, &f, 4);
        for (int k = 0; k < 4; ++k) grey.push_back(char((u >> (8 * k)) & 0xff));
    }
    write_bytes(path("grey.pfm"), grey);
    img = candela::read_linear_image(path("grey.pfm"));
    EXPECT_EQ(img.rgb, (std::vector<float>{0.5f, 0.5f, 0.5f, 8.f, 8.f, 8.f}));
}

TEST_F(ImageIoTest, ReadErrorsNameTheFile) {
    expect_error_naming(path("missing.exr"), [&] { candela::read_linear_image(path("missing.exr")); });
    expect_error_naming(path("missing.pfm"), [&] { candela::read_linear_image(path("missing.pfm")); });

    write_bytes(path("garbage.exr"), "this is not an image at all, just some text\n");
    expect_error_naming(path("garbage.exr"), [&] { candela::read_linear_image(path("garbage.exr")); });
    write_bytes(path("garbage.pfm"), "P6\n1 1\n255\nabc");
    expect_error_naming(path("garbage.pfm"), [&] { candela::read_linear_image(path("garbage.pfm")); });
    write_bytes(path("badsize.pfm"), "PF\n-3 x\n-1.0\n");
    expect_error_naming(path("badsize.pfm"), [&] { candela::read_linear_image(path("badsize.pfm")); });
    write_bytes(path("empty.exr"), "");
    expect_error_naming(path("empty.exr"), [&] { candela::read_linear_image(path("empty.exr")); });

    // Truncated copies of valid files, cut in the raster and in the header.
    for (const char* ext : {".exr", ".pfm"}) {
        const std::string full = path(std::string("full") + ext);
        candela::write_linear_image(full, test_image(16, 8));
        const std::string bytes = read_bytes(full);
        for (size_t keep : {bytes.size() - 7, bytes.size() / 2, size_t(9)}) {
            const std::string cut = path("cut" + std::to_string(keep) + ext);
            write_bytes(cut, bytes.substr(0, keep));
            expect_error_naming(cut, [&] { candela::read_linear_image(cut); });
        }
    }
    expect_error_naming(path("a.tiff"), [&] { candela::read_linear_image(path("a.tiff")); });
}

TEST_F(ImageIoTest, WriteErrorsNameTheFile) {
    expect_error_naming(path("a.png"), [&] { candela::write_linear_image(path("a.png"), test_image(2, 2)); });
    Image bad = test_image(2, 2);
    bad.rgb.pop_back();
    expect_error_naming(path("bad.exr"), [&] { candela::write_linear_image(path("bad.exr"), bad); });
    expect_error_naming(path("empty.pfm"), [&] { candela::write_linear_image(path("empty.pfm"), Image{}); });
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageIoTest, AtomicWriteReplacesAndLeavesNoTemporary) {
    const std::string target = path("out.bin");
    candela::write_file_atomic(target, "old contents", 12);
    candela::write_file_atomic(target, "new", 3);
    EXPECT_EQ(read_bytes(target), "new");
    candela::write_file_atomic(target, "", 0);
    EXPECT_EQ(read_bytes(target), "");
    candela::write_linear_image(path("img.exr"), test_image(3, 3));
    candela::write_linear_image(path("img.pfm"), test_image(3, 3));
    EXPECT_EQ(listing(), (std::vector<std::string>{"img.exr", "img.pfm", "out.bin"}));
}

TEST_F(ImageIoTest, AtomicWriteIntoMissingDirectoryThrowsAndLeavesNothing) {
    const std::string target = path("no/such/dir/out.exr");
    expect_error_naming(target, [&] { candela::write_linear_image(target, test_image(2, 2)); });
    expect_error_naming(target, [&] { candela::write_file_atomic(target, "x", 1); });
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageIoTest, FailedRenameKeepsOldTargetAndRemovesTemporary) {
    // The target is a non-empty directory: the temporary is written, the rename fails (even as
    // root), and what was there must survive untouched with no temporary left beside it.
    const std::string target = path("taken.pfm");
    fs::create_directories(target);
    write_bytes(target + "/keep.txt", "precious");
    expect_error_naming(target, [&] { candela::write_linear_image(target, test_image(4, 4)); });
    EXPECT_EQ(read_bytes(target + "/keep.txt"), "precious");
    EXPECT_EQ(listing(), (std::vector<std::string>{"taken.pfm"}));
}
