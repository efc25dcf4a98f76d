#pragma once
// BDPT's multiple importance sampling weight (Veach 1997, ch. 10; the recurrence as pbrt-v3's
// MISWeight, with the power heuristic). Pure arithmetic on the subpaths' densities, so that the
// unit test can check it on made-up paths (tests/test_bdpt.cpp).
//
// A path of n = s + t vertices made by strategy (s, t): light vertices y_0..y_{s-1}, camera
// vertices z_0..z_{t-1} (z_0 on the camera, y_0 on a light). Every vertex holds
//   pdf_fwd: the area density with which its own subpath sampled it (from its predecessors),
//   pdf_rev: the area density with which the OTHER subpath would sample it, walking on,
// both with the connection's values already in place (the caller sets the pdf_rev of the four
// vertices next to the connection: y_{s-1}, y_{s-2}, z_{t-1}, z_{t-2}). The density of strategy
// (s-1, t+1) over that of (s, t) is y_{s-1}.pdf_rev / y_{s-1}.pdf_fwd, and so on outwards, so all
// the other strategies' densities follow from one pass over the path, no O(n^2) re-evaluation:
//   w(s, t) = 1 / (1 + sum over the other strategies k of (p_k / p_s)^2).
// A strategy is left out (it cannot make this path) when either end of its connection is a delta
// vertex (sampled by a specular lobe), when its light end is a delta light (s = 0 with a point,
// spot or directional light), and when it would connect the camera to an infinite light (t = 1,
// s = 1 with y_0 a direction: not a strategy of candela's BDPT). A zero density (a delta
// vertex's) counts as 1 in the ratios: it cancels against the same delta in the other strategy.
namespace candela {

struct MisVertex {
    float pdf_fwd = 0.f, pdf_rev = 0.f;
    bool delta = false;       // sampled by a delta lobe (or a camera with a delta direction: z_0)
    bool infinite = false;    // a direction: y_0 of an infinite light, or where a camera path left the scene
};

// `y0_delta_light`: y_0 (when s > 0; else z_{t-1}, the emitter the camera path reached) is a delta light.
inline float mis_weight(const MisVertex* y, int s, const MisVertex* z, int t, bool y0_delta_light) {
    if (s + t == 2) return 1.f;  // the emitter seen directly: (0, 2) and (1, 1) are not both strategies
    auto remap = [](float p) { return p != 0.f ? p : 1.f; };
    double sum = 0.0, r = 1.0;
    for (int i = t - 1; i > 0; --i) {  // strategy (s + t - i, i): z_i becomes the light end
        r *= double(remap(z[i].pdf_rev)) / double(remap(z[i].pdf_fwd));
        const bool camera_to_direction = i == 1 && z[1].infinite;
        if (!z[i].delta && !z[i - 1].delta && !camera_to_direction) sum += r * r;
    }
    r = 1.0;
    for (int i = s - 1; i >= 0; --i) {  // strategy (i, s + t - i): y_i becomes the camera end
        r *= double(remap(y[i].pdf_rev)) / double(remap(y[i].pdf_fwd));
        const bool prev_delta = i > 0 ? y[i - 1].delta : y0_delta_light;
        if (!y[i].delta && !prev_delta) sum += r * r;
    }
    return float(1.0 / (1.0 + sum));
}

}  // namespace candela
