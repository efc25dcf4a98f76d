#include "light/envmap.h"
#include "core/error.h"

namespace candela {

EnvironmentMap::EnvironmentMap(const TexelGrid& t, std::string name) : width_(t.width), height_(t.height), name_(std::move(name)) {
    if (width_ < 2 || height_ < 3)
        throw Error(name_.empty() ? "<envmap>" : name_, 0, "the environment map resolution must be at least 2x3 pixels");
    const int W1 = width_ + 1;
    data_.resize(size_t(W1) * size_t(height_));
    for (int y = 0; y < height_; ++y) {
        for (int x = 0; x < width_; ++x) data_[size_t(y) * size_t(W1) + size_t(x)] = t.texel(x, y);
        data_[size_t(y) * size_t(W1) + size_t(width_)] = t.texel(0, y);  // the periodic seam
    }
    std::vector<float> lum(size_t(W1) * size_t(height_));
    for (size_t i = 0; i < lum.size(); ++i) lum[i] = std::max(luminance(data_[i]), 0.f);
    std::vector<float> w(size_t(width_) * size_t(height_ - 1));
    const float dtheta = kPi / float(height_ - 1);
    for (int y = 0; y + 1 < height_; ++y) {
        // The mean of sin(theta) over the cell's rows: (cos theta0 - cos theta1) / dtheta.
        const float sin_mean = (std::cos(float(y) * dtheta) - std::cos(float(y + 1) * dtheta)) / dtheta;
        for (int x = 0; x < width_; ++x) {
            const size_t a = size_t(y) * size_t(W1) + size_t(x), b = a + size_t(W1);
            w[size_t(y) * size_t(width_) + size_t(x)] = 0.25f * (lum[a] + lum[a + 1] + lum[b] + lum[b + 1]) * sin_mean;
        }
    }
    dist_.build(w, width_, height_ - 1);
}

std::shared_ptr<const EnvironmentMap> EnvironmentMap::load(const std::string& path) {
    std::shared_ptr<const TexelGrid> t = load_texels(path, false);
    return std::make_shared<const EnvironmentMap>(*t, path);
}

vec3 EnvironmentMap::uv_to_direction(vec2 uv, float& sin_theta) {
    const float theta = uv.y * kPi, phi = uv.x * (2.f * kPi);
    sin_theta = std::sin(theta);
    const float cos_theta = std::cos(theta), sin_phi = std::sin(phi), cos_phi = std::cos(phi);
    return vec3(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta);
}

vec2 EnvironmentMap::direction_to_uv(vec3 d) {
    // At a pole (x = z = 0) Dr.Jit's atan2 gives 0 whatever the signs of the zeros, where std::atan2
    // gives +-pi for a negative zero: take Mitsuba's u = 0 there, so that the poles agree too.
    const float phi = (d.x == 0.f && d.z == 0.f) ? 0.f : std::atan2(d.x, -d.z);
    return vec2(phi * (0.5f * kInvPi), std::acos(glm::clamp(d.y, -1.f, 1.f)) * kInvPi);
}

vec3 EnvironmentMap::eval(vec2 uv) const {
    float s = uv.x - half_texel();
    s -= std::floor(s);
    const float x = s * float(width_), y = glm::clamp(uv.y, 0.f, 1.f) * float(height_ - 1);
    if (!(x >= 0.f) || !(y >= 0.f)) return vec3(0.f);  // NaN
    const int px = std::min(int(x), width_ - 1), py = std::min(int(y), height_ - 2);
    const float wx = x - float(px), wy = y - float(py);
    const vec3 v0 = (1.f - wx) * at(px, py) + wx * at(px + 1, py);
    const vec3 v1 = (1.f - wx) * at(px, py + 1) + wx * at(px + 1, py + 1);
    return (1.f - wy) * v0 + wy * v1;
}

bool EnvironmentMap::sample(vec2 u, vec2& uv, float& pdf_uv) const {
    if (!dist_.sample(u, uv, pdf_uv)) return false;
    uv.x += half_texel();
    return true;
}

float EnvironmentMap::pdf(vec2 uv) const {
    float s = uv.x - half_texel();
    s -= std::floor(s);
    return dist_.pdf(vec2(s, uv.y));
}

vec3 EnvironmentMap::integral() const {
    // Per cell, L(theta) is linear in theta between rows y and y + 1 (its mean over phi is the
    // mean of the two columns' blend: each column pair contributes (a + b) / 2 over dphi):
    // int_{t0}^{t1} ((t1 - t) a + (t - t0) b) / dt sin t dt, with
    //   int (t1 - t) sin t dt = dt cos t0 - (sin t1 - sin t0)  and
    //   int (t - t0) sin t dt = (sin t1 - sin t0) - dt cos t1.
    const double dt = kPi / double(height_ - 1), dphi = 2.0 * kPi / double(width_);
    dvec3 sum(0.0);
    for (int y = 0; y + 1 < height_; ++y) {
        const double t0 = y * dt, t1 = (y + 1) * dt;
        const double ia = (dt * std::cos(t0) - (std::sin(t1) - std::sin(t0))) / dt;
        const double ib = ((std::sin(t1) - std::sin(t0)) - dt * std::cos(t1)) / dt;
        dvec3 ra(0.0), rb(0.0);
        for (int x = 0; x < width_; ++x) {
            ra += 0.5 * (dvec3(at(x, y)) + dvec3(at(x + 1, y)));
            rb += 0.5 * (dvec3(at(x, y + 1)) + dvec3(at(x + 1, y + 1)));
        }
        sum += (ia * ra + ib * rb) * dphi;
    }
    return vec3(sum);
}

}  // namespace candela
