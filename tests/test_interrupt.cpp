// The process-wide cancellation point (core/interrupt.h): scene loading and accelerator builds
// stop soon after an interrupt is requested, and throw Interrupted (not Error) from outside any
// OpenMP region. The program-level behaviour (a signal during a load writes nothing) is in
// test_signals.cpp.
#include <gtest/gtest.h>
#include <chrono>
#include <cstdio>
#include <thread>
#include "accel/grid.h"
#include "accel/kdtree.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "sampling/pcg32.h"
#include "scene/loaders.h"
#include "scene/obj.h"
#include "support/run.h"

using namespace candela;

namespace {

// n random triangles in a unit cube: a k-d tree build of a million takes seconds.
Mesh random_triangles(uint32_t n) {
    PCG32 rng(7, 1);
    Mesh m;
    for (uint32_t i = 0; i < n; ++i) {
        vec3 c(rng.next_float(), rng.next_float(), rng.next_float());
        for (int k = 0; k < 3; ++k)
            m.positions.push_back(c + 0.01f * vec3(rng.next_float(), rng.next_float(), rng.next_float()));
        m.triangles.push_back(uvec3(3 * i, 3 * i + 1, 3 * i + 2));
        m.tri_shape.push_back(0);
    }
    return m;
}

// How long a stop may take: a few node sweeps or sort runs of the largest nodes (measured below
// 0.3 s in the Release build); the sanitizer build runs several times slower.
#ifdef CANDELA_SANITIZE
constexpr double kMaxStopSeconds = 4.0;
#else
constexpr double kMaxStopSeconds = 0.5;
#endif

struct ClearInterrupt {
    ~ClearInterrupt() { clear_interrupt(); }
};

// Runs `build` on a thread, requests an interrupt after `delay_ms`, and returns the seconds from
// the request to the end of `build`; `threw` says whether it ended with Interrupted (false: it
// had finished before the request).
template <class F>
double seconds_to_stop(F build, int delay_ms, bool& threw) {
    ClearInterrupt guard;
    threw = false;
    std::chrono::steady_clock::time_point end;
    std::thread t([&] {
        try {
            build();
        } catch (const Interrupted&) {
            threw = true;
        }
        end = std::chrono::steady_clock::now();
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    auto asked = std::chrono::steady_clock::now();
    request_interrupt();
    t.join();
    return std::chrono::duration<double>(end - asked).count();
}

}  // namespace

TEST(Interrupt, FlagAndException) {
    ClearInterrupt guard;
    EXPECT_FALSE(interrupt_requested());
    EXPECT_NO_THROW(throw_if_interrupted());
    request_interrupt();
    EXPECT_TRUE(interrupt_requested());
    EXPECT_THROW(throw_if_interrupted(), Interrupted);
    try {
        throw_if_interrupted();
    } catch (const Error&) {
        ADD_FAILURE() << "Interrupted must not be an Error: the loaders rewrap Errors";
    } catch (const Interrupted&) {
    }
    clear_interrupt();
    EXPECT_NO_THROW(throw_if_interrupted());
}

TEST(Interrupt, KdTreeBuildStopsPromptly) {
    const Mesh m = random_triangles(1000000);
    bool threw = false;
    double s = seconds_to_stop([&] { KdTreeAccel accel(m); }, 300, threw);
    EXPECT_TRUE(threw) << "the build finished before the interrupt: make the mesh larger";
    EXPECT_LT(s, kMaxStopSeconds);
    std::printf("k-d tree build stopped %.3f s after the request\n", s);
    // With the flag cleared, trees build again.
    KdTree t;
    t.build(random_triangles(1000));
    EXPECT_FALSE(t.empty());
}

TEST(Interrupt, HybridGridBuildStopsPromptly) {
    const Mesh m = random_triangles(1000000);
    bool threw = false;
    double s = seconds_to_stop([&] { HybridGridAccel accel(m); }, 300, threw);
    EXPECT_TRUE(threw) << "the build finished before the interrupt: make the mesh larger";
    EXPECT_LT(s, kMaxStopSeconds);
    std::printf("hybrid grid build stopped %.3f s after the request\n", s);
}

TEST(Interrupt, ObjLoadStops) {
    ClearInterrupt guard;
    std::string d = test::temp_dir("interrupt-obj");
    test::write_text(d + "/t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    EXPECT_NO_THROW(load_scene(d + "/t.obj", {}));
    request_interrupt();
    EXPECT_THROW(load_scene(d + "/t.obj", {}), Interrupted);
    EXPECT_THROW(read_obj(d + "/t.obj", false), Interrupted);
    test::write_text(d + "/s.xml",
                     "<scene version=\"3.0.0\">\n  <shape type=\"obj\">\n    <string name=\"filename\" "
                     "value=\"t.obj\"/>\n  </shape>\n</scene>\n");
    EXPECT_THROW(load_scene(d + "/s.xml", {}), Interrupted);  // through the XML shape's error wrapping
}
