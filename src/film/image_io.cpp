#include "film/image_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>

#include <tinyexr.h>

#include "core/error.h"

namespace candela {

namespace {

std::string errno_text(int err) { return std::strerror(err); }

void check_image(const std::string& path, const Image& img) {
    if (img.width <= 0 || img.height <= 0)
        throw Error(path, 0, "cannot write an empty image (" + std::to_string(img.width) + "x" +
                                 std::to_string(img.height) + ")");
    if (img.rgb.size() != size_t(img.width) * size_t(img.height) * 3)
        throw Error(path, 0, "image buffer holds " + std::to_string(img.rgb.size()) + " floats, expected " +
                                 std::to_string(size_t(img.width) * size_t(img.height) * 3));
    if (!img.alpha.empty() && img.alpha.size() != size_t(img.width) * size_t(img.height))
        throw Error(path, 0, "alpha buffer holds " + std::to_string(img.alpha.size()) + " floats, expected " +
                                 std::to_string(size_t(img.width) * size_t(img.height)));
}

// ---- EXR -----------------------------------------------------------------------------------------

// tinyexr hands out C allocations and error strings; these guards free them on every path.
struct ExrErr {
    const char* msg = nullptr;
    ~ExrErr() { if (msg) FreeEXRErrorMessage(msg); }
    // tinyexr's messages end in (and may contain) newlines; Error messages are one line.
    std::string text(int code) const {
        std::string t = msg ? std::string(msg) : "tinyexr error " + std::to_string(code);
        for (char& c : t)
            if (c == '\n' || c == '\r') c = ' ';
        while (!t.empty() && t.back() == ' ') t.pop_back();
        return t;
    }
};
struct ExrHeaderGuard {
    EXRHeader h;
    ExrHeaderGuard() { InitEXRHeader(&h); }
    // Freed even when parsing failed: tinyexr fills the header from what it read before the
    // error, and a zeroed header frees as a no-op.
    ~ExrHeaderGuard() { FreeEXRHeader(&h); }
};
struct ExrImageGuard {
    EXRImage img;
    bool loaded = false;
    ExrImageGuard() { InitEXRImage(&img); }
    ~ExrImageGuard() { if (loaded) FreeEXRImage(&img); }
};

void write_exr(const std::string& path, const Image& img) {
    const size_t n = size_t(img.width) * size_t(img.height);
    std::vector<float> r(n), g(n), b(n), a = img.alpha;
    for (size_t i = 0; i < n; ++i) {
        r[i] = img.rgb[3 * i + 0];
        g[i] = img.rgb[3 * i + 1];
        b[i] = img.rgb[3 * i + 2];
    }
    // EXR readers expect the channel list sorted by name, so the planes go in as (A,) B, G, R.
    const int nc = a.empty() ? 3 : 4;
    float* planes[4] = {b.data(), g.data(), r.data(), nullptr};
    const char* names[4] = {"B", "G", "R", nullptr};
    if (nc == 4) {
        float* p4[4] = {a.data(), b.data(), g.data(), r.data()};
        const char* n4[4] = {"A", "B", "G", "R"};
        std::copy(p4, p4 + 4, planes);
        std::copy(n4, n4 + 4, names);
    }
    EXRChannelInfo channels[4];
    std::memset(channels, 0, sizeof(channels));
    int pixel_types[4], requested[4];
    for (int c = 0; c < nc; ++c) {
        std::strncpy(channels[c].name, names[c], sizeof(channels[c].name) - 1);
        channels[c].x_sampling = channels[c].y_sampling = 1;
        pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;  // type of the data we pass in
        requested[c] = TINYEXR_PIXELTYPE_FLOAT;    // type stored in the file: full float, lossless
    }

    EXRImage image;
    InitEXRImage(&image);
    image.images = reinterpret_cast<unsigned char**>(planes);
    image.width = img.width;
    image.height = img.height;
    image.num_channels = nc;

    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = nc;
    header.channels = channels;
    header.pixel_types = pixel_types;
    header.requested_pixel_types = requested;
    header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;  // lossless for float data

    unsigned char* mem = nullptr;
    ExrErr err;
    size_t size = SaveEXRImageToMemory(&image, &header, &mem, &err.msg);
    std::unique_ptr<unsigned char, void (*)(void*)> owned(mem, std::free);
    if (size == 0 || !mem) throw Error(path, 0, "cannot encode EXR: " + err.text(0));
    write_file_atomic(path, mem, size);
}

// Index of the channel called `name`, or of "<layer>.<name>" when no unprefixed one exists.
int find_channel(const EXRHeader& h, const char* name) {
    for (int c = 0; c < h.num_channels; ++c)
        if (std::strcmp(h.channels[c].name, name) == 0) return c;
    for (int c = 0; c < h.num_channels; ++c) {
        const char* dot = std::strrchr(h.channels[c].name, '.');
        if (dot && std::strcmp(dot + 1, name) == 0) return c;
    }
    return -1;
}

// Every chunk named by the offset table of a scanline file must lie inside the file.
void check_exr_chunks(const std::string& path, const EXRHeader& h, const std::vector<unsigned char>& data) {
    int lines = 1;  // scanlines per chunk, by compression (OpenEXR file layout)
    switch (h.compression_type) {
        case TINYEXR_COMPRESSIONTYPE_NONE: case TINYEXR_COMPRESSIONTYPE_RLE: case TINYEXR_COMPRESSIONTYPE_ZIPS:
            lines = 1; break;
        case TINYEXR_COMPRESSIONTYPE_ZIP: case 5 /* PXR24 */: lines = 16; break;
        case TINYEXR_COMPRESSIONTYPE_PIZ: case 6 /* B44 */: case 7 /* B44A */: lines = 32; break;
        default: return;  // other codecs are left to tinyexr
    }
    const long long height = (long long)h.data_window.max_y - h.data_window.min_y + 1;
    if (height <= 0) throw Error(path, 0, "EXR data window is empty");
    const long long chunks = (height + lines - 1) / lines;
    auto le = [&](size_t at, int n) {  // little-endian unsigned integer of n bytes
        uint64_t v = 0;
        for (int k = 0; k < n; ++k) v |= uint64_t(data[at + size_t(k)]) << (8 * k);
        return v;
    };
    const size_t table = size_t(h.header_len) + 8;  // after magic, version and header
    if (table > data.size() || uint64_t(chunks) > (data.size() - table) / 8)
        throw Error(path, 0, "truncated EXR (offset table cut short)");
    for (long long c = 0; c < chunks; ++c) {
        const uint64_t offset = le(table + size_t(c) * 8, 8);
        // A chunk is: int32 y, int32 byte count, bytes.
        if (offset > data.size() || data.size() - offset < 8)
            throw Error(path, 0, "truncated or corrupt EXR (chunk " + std::to_string(c) + " outside the file)");
        const uint64_t bytes = le(size_t(offset) + 4, 4);
        if (bytes > data.size() - offset - 8)
            throw Error(path, 0, "truncated EXR (chunk " + std::to_string(c) + " cut short)");
    }
}

Image read_exr(const std::string& path, const std::vector<unsigned char>& data) {
    EXRVersion version;
    int rc = ParseEXRVersionFromMemory(&version, data.data(), data.size());
    if (rc != TINYEXR_SUCCESS) throw Error(path, 0, "not an OpenEXR file (bad magic number or version)");
    if (version.multipart || version.non_image)
        throw Error(path, 0, "multi-part and deep EXR files are not supported");

    ExrHeaderGuard header;
    ExrErr err;
    rc = ParseEXRHeaderFromMemory(&header.h, &version, data.data(), data.size(), &err.msg);
    if (rc != TINYEXR_SUCCESS) throw Error(path, 0, "bad EXR header: " + err.text(rc));
    // Half channels are widened to float on load so that one code path reads every channel.
    for (int c = 0; c < header.h.num_channels; ++c)
        if (header.h.pixel_types[c] == TINYEXR_PIXELTYPE_HALF)
            header.h.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;

    // Truncated scanline files, the common bad file, get a precise message here first.
    if (!header.h.tiled) check_exr_chunks(path, header.h, data);
    ExrImageGuard image;
    // On a decoding error tinyexr 1.0.1 frees the image with FreeEXRImage, which frees as many
    // channel buffers as the image's channel count, but a scanline image gets its count only after
    // a successful decode: the buffers leaked (a fuzzer finding, e.g. PIZ data that does not
    // decode). With the count set beforehand its own cleanup frees them; on success it sets the
    // same count. The failed image must not be freed again (its pointers are left dangling).
    image.img.num_channels = header.h.num_channels;
    rc = LoadEXRImageFromMemory(&image.img, &header.h, data.data(), data.size(), &err.msg);
    if (rc != TINYEXR_SUCCESS) throw Error(path, 0, "cannot decode EXR pixels: " + err.text(rc));
    image.loaded = true;

    const EXRImage& ei = image.img;
    if (ei.width <= 0 || ei.height <= 0) throw Error(path, 0, "EXR image is empty");

    // Pick the source channel of R, G and B: named R/G/B first; else luminance Y or a single
    // channel as grey; else the first channels in file order. A missing channel reads as 0.
    int src[3] = {find_channel(header.h, "R"), find_channel(header.h, "G"), find_channel(header.h, "B")};
    if (src[0] < 0 && src[1] < 0 && src[2] < 0) {
        int y = find_channel(header.h, "Y");
        if (y < 0 && header.h.num_channels == 1) y = 0;
        if (y >= 0) {
            src[0] = src[1] = src[2] = y;
        } else {
            for (int c = 0; c < 3; ++c) src[c] = c < header.h.num_channels ? c : -1;
        }
    }

    Image out;
    out.width = ei.width;
    out.height = ei.height;
    out.rgb.assign(size_t(out.width) * size_t(out.height) * 3, 0.f);

    // Reads texel `i` of a channel plane (float after widening, or uint).
    auto value = [&](const unsigned char* plane, int ch, size_t i) -> float {
        if (header.h.requested_pixel_types[ch] == TINYEXR_PIXELTYPE_UINT) {
            uint32_t u;
            std::memcpy(&u, plane + 4 * i, 4);
            return float(u);
        }
        float f;
        std::memcpy(&f, plane + 4 * i, 4);
        return f;
    };

    if (!header.h.tiled) {
        if (!ei.images) throw Error(path, 0, "EXR has no scanline data");
        const size_t n = size_t(out.width) * size_t(out.height);
        for (int c = 0; c < 3; ++c) {
            if (src[c] < 0) continue;
            const unsigned char* plane = ei.images[src[c]];
            for (size_t i = 0; i < n; ++i) out.rgb[3 * i + c] = value(plane, src[c], i);
        }
    } else {
        // Level 0 tiles: offsets count tiles; each tile plane is tile_size_x wide.
        const int tw = header.h.tile_size_x, th = header.h.tile_size_y;
        for (int t = 0; t < ei.num_tiles; ++t) {
            const EXRTile& tile = ei.tiles[t];
            for (int c = 0; c < 3; ++c) {
                if (src[c] < 0) continue;
                const unsigned char* plane = tile.images[src[c]];
                for (int j = 0; j < tile.height; ++j)
                    for (int i = 0; i < tile.width; ++i) {
                        int x = tile.offset_x * tw + i, y = tile.offset_y * th + j;
                        if (x >= out.width || y >= out.height) continue;
                        out.rgb[3 * (size_t(y) * size_t(out.width) + size_t(x)) + c] =
                            value(plane, src[c], size_t(j) * size_t(tw) + size_t(i));
                    }
            }
        }
    }
    return out;
}

// ---- PFM -----------------------------------------------------------------------------------------

void put_f32_le(std::string& s, float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    for (int k = 0; k < 4; ++k) s.push_back(char((u >> (8 * k)) & 0xff));
}

float get_f32(const unsigned char* p, bool little_endian) {
    uint32_t u = 0;
    for (int k = 0; k < 4; ++k) u |= uint32_t(p[k]) << (8 * (little_endian ? k : 3 - k));
    float f;
    std::memcpy(&f, &u, 4);
    return f;
}

void write_pfm(const std::string& path, const Image& img) {
    std::string out = "PF\n" + std::to_string(img.width) + " " + std::to_string(img.height) + "\n-1.0\n";
    out.reserve(out.size() + img.rgb.size() * 4);
    // PFM stores scanlines bottom to top; our images are top row first.
    for (int y = img.height - 1; y >= 0; --y) {
        const float* row = img.rgb.data() + size_t(y) * size_t(img.width) * 3;
        for (size_t i = 0; i < size_t(img.width) * 3; ++i) put_f32_le(out, row[i]);
    }
    write_file_atomic(path, out.data(), out.size());
}

Image read_pfm(const std::string& path, const std::vector<unsigned char>& data) {
    size_t pos = 0;
    auto skip_space = [&] {
        while (pos < data.size() && std::isspace(data[pos])) ++pos;
    };
    auto token = [&]() -> std::string {
        skip_space();
        std::string t;
        while (pos < data.size() && !std::isspace(data[pos]) && t.size() < 64) t.push_back(char(data[pos++]));
        return t;
    };
    const std::string magic = token();
    int channels = magic == "PF" ? 3 : magic == "Pf" ? 1 : 0;
    if (channels == 0) throw Error(path, 0, "not a PFM file (expected \"PF\" or \"Pf\")");

    long long w = 0, h = 0;
    double scale = 0;
    try {
        size_t used = 0;
        std::string tw = token(), th = token(), ts = token();
        w = std::stoll(tw, &used);
        if (used != tw.size()) throw std::invalid_argument(tw);
        h = std::stoll(th, &used);
        if (used != th.size()) throw std::invalid_argument(th);
        scale = std::stod(ts, &used);
        if (used != ts.size()) throw std::invalid_argument(ts);
    } catch (const std::logic_error&) {
        throw Error(path, 0, "bad PFM header (width, height and scale expected)");
    }
    if (w <= 0 || h <= 0 || w > (1 << 20) || h > (1 << 20))
        throw Error(path, 0, "bad PFM size " + std::to_string(w) + "x" + std::to_string(h));
    if (scale == 0 || !std::isfinite(scale)) throw Error(path, 0, "bad PFM scale (must be non-zero)");
    // Exactly one whitespace character separates the header from the raster.
    if (pos >= data.size() || !std::isspace(data[pos])) throw Error(path, 0, "truncated PFM header");
    ++pos;

    const bool little = scale < 0;
    const size_t n = size_t(w) * size_t(h);
    const size_t need = n * size_t(channels) * 4;
    if (data.size() - pos < need)
        throw Error(path, 0, "truncated PFM: " + std::to_string(data.size() - pos) + " bytes of raster, expected " +
                                 std::to_string(need));

    Image img;
    img.width = int(w);
    img.height = int(h);
    img.rgb.resize(n * 3);
    const unsigned char* raster = data.data() + pos;
    for (size_t fy = 0; fy < size_t(h); ++fy) {
        size_t y = size_t(h) - 1 - fy;  // file rows run bottom to top
        for (size_t x = 0; x < size_t(w); ++x) {
            const unsigned char* p = raster + (fy * size_t(w) + x) * size_t(channels) * 4;
            float* q = img.rgb.data() + (y * size_t(w) + x) * 3;
            for (int c = 0; c < 3; ++c) q[c] = get_f32(p + 4 * (channels == 3 ? c : 0), little);
        }
    }
    return img;
}

}  // namespace

std::string file_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    if (ext == ".") return "";
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

void write_linear_image(const std::string& path, const Image& img) {
    const std::string ext = file_extension(path);
    if (ext != ".exr" && ext != ".pfm")
        throw Error(path, 0, "unsupported linear image format \"" + ext + "\" (use .exr or .pfm)");
    check_image(path, img);
    if (ext == ".exr") write_exr(path, img);
    else write_pfm(path, img);
}

std::vector<unsigned char> read_whole_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, 0, "cannot open: " + errno_text(errno));
    std::vector<unsigned char> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw Error(path, 0, "read error");
    return data;
}

