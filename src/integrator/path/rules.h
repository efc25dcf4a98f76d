#pragma once
// The numeric rules of a path's bounce that both the per-path bounce (path/bounce.h) and the SIMD
// lane step (path/diffuse_step.cpp) apply, written once (path/rules.inc) over a value type V and
// its operations.
// Ops provides set(float), mul, add, div, lt, gt, is_inf and select(mask, a, b) for V: a float with
// ScalarOps below, a Highway vector in diffuse_step.cpp. Each rule is a fixed sequence of IEEE
// operations, so a lane computes what the per-path bounce computes, bit for bit (the staged loop's
// images are compared with the per-path loop's: tests/test_staged.cpp).
#include <cmath>

namespace candela {

// The operations on one float.
struct ScalarOps {
    static float set(float x) { return x; }
    static float mul(float a, float b) { return a * b; }
    static float add(float a, float b) { return a + b; }
    static float div(float a, float b) { return a / b; }
    static bool lt(float a, float b) { return a < b; }
    static bool gt(float a, float b) { return a > b; }
    static bool is_inf(float a) { return std::isinf(a); }
    static float select(bool m, float a, float b) { return m ? a : b; }
};

namespace path_rules {
#include "integrator/path/rules.inc"
}  // namespace path_rules
}  // namespace candela
