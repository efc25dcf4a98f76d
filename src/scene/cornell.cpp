#include "scene/cornell.h"
#include <array>

namespace candela {

namespace {

using Quad = std::array<vec3, 4>;

// Reorders a quad's corners when needed so that its normal (p1-p0) x (p2-p0) points towards `inside`
// (or away from it when outward is true).
Quad orient(Quad q, vec3 ref, bool outward) {
    vec3 n = glm::cross(q[1] - q[0], q[2] - q[0]);
    vec3 c = 0.25f * (q[0] + q[1] + q[2] + q[3]);
    float s = glm::dot(n, ref - c);
    if ((s < 0.f) != outward) std::swap(q[1], q[3]);
    return q;
}

}  // namespace

std::vector<CornellPart> cornell_box_parts() {
    const vec3 room_center(278.f, 274.4f, 279.6f);
    std::vector<CornellPart> parts;
    auto room = [&](const char* name, int mat, Quad q) {
        parts.push_back({name, mat, {orient(q, room_center, false)}});
    };
    room("floor", 0, {vec3(552.8f, 0.f, 0.f), vec3(0.f, 0.f, 0.f), vec3(0.f, 0.f, 559.2f), vec3(549.6f, 0.f, 559.2f)});
    room("ceiling", 0, {vec3(556.f, 548.8f, 0.f), vec3(556.f, 548.8f, 559.2f), vec3(0.f, 548.8f, 559.2f), vec3(0.f, 548.8f, 0.f)});
    room("back", 0, {vec3(549.6f, 0.f, 559.2f), vec3(0.f, 0.f, 559.2f), vec3(0.f, 548.8f, 559.2f), vec3(556.f, 548.8f, 559.2f)});
    room("green", 2, {vec3(0.f, 0.f, 559.2f), vec3(0.f, 0.f, 0.f), vec3(0.f, 548.8f, 0.f), vec3(0.f, 548.8f, 559.2f)});
    room("red", 1, {vec3(552.8f, 0.f, 0.f), vec3(549.6f, 0.f, 559.2f), vec3(556.f, 548.8f, 559.2f), vec3(556.f, 548.8f, 0.f)});
    // The light faces down (towards the room), 0.1 mm below the ceiling so the two never coincide.
    room("light", 3, {vec3(343.f, 548.7f, 227.f), vec3(343.f, 548.7f, 332.f), vec3(213.f, 548.7f, 332.f), vec3(213.f, 548.7f, 227.f)});

    auto block = [&](const char* name, std::vector<Quad> faces) {
        vec3 c(0.f);
        for (auto& f : faces) c += 0.25f * (f[0] + f[1] + f[2] + f[3]);
        c /= float(faces.size());
        CornellPart p{name, 0, {}};
        for (auto& f : faces) p.quads.push_back(orient(f, c, true));
        parts.push_back(p);
    };
    block("short_block", {
        {vec3(130.f, 165.f, 65.f), vec3(82.f, 165.f, 225.f), vec3(240.f, 165.f, 272.f), vec3(290.f, 165.f, 114.f)},
        {vec3(290.f, 0.f, 114.f), vec3(290.f, 165.f, 114.f), vec3(240.f, 165.f, 272.f), vec3(240.f, 0.f, 272.f)},
        {vec3(130.f, 0.f, 65.f), vec3(130.f, 165.f, 65.f), vec3(290.f, 165.f, 114.f), vec3(290.f, 0.f, 114.f)},
        {vec3(82.f, 0.f, 225.f), vec3(82.f, 165.f, 225.f), vec3(130.f, 165.f, 65.f), vec3(130.f, 0.f, 65.f)},
        {vec3(240.f, 0.f, 272.f), vec3(240.f, 165.f, 272.f), vec3(82.f, 165.f, 225.f), vec3(82.f, 0.f, 225.f)},
    });
    block("tall_block", {
        {vec3(423.f, 330.f, 247.f), vec3(265.f, 330.f, 296.f), vec3(314.f, 330.f, 456.f), vec3(472.f, 330.f, 406.f)},
        {vec3(423.f, 0.f, 247.f), vec3(423.f, 330.f, 247.f), vec3(472.f, 330.f, 406.f), vec3(472.f, 0.f, 406.f)},
        {vec3(472.f, 0.f, 406.f), vec3(472.f, 330.f, 406.f), vec3(314.f, 330.f, 456.f), vec3(314.f, 0.f, 456.f)},
        {vec3(314.f, 0.f, 456.f), vec3(314.f, 330.f, 456.f), vec3(265.f, 330.f, 296.f), vec3(265.f, 0.f, 296.f)},
        {vec3(265.f, 0.f, 296.f), vec3(265.f, 330.f, 296.f), vec3(423.f, 330.f, 247.f), vec3(423.f, 0.f, 247.f)},
    });
    return parts;
}

SceneDescription make_cornell_box() {
    SceneDescription s;
    s.source = "<built-in Cornell box>";
    s.materials = {
        {"white", DiffuseBsdf{kCornellWhite}, false},
        {"red", DiffuseBsdf{kCornellRed}, false},
        {"green", DiffuseBsdf{kCornellGreen}, false},
    };
    s.emitters.push_back({kCornellLight});
    for (const CornellPart& part : cornell_box_parts()) {
        std::vector<vec3> pos;
        std::vector<uvec3> tris;
        for (const auto& q : part.quads) {
            uint32_t b = uint32_t(pos.size());
            pos.insert(pos.end(), q.begin(), q.end());
            tris.push_back(uvec3(b, b + 1, b + 2));
            tris.push_back(uvec3(b, b + 2, b + 3));
        }
        bool light = part.material == 3;
        s.add_shape(part.name, pos, {}, tris, light ? 0u : uint32_t(part.material), light ? 0 : -1);
    }
    s.camera.to_world = look_at(vec3(278.f, 273.f, -800.f), vec3(278.f, 273.f, -799.f), vec3(0.f, 1.f, 0.f));
    s.camera.fov_deg = 39.3077f;
    s.camera.fov_axis = FovAxis::X;
    s.camera.near_clip = 10.f;
    s.camera.far_clip = 2800.f;
    s.settings.width = 512;
    s.settings.height = 512;
    s.settings.spp = 64;
    return s;
}

}  // namespace candela
