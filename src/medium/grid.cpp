#include "medium/grid.h"
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include "core/error.h"

namespace candela {

namespace {

template <class T>
T read_le(const std::string& b, size_t at) {
    T v;
    std::memcpy(&v, b.data() + at, sizeof v);  // the hosts candela builds on are little-endian
    return v;
}

}  // namespace

VolumeGrid parse_vol(const std::string& name, const std::string& b) {
    constexpr size_t kHeader = 3 + 1 + 4 * 5 + 4 * 6;
    if (b.size() < kHeader) throw Error(name, 0, "not a .vol grid: " + std::to_string(b.size()) + " bytes, shorter than its 48-byte header");
    if (b.compare(0, 3, "VOL") != 0) throw Error(name, 0, "not a .vol grid (it does not start with 'VOL')");
    if (uint8_t(b[3]) != 3) throw Error(name, 0, ".vol version " + std::to_string(int(uint8_t(b[3]))) + " (Mitsuba reads version 3)");
    const int32_t encoding = read_le<int32_t>(b, 4);
    if (encoding != 1) throw Error(name, 0, ".vol encoding " + std::to_string(encoding) + " (Mitsuba 3 reads 1: float32)");
    VolumeGrid g;
    g.res = glm::ivec3(read_le<int32_t>(b, 8), read_le<int32_t>(b, 12), read_le<int32_t>(b, 16));
    g.channels = read_le<int32_t>(b, 20);
    if (g.res.x < 1 || g.res.y < 1 || g.res.z < 1)
        throw Error(name, 0, ".vol resolution " + std::to_string(g.res.x) + " x " + std::to_string(g.res.y) + " x " +
                                 std::to_string(g.res.z) + " (each must be >= 1)");
    if (g.channels != 1 && g.channels != 3)
        throw Error(name, 0, ".vol with " + std::to_string(g.channels) + " channels (candela reads 1 or 3)");
    // Multiplied step by step so that the product cannot wrap (found by fuzz_vol: 2^25 x 2^9 x 2^30).
    uint64_t values = uint64_t(g.channels);
    for (int a = 0; a < 3 && values <= kMaxVolValues; ++a) values *= uint64_t(g.res[a]);
    if (values > kMaxVolValues)
        throw Error(name, 0, ".vol grid of " + std::to_string(g.res.x) + " x " + std::to_string(g.res.y) + " x " +
                                 std::to_string(g.res.z) + " x " + std::to_string(g.channels) +
                                 " values, more than candela's limit of " + std::to_string(kMaxVolValues));
    vec3 lo(read_le<float>(b, 24), read_le<float>(b, 28), read_le<float>(b, 32));
    vec3 hi(read_le<float>(b, 36), read_le<float>(b, 40), read_le<float>(b, 44));
    g.bbox = AABB(lo, hi);
    const uint64_t have = b.size() - kHeader;
    if (have != values * 4)
        throw Error(name, 0, std::string(".vol grid ") + (have < values * 4 ? "truncated" : "with trailing bytes") + ": " +
                                 std::to_string(have) + " bytes of values, its header says " + std::to_string(values * 4));
    g.data.resize(size_t(values));
    std::memcpy(g.data.data(), b.data() + kHeader, size_t(values) * 4);
    for (size_t i = 0; i < g.data.size(); ++i) {
        if (!std::isfinite(g.data[i])) throw Error(name, 0, ".vol value " + std::to_string(i) + " is NaN or infinite");
        g.max_value = std::max(g.max_value, g.data[i]);
    }
    return g;
}

VolumeGrid read_vol(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, 0, "cannot open the .vol grid");
    std::ostringstream s;
    s << in.rdbuf();
    return parse_vol(path, s.str());
}

vec3 VolumeGrid::eval(vec3 p) const {
    auto at = [&](int x, int y, int z) {
        const size_t i = (size_t(z) * size_t(res.y) + size_t(y)) * size_t(res.x) + size_t(x);
        const float* v = &data[i * size_t(channels)];
        return channels == 1 ? vec3(v[0]) : vec3(v[0], v[1], v[2]);
    };
    if (nearest) {
        const glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor(p * vec3(res))), glm::ivec3(0), res - 1);
        return at(c.x, c.y, c.z);
    }
    const vec3 q = glm::clamp(p * vec3(res) - 0.5f, vec3(0.f), vec3(res - 1));
    const glm::ivec3 c0 = glm::min(glm::ivec3(glm::floor(q)), res - 1);
    const glm::ivec3 c1 = glm::min(c0 + 1, res - 1);
    const vec3 f = q - vec3(c0);
    const vec3 x00 = glm::mix(at(c0.x, c0.y, c0.z), at(c1.x, c0.y, c0.z), f.x);
    const vec3 x10 = glm::mix(at(c0.x, c1.y, c0.z), at(c1.x, c1.y, c0.z), f.x);
    const vec3 x01 = glm::mix(at(c0.x, c0.y, c1.z), at(c1.x, c0.y, c1.z), f.x);
    const vec3 x11 = glm::mix(at(c0.x, c1.y, c1.z), at(c1.x, c1.y, c1.z), f.x);
    return glm::mix(glm::mix(x00, x10, f.y), glm::mix(x01, x11, f.y), f.z);
}

}  // namespace candela
