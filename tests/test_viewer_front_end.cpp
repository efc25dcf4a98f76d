// The viewer's front end without a window: edits reach the screen, dropped scenes load in the
// background, saves are written off the window's thread, picking selects a material, and the
// window's thread never prepares BSDF tables. The TSan run includes these tests: they drive the
// session the way the window does.
#include <gtest/gtest.h>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>
#include "film/image_io.h"
#include "support/run.h"
#include "viewer/front_end.h"

using namespace candela;
using candela::test::temp_dir;

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

std::shared_ptr<const Scene> cornell(int res) {
    SceneOverrides ov;
    ov.width = ov.height = res;
    return prepare_scene("", ov);
}

SessionOptions options(int max_passes = 0) {
    SessionOptions so;
    so.threads = 2;
    so.max_passes = max_passes;
    return so;
}

// Runs frames as the window does until `done` holds (or the timeout, in seconds, expires).
template <class F>
bool frames_until(ViewerFrontEnd& fe, F done, double timeout = 60) {
    const double t0 = now();
    while (now() - t0 < timeout) {
        fe.begin_frame(now());
        fe.end_frame(now());
        if (done()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return false;
}

}  // namespace

TEST(ViewerFrontEnd, CameraEditsReachTheScreen) {
    ViewerFrontEnd fe(cornell(24), options(), {});
    ASSERT_TRUE(frames_until(fe, [&] { return !fe.image().rgb.empty() && !fe.image().preview; }));
    // A drag: orbit steps in consecutive frames, each sent when the last has reached the screen.
    for (int i = 0; i < 20; ++i) {
        fe.camera().orbit(0.02f, 0.005f);
        fe.camera_changed(now());
        fe.begin_frame(now());
        fe.end_frame(now());
        EXPECT_TRUE(fe.interactive());
    }
    const mat4 final_pose = fe.camera().to_world();
    // Once the hold is over, full passes of the last pose are on screen.
    ASSERT_TRUE(frames_until(fe, [&] {
        return !fe.dirty() && !fe.interactive() && fe.image().generation >= fe.sent_generation() &&
               !fe.image().preview && fe.image().passes >= 2;
    }));
    const std::shared_ptr<const Scene> shown = fe.session().scene();
    EXPECT_EQ(shown->camera.to_world, final_pose);
    EXPECT_EQ(fe.params().camera.to_world, final_pose);
}

TEST(ViewerFrontEnd, DroppedScenesLoadInTheBackground) {
    ViewerFrontEnd fe(cornell(16), options(), {});
    const std::string dir = temp_dir("front_end_drop");
    const std::string obj = dir + "/tri.obj";
    std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::ofstream(dir + "/broken.obj") << "v 0 0 0\nf 1 2 9\n";

    fe.drop({dir + "/notes.txt"});
    fe.begin_frame(now());
    EXPECT_TRUE(fe.status_is_error());
    EXPECT_NE(fe.status().find("not a scene"), std::string::npos) << fe.status();

    fe.drop({dir + "/broken.obj"});
    ASSERT_TRUE(frames_until(fe, [&] { return !fe.loading() && fe.status_is_error(); })) << fe.status();
    EXPECT_EQ(fe.scene().source, "<built-in Cornell box>") << "the old scene keeps rendering";

    fe.drop({obj, dir + "/ignored.obj"});  // the first file of a drop wins
    ASSERT_TRUE(frames_until(fe, [&] { return !fe.loading() && fe.scene().source == obj; })) << fe.status();
    EXPECT_FALSE(fe.status_is_error()) << fe.status();
    EXPECT_EQ(fe.scene().mesh.triangle_count(), 1u);
    EXPECT_EQ(fe.params().materials.size(), fe.scene().materials.size());
    ASSERT_TRUE(frames_until(fe, [&] { return fe.session().scene()->source == obj && !fe.image().rgb.empty(); }));
}

TEST(ViewerFrontEnd, SavesAreWrittenOffTheWindowThread) {
    ViewerFrontEnd fe(cornell(16), options(2), {});
    const std::string path = temp_dir("front_end_save") + "/shot.exr";
    ASSERT_TRUE(fe.session().wait_for(0, 2, 60));
    fe.save_exr(path);
    ASSERT_TRUE(frames_until(fe, [&] { return !fe.saving(); }));
    EXPECT_FALSE(fe.status_is_error()) << fe.status();
    Image img = read_linear_image(path);
    SessionImage full = fe.session().latest_full_image();
    EXPECT_EQ(img.width, full.width);
    EXPECT_EQ(img.rgb, full.rgb);
}

TEST(ViewerFrontEnd, PickSelectsTheMaterialUnderThePixel) {
    ViewerFrontEnd fe(cornell(64), options(1), {});
    fe.pick(ivec2(4, 32));  // the left wall: red, at x = 556 (image left)
    ASSERT_TRUE(fe.has_pick());
    ASSERT_TRUE(fe.pick_result().hit);
    EXPECT_EQ(fe.selected_material, 1);
    EXPECT_TRUE(fe.reveal_selected);
    EXPECT_EQ(fe.scene().shapes[fe.pick_result().shape].name, "red");
}

// Dragging a rough-plastic roughness slider: the window only edits parameters; the worker builds
// the coat tables for each scene it renders.
TEST(ViewerFrontEnd, TheWindowThreadNeverPreparesBsdfTables) {
    SceneDescription d;
    d.source = "<plastic>";
    PlasticBsdf p;
    p.alpha = 0.3f;
    d.materials.push_back({"plastic", p, false});
    d.emitters.push_back({vec3(1.f)});
    d.add_shape("floor", {vec3(-1, 0, -1), vec3(1, 0, -1), vec3(0, 0, 1)}, {}, {uvec3(0, 2, 1)}, 0, -1);
    d.add_shape("lamp", {vec3(-1, 2, -1), vec3(1, 2, -1), vec3(0, 2, 1)}, {}, {uvec3(0, 1, 2)}, 0, 0);
    d.camera.to_world = look_at(vec3(0, 1, -4), vec3(0, 1, 0), vec3(0, 1, 0));
    d.settings.width = d.settings.height = 16;
    ViewerFrontEnd fe(build_scene(std::move(d)), options(), {});
    for (int i = 1; i <= 10; ++i) {
        std::get<PlasticBsdf>(fe.params().materials[0].bsdf).alpha = 0.3f + 0.02f * float(i);
        fe.params_changed(now());
        fe.begin_frame(now());
        fe.end_frame(now());
    }
    const PlasticBsdf& edited = std::get<PlasticBsdf>(fe.params().materials[0].bsdf);
    EXPECT_FALSE(edited.prepared()) << "the window's copy is parameters only";
    ASSERT_TRUE(frames_until(fe, [&] { return !fe.dirty() && fe.image().generation >= fe.sent_generation(); }));
    const PlasticBsdf& rendered = std::get<PlasticBsdf>(fe.session().scene()->materials[0].bsdf);
    ASSERT_TRUE(rendered.prepared());
    EXPECT_EQ(rendered.tables->alpha, edited.alpha);
}

// The front end's statistics carry the estimated error for the panel's plot, and the panel's
// target (set on the session) stops the render: the window's loop sees "target reached".
TEST(ViewerFrontEnd, TargetErrorReachesThePanel) {
    ViewerFrontEnd fe(cornell(24), options(), {});
    fe.session().set_target_error(0.4);
    ASSERT_TRUE(frames_until(fe, [&] { return fe.stats().target_reached && fe.stats().idle; }));
    EXPECT_GE(fe.stats().estimate, 0.0);
    EXPECT_LT(fe.stats().estimate, 0.4);
    EXPECT_FALSE(fe.stats().estimates.empty());
    // An edit restarts: the new render starts without an estimate and stops at the target again.
    fe.params().settings.max_depth = 2;
    fe.params_changed(now());
    ASSERT_TRUE(frames_until(fe, [&] {
        return fe.image().generation >= fe.sent_generation() && fe.stats().generation >= fe.sent_generation() &&
               fe.stats().target_reached && fe.stats().idle;
    }));
    EXPECT_LT(fe.stats().estimate, 0.4);
}

// The panel's integrator combo box edits params().settings.integrator.type and calls
// params_changed: the running session switches to each integrator without a restart of the
// window or the session (docs/viewer.md): full passes of the new integrator accumulate (8 of them in
// one generation), its image is the same scene's (its mean near the path tracer's), and the panel's
// statistics show its rays, and its splats for the splatting integrators.
TEST(ViewerFrontEnd, TheIntegratorSwitchesLive) {
    ViewerFrontEnd fe(cornell(24), options(), {});
    const RenderSession* session = &fe.session();
    auto mean_of = [](const SessionImage& img) {
        double s = 0;
        for (float v : img.rgb) s += double(v);
        return s / double(std::max<size_t>(1, img.rgb.size()));
    };
    ASSERT_TRUE(frames_until(fe, [&] { return !fe.image().preview && fe.image().passes >= 8; }));
    const double path_mean = mean_of(fe.image());
    ASSERT_GT(path_mean, 0.0);
    const IntegratorType types[] = {IntegratorType::Bdpt, IntegratorType::Ptracer, IntegratorType::Pssmlt,
                                    IntegratorType::Mmlt, IntegratorType::Path};
    // The switch is under test, not MLT's brightness: a small bootstrap (mmlt's default is 100000
    // paths per depth, 13 depths here, minutes in the sanitizer and TSan builds' single thread).
    fe.params().settings.integrator.mlt.bootstrap_samples = 20000;
    for (IntegratorType type : types) {
        const std::string name = integrator_type_name(type);
        fe.params().settings.integrator.type = type;
        fe.params_changed(now());
        ASSERT_TRUE(frames_until(
            fe,
            [&] {
                return !fe.dirty() && fe.image().generation >= fe.sent_generation() &&
                       fe.stats().generation >= fe.sent_generation() && !fe.image().preview &&
                       fe.image().passes >= 8 && fe.stats().passes >= 8;
            },
            180))
            << name;
        EXPECT_EQ(&fe.session(), session) << name << ": the session was replaced";
        EXPECT_EQ(fe.session().scene()->settings.integrator.type, type) << name;
        const SessionStats& st = fe.stats();
        EXPECT_TRUE(st.error.empty()) << name << ": " << st.error;
        EXPECT_GT(st.mrays_per_s, 0.0) << name;
        EXPECT_GT(st.msamples_per_s, 0.0) << name;
        if (type == IntegratorType::Path) {
            EXPECT_EQ(st.splats, 0u) << name;
        } else {
            EXPECT_GT(st.splats, 0u) << name << ": no splats in the panel's statistics";
        }
        EXPECT_EQ(st.nonfinite, 0u) << name;
        // Converging: the change per pass (about 1/k after k passes) has fallen since pass 2. Not
        // for the Metropolis integrators: their chains advance less than one mutation per pass at
        // this size, and the per-pixel change of their first passes is erratic (it rises at first).
        ASSERT_GE(st.change.size(), 2u) << name;
        if (type != IntegratorType::Pssmlt && type != IntegratorType::Mmlt) {
            EXPECT_LT(st.change.back(), st.change.front()) << name;
        }
        // The same scene: the image's mean is the path tracer's within noise (20%: a few spp).
        const double m = mean_of(fe.image());
        std::printf("  %-8s %d passes, %.3f Mrays/s, %llu splats, image mean %.4f (path %.4f)\n", name.c_str(), st.passes,
                    st.mrays_per_s, (unsigned long long)st.splats, m, path_mean);
        EXPECT_NEAR(m, path_mean, 0.2 * path_mean) << name;
    }
}
