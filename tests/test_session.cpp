// The render session: passes match the renderer bit for bit, edits restart, previews while the user
// interacts, pause, and the front end never waits for a pass.
#include <gtest/gtest.h>
#include <algorithm>
#include <chrono>
#include <thread>
#include "render/launch.h"
#include "render/renderer.h"
#include "render/session.h"
#include "core/error.h"
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

using namespace candela;

namespace {

std::shared_ptr<const Scene> cornell(int w, int h) {
    SceneOverrides ov;
    ov.width = w;
    ov.height = h;
    return prepare_scene("", ov);
}

double image_sum(const SessionImage& img) {
    double s = 0;
    for (float v : img.rgb) s += v;
    return s;
}

// Median luminance: robust to the few pixels that see the light directly.
double median_luminance(const SessionImage& img) {
    std::vector<float> l;
    for (size_t i = 0; i + 2 < img.rgb.size(); i += 3) l.push_back(luminance(vec3(img.rgb[i], img.rgb[i + 1], img.rgb[i + 2])));
    std::nth_element(l.begin(), l.begin() + l.size() / 2, l.end());
    return l[l.size() / 2];
}

double now_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

TEST(Session, FullPassesMatchTheRenderer) {
    auto scene = cornell(48, 32);
    SessionOptions opt;
    opt.threads = 2;
    opt.spp_per_pass = 2;
    opt.max_passes = 3;
    RenderSession session(scene, opt);
    ASSERT_TRUE(session.wait_for(0, 3, 60));
    SessionImage img = session.latest_full_image();

    // The same passes rendered directly: the same sample indices give the same image, bit for bit.
    auto ref_scene = cornell(48, 32);
    Film film(48, 32);
    for (int p = 0; p < 3; ++p) Renderer::render_pass(*ref_scene, film, uint32_t(p * 2), 2, 1);
    std::vector<float> ref = film.resolve();
    ASSERT_EQ(img.width, 48);
    ASSERT_EQ(img.height, 32);
    EXPECT_FALSE(img.preview);
    EXPECT_EQ(img.passes, 3);
    ASSERT_EQ(img.rgb.size(), ref.size());
    for (size_t i = 0; i < ref.size(); ++i) ASSERT_EQ(img.rgb[i], ref[i]) << "at float " << i;

    SessionStats st = session.stats();
    EXPECT_EQ(st.passes, 3);
    EXPECT_DOUBLE_EQ(st.spp, 6.0);
    EXPECT_GT(st.msamples_per_s, 0.0);
    EXPECT_GT(st.mrays_per_s, st.msamples_per_s);  // at least one ray per sample
    EXPECT_EQ(st.change.size(), 2u);                // one convergence point per pass after the first
    // Stops at max_passes: no further passes.
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_EQ(session.stats().passes, 3);
}

TEST(Session, FirstImageIsAQuarterResolutionPreview) {
    SessionOptions opt;
    opt.threads = 2;
    opt.max_passes = 1;
    RenderSession session(cornell(64, 48), opt);
    ASSERT_TRUE(session.wait_for(0, 0, 60));
    SessionImage img;
    ASSERT_TRUE(session.take_image(img));
    // Either the preview, or (when the full pass was quick) the full image that replaced it.
    if (img.preview) {
        EXPECT_EQ(img.width, 16);
        EXPECT_EQ(img.height, 12);
    } else {
        EXPECT_EQ(img.width, 64);
    }
    EXPECT_FALSE(session.take_image(img)) << "the same image must not be handed out twice";
}

TEST(Session, LightEditRestartsAndRebuildsTheLights) {
    auto scene = cornell(32, 32);
    SceneParams params = scene->params();
    SessionOptions opt;
    opt.threads = 2;
    opt.max_passes = 2;
    RenderSession session(scene, opt);
    ASSERT_TRUE(session.wait_for(0, 2, 60));
    EXPECT_GT(image_sum(session.latest_full_image()), 0.0);

    params.emitters[0].radiance = vec3(0.f);  // the only light off: the image must be black
    uint64_t gen = session.update(params);
    EXPECT_EQ(gen, 1u);
    ASSERT_TRUE(session.wait_for(gen, 2, 60));
    SessionImage img = session.latest_full_image();
    EXPECT_EQ(img.generation, gen);
    EXPECT_EQ(image_sum(img), 0.0);
    EXPECT_EQ(session.stats().generation, gen);
    EXPECT_EQ(session.stats().passes, 2);
}

TEST(Session, MaterialEditChangesTheImage) {
    auto scene = cornell(32, 32);
    SceneParams params = scene->params();
    SessionOptions opt;
    opt.threads = 2;
    opt.max_passes = 4;
    RenderSession session(scene, opt);
    ASSERT_TRUE(session.wait_for(0, 4, 60));
    EXPECT_GT(median_luminance(session.latest_full_image()), 0.0);
    for (Material& m : params.materials) std::get<DiffuseBsdf>(m.bsdf).albedo = vec3(0.f);
    uint64_t gen = session.update(params);
    ASSERT_TRUE(session.wait_for(gen, 4, 60));
    // Black walls: only the light itself (seen directly) remains.
    SessionImage img = session.latest_full_image();
    EXPECT_EQ(median_luminance(img), 0.0);
    EXPECT_GT(image_sum(img), 0.0);
}

TEST(Session, EditsReturnAtOnceAndRestartWithinATile) {
    // Slow passes (64 spp at 256 x 256): a restart must not wait for the pass to finish.
    auto scene = cornell(256, 256);
    SceneParams params = scene->params();
    SessionOptions opt;
    opt.threads = 2;
    opt.spp_per_pass = 64;
    RenderSession session(scene, opt);
    ASSERT_TRUE(session.wait_for(0, 0, 60));                       // the preview is out
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // a full pass is in flight

    double t0 = now_seconds();
    params.camera.fov_deg = 30.f;
    uint64_t gen = session.update(params);
    double t_update = now_seconds() - t0;
    ASSERT_TRUE(session.wait_for(gen, 0, 60));
    double t_image = now_seconds() - t0;
    EXPECT_LT(t_update, 0.01) << "update() must not wait for the worker";
    // One tile of 64 spp per thread, then a 64 x 64 preview at 1 spp: about 1/100 of the full pass
    // that was cancelled (seconds on a busy machine). The bound is loose so that load cannot fail it.
    EXPECT_LT(t_image, 5.0);
    SessionImage img;
    ASSERT_TRUE(session.take_image(img));
    EXPECT_EQ(img.generation, gen);
    EXPECT_TRUE(img.preview);
    EXPECT_EQ(img.width, 64);
    std::printf("update() %.3f ms, first image of the new generation after %.1f ms\n", t_update * 1e3, t_image * 1e3);
}

TEST(Session, InteractiveRendersPreviewsOnlyUntilReleased) {
    auto scene = cornell(64, 64);
    SceneParams params = scene->params();
    SessionOptions opt;
    opt.threads = 2;
    opt.max_passes = 3;
    RenderSession session(scene, opt);
    session.set_interactive(true);
    params.camera.fov_deg = 45.f;
    uint64_t gen = session.update(params);
    ASSERT_TRUE(session.wait_for(gen, 0, 60));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    SessionStats st = session.stats();
    EXPECT_EQ(st.generation, gen);
    EXPECT_EQ(st.passes, 0) << "no full pass while interacting";
    SessionImage img;
    ASSERT_TRUE(session.take_image(img));
    EXPECT_TRUE(img.preview);
    EXPECT_EQ(img.width, 16);
    EXPECT_GT(img.passes, 1) << "previews accumulate while the user holds still";

    session.set_interactive(false);  // no restart: full passes begin on the same generation
    ASSERT_TRUE(session.wait_for(gen, 3, 60));
    EXPECT_EQ(session.stats().generation, gen);
    ASSERT_TRUE(session.take_image(img));
    EXPECT_FALSE(img.preview);
    EXPECT_EQ(img.width, 64);
}

TEST(Session, PauseStopsFullPassesAndResetRestarts) {
    SessionOptions opt;
    opt.threads = 2;
    RenderSession session(cornell(32, 32), opt);
    ASSERT_TRUE(session.wait_for(0, 2, 60));
    session.set_paused(true);
    // The pass in flight completes, then the worker rests.
    for (int i = 0; i < 1000 && !session.stats().idle; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_TRUE(session.stats().idle);
    int p0 = session.stats().passes;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    EXPECT_EQ(session.stats().passes, p0);
    EXPECT_TRUE(session.stats().paused);

    uint64_t gen = session.reset();  // while paused: restarts and shows one preview
    ASSERT_TRUE(session.wait_for(gen, 0, 60));
    EXPECT_EQ(session.stats().passes, 0);
    session.set_paused(false);
    ASSERT_TRUE(session.wait_for(gen, 2, 60));
}

TEST(Session, ReplaceSceneSwitchesFilmSize) {
    SessionOptions opt;
    opt.threads = 2;
    opt.max_passes = 1;
    RenderSession session(cornell(32, 32), opt);
    ASSERT_TRUE(session.wait_for(0, 1, 60));
    auto other = cornell(40, 24);
    uint64_t gen = session.replace_scene(other);
    EXPECT_EQ(session.scene().get(), other.get());
    ASSERT_TRUE(session.wait_for(gen, 1, 60));
    SessionImage img = session.latest_full_image();
    EXPECT_EQ(img.width, 40);
    EXPECT_EQ(img.height, 24);
}

TEST(Session, MeanRelativeChange) {
    std::vector<float> a = {1, 1, 1, 0, 0, 0}, b = {2, 2, 2, 0, 0, 0};
    // One non-black pixel: |2 - 1| / (1 + eps).
    EXPECT_NEAR(mean_relative_change(b, a, 0.f), 1.0, 1e-6);
    EXPECT_EQ(mean_relative_change(a, a), 0.0);
    EXPECT_EQ(mean_relative_change(a, {1, 1, 1}), 0.0);  // sizes differ
}

TEST(Session, RenderPriorityAppliesToTheWorker) {
    EXPECT_EQ(parse_render_priority("idle"), RenderPriority::Idle);
    EXPECT_EQ(parse_render_priority("low"), RenderPriority::Low);
    EXPECT_EQ(parse_render_priority("normal"), RenderPriority::Normal);
    EXPECT_THROW(parse_render_priority("high"), Error);
    const int base_nice = getpriority(PRIO_PROCESS, 0);
    for (RenderPriority p : {RenderPriority::Normal, RenderPriority::Low, RenderPriority::Idle}) {
        SessionOptions opt;
        opt.threads = 1;
        opt.max_passes = 1;
        opt.priority = p;
        std::atomic<int> policy{-1}, nice{-100};  // outlive the session, whose worker writes them
        RenderSession session(cornell(32, 24), opt);
        // The publish callback runs on the worker thread: it sees that thread's own scheduling.
        session.set_on_publish([&] {
            policy = sched_getscheduler(0);
            nice = getpriority(PRIO_PROCESS, id_t(syscall(SYS_gettid)));
        });
        ASSERT_TRUE(session.wait_for(0, 1, 120)) << render_priority_name(p);
        session.reset();  // one more publish, certainly after the callback was set
        ASSERT_TRUE(session.wait_for(1, 1, 120)) << render_priority_name(p);
        EXPECT_EQ(policy.load(), p == RenderPriority::Idle ? SCHED_IDLE : SCHED_OTHER) << render_priority_name(p);
        EXPECT_EQ(nice.load(), p == RenderPriority::Normal ? base_nice : 19) << render_priority_name(p);
    }
}

// What changes nothing in the image must not restart it: a thread-count change keeps the generation
// and the passes accumulated so far, and the passes after it are the same samples as those of an
// undisturbed render (the image does not depend on the thread count). (The viewer's display-only
// controls, exposure and the panel, never reach the session at all.)
TEST(Session, ThreadCountChangeDoesNotRestart) {
    SessionOptions opt;
    opt.threads = 2;
    opt.spp_per_pass = 1;
    opt.max_passes = 6;
    RenderSession session(cornell(32, 24), opt);
    ASSERT_TRUE(session.wait_for(0, 2, 60));
    const uint64_t gen = session.stats().generation;
    const int before = session.stats().passes;
    session.set_threads(1);
    ASSERT_TRUE(session.wait_for(gen, 6, 120));
    EXPECT_EQ(session.stats().generation, gen);
    EXPECT_GE(session.stats().passes, before);
    SessionImage img = session.latest_full_image();
    EXPECT_EQ(img.generation, gen);
    EXPECT_EQ(img.passes, 6);

    Film film(32, 24);
    auto ref_scene = cornell(32, 24);
    for (int p = 0; p < 6; ++p) Renderer::render_pass(*ref_scene, film, uint32_t(p), 1, 2);
    std::vector<float> ref = film.resolve();
    ASSERT_EQ(img.rgb.size(), ref.size());
    for (size_t i = 0; i < ref.size(); ++i) ASSERT_EQ(img.rgb[i], ref[i]) << "at float " << i;
}

// The front end reads snapshots while the worker applies edits. A snapshot never changes (the
// worker builds a new scene for every edit), so the window can read any part of it (emitters,
// materials, settings: what the panel shows) without a lock; under ThreadSanitizer this is the
// check that the window and the worker share no mutable scene state.
TEST(Session, FrontEndReadsSnapshotsWhileTheWorkerEdits) {
    auto scene = cornell(24, 24);
    SceneParams params = scene->params();
    SessionOptions opt;
    opt.threads = 2;
    RenderSession session(scene, opt);
    const std::shared_ptr<const Scene> first = session.scene();
    const vec3 L0 = first->emitters[0].radiance;
    uint64_t gen = 0;
    double seen = 0;
    for (int i = 1; i <= 40; ++i) {
        params.emitters[0].radiance = L0 * (1.f + 0.01f * float(i));
        std::get<DiffuseBsdf>(params.materials[0].bsdf).albedo = vec3(0.5f + 0.01f * float(i));
        params.settings.max_depth = i % 5;
        gen = session.update(params);
        // What the panel reads, from whatever snapshot is current.
        std::shared_ptr<const Scene> s = session.scene();
        seen += s->emitters[0].radiance.x + std::get<DiffuseBsdf>(s->materials[0].bsdf).albedo.x +
                double(s->settings.max_depth) + double(s->lights.triangle_count());
        if (i % 8 == 0) {
            ASSERT_TRUE(session.wait_for(gen, 0, 60));
        }
    }
    ASSERT_TRUE(session.wait_for(gen, 1, 60));
    EXPECT_GT(seen, 0.0);
    // The first snapshot is untouched; the current one has the last edit, with its own light set
    // over the same geometry and accelerator.
    EXPECT_EQ(first->emitters[0].radiance, L0);
    std::shared_ptr<const Scene> last = session.scene();
    EXPECT_EQ(last->emitters[0].radiance, params.emitters[0].radiance);
    EXPECT_EQ(last->settings.max_depth, params.settings.max_depth);
    EXPECT_EQ(last->geometry.get(), first->geometry.get());
    EXPECT_EQ(last->accel.get(), first->accel.get());
    EXPECT_NE(last->light_set.get(), first->light_set.get());
}

// An edit that does not fit the scene (here: a material missing) is refused by the worker, which
// keeps rendering the last good parameters and says why; nothing throws on either thread.
TEST(Session, AnEditThatDoesNotFitIsRefused) {
    auto scene = cornell(16, 16);
    SceneParams params = scene->params();
    SessionOptions opt;
    opt.threads = 1;
    opt.max_passes = 2;
    RenderSession session(scene, opt);
    ASSERT_TRUE(session.wait_for(0, 2, 60));
    const double before = image_sum(session.latest_full_image());
    params.materials.pop_back();
    uint64_t gen = session.update(params);
    ASSERT_TRUE(session.wait_for(gen, 2, 60));
    SessionStats st = session.stats();
    EXPECT_NE(st.error.find("names material"), std::string::npos) << st.error;
    EXPECT_EQ(session.scene()->materials.size(), scene->materials.size());
    EXPECT_EQ(image_sum(session.latest_full_image()), before);  // the same samples of the same scene
}

// A target error stops the full passes once the estimated error (from the even and odd passes) is
// below it, without a restart; a lower target resumes the render, 0 renders on for ever. The
// estimate is published after every pass from the second on, and falls as passes accumulate.
TEST(Session, TargetErrorStopsTheRender) {
    SessionOptions opt;
    opt.threads = 2;
    opt.spp_per_pass = 2;
    RenderSession session(cornell(32, 24), opt);
    session.set_target_error(0.5);
    auto wait_reached = [&] {
        for (int i = 0; i < 6000 && !(session.stats().target_reached && session.stats().idle); ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        return session.stats().target_reached && session.stats().idle;
    };
    ASSERT_TRUE(wait_reached());
    SessionStats st = session.stats();
    EXPECT_GE(st.passes, 2);
    EXPECT_GE(st.estimate, 0.0);
    EXPECT_LT(st.estimate, 0.5);
    EXPECT_EQ(st.estimates.size(), size_t(st.passes - 1));
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    EXPECT_EQ(session.stats().passes, st.passes);  // stopped
    // A lower target: the same generation renders on until it is reached too.
    const double lower = st.estimate / 1.5;
    session.set_target_error(lower);
    ASSERT_TRUE(wait_reached());
    SessionStats st2 = session.stats();
    EXPECT_EQ(st2.generation, st.generation);
    EXPECT_GT(st2.passes, st.passes);
    EXPECT_LT(st2.estimate, lower);
    EXPECT_LT(st2.estimates.back(), st2.estimates.front());
    // No target: renders on.
    session.set_target_error(0);
    EXPECT_FALSE(session.stats().target_reached);
    ASSERT_TRUE(session.wait_for(st2.generation, st2.passes + 2, 60));
}