Image read_linear_image(const std::string& path) {
    const std::string ext = file_extension(path);
    if (ext != ".exr" && ext != ".pfm")
        throw Error(path, 0, "unsupported linear image format \"" + ext + "\" (use .exr or .pfm)");
    const std::vector<unsigned char> data = read_whole_file(path);
    return ext == ".exr" ? read_exr(path, data) : read_pfm(path, data);
}

void write_file_atomic(const std::string& path, const void* data, size_t size) {
    // The temporary lives beside the target so that rename() stays within one file system and is
    // atomic. Its name is unique per process and call; O_EXCL refuses to reuse a stale one.
    static std::atomic<unsigned> counter{0};
    std::string tmp;
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        tmp = path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter.fetch_add(1));
        fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);  // umask applies
        if (fd < 0 && errno != EEXIST) break;
    }
    if (fd < 0) throw Error(path, 0, "cannot create temporary file: " + errno_text(errno));

    auto fail = [&](const std::string& what) {
        int err = errno;
        if (fd >= 0) ::close(fd);
        ::unlink(tmp.c_str());
        throw Error(path, 0, what + ": " + errno_text(err));
    };
    const char* p = static_cast<const char*>(data);
    size_t left = size;
    while (left > 0) {
        ssize_t n = ::write(fd, p, left);
        if (n < 0) {
            if (errno == EINTR) continue;
            fail("write failed");
        }
        p += n;
        left -= size_t(n);
    }
    // fsync before rename: otherwise a crash can leave the new name pointing at an empty file.
    if (::fsync(fd) != 0) fail("fsync failed");
    int rc = ::close(fd);
    fd = -1;
    if (rc != 0) fail("close failed");
    if (::rename(tmp.c_str(), path.c_str()) != 0) fail("cannot rename temporary file into place");

    // Persist the rename itself. The file is already complete under its name, so a failure to
    // sync the directory is not worth reporting.
    std::string dir = std::filesystem::path(path).parent_path().string();
    int dfd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
}

}  // namespace candela
