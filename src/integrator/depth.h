#pragma once
// Depth. Users give Mitsuba's numbers everywhere (scene files, --max-depth, --rr-depth, the viewer's
// panel, docs): max_depth counts path segments (1: emitters seen directly, 2: direct light, -1:
// unbounded) and rr_depth is the path vertex (1: the first surface hit) from which Russian roulette
// may end the path. RenderSettings::max_depth counts scattering events, one less; the two functions
// below are the only conversion between the two. rr_depth means the same in both.

namespace candela {

inline int max_depth_from_mitsuba(int max_depth) { return max_depth < 0 ? -1 : max_depth - 1; }
inline int max_depth_to_mitsuba(int scattering_events) { return scattering_events < 0 ? -1 : scattering_events + 1; }

// The one rule of scene files and command line: nullptr when valid, else why not. Mitsuba 3 takes
// max_depth -1 or >= 0 and rr_depth > 0; a max_depth of 0 renders black and is refused too.
inline const char* max_depth_error(int max_depth) {
    if (max_depth < -1) return "max_depth must be -1 (unbounded) or >= 1";
    if (max_depth == 0) return "max_depth 0 renders a black image; use -1 (unbounded) or >= 1 (1: emitters only)";
    return nullptr;
}
inline const char* rr_depth_error(int rr_depth) {
    return rr_depth < 1 ? "rr_depth must be >= 1 (Mitsuba's: the path vertex where Russian roulette starts)" : nullptr;
}

}  // namespace candela
