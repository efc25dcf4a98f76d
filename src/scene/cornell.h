#pragma once
#include <array>
#include "scene/scene.h"

namespace candela {

// The Cornell box from the published measurements (Cornell Program of Computer Graphics), in
// millimetres: the camera at (278, 273, -800) looks along +z with a 39.3077 degree horizontal fov.
// The red wall is at x = 556 (image left), the green wall at x = 0. Every face is wound so that its
// normal points into the room or out of the blocks (the BSDFs are one-sided, as in Mitsuba), and
// the 130 x 105 mm light sits 0.1 mm under the ceiling, facing down.
// scenes/cornell-box/ holds the same geometry as Mitsuba XML + OBJ (tests check they agree).
SceneDescription make_cornell_box();

// The raw geometry, for the OBJ exporter and the tests: name, material, quads (4 corners each).
struct CornellPart {
    const char* name;
    int material;  // 0 white, 1 red, 2 green, 3 light (white albedo, emitting)
    std::vector<std::array<vec3, 4>> quads;
};
std::vector<CornellPart> cornell_box_parts();

// Albedos and light radiance of the published box (as RGB).
constexpr vec3 kCornellWhite{0.725f, 0.71f, 0.68f};
constexpr vec3 kCornellRed{0.63f, 0.065f, 0.05f};
constexpr vec3 kCornellGreen{0.14f, 0.45f, 0.091f};
constexpr vec3 kCornellLight{17.f, 12.f, 4.f};

}  // namespace candela
