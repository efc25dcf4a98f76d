// The scene description and the built scene (scene/scene.h): an edit builds a new immutable scene
// that shares what did not change, and derived data is made when a scene is built.
#include <gtest/gtest.h>
#include "core/error.h"
#include "render/launch.h"
#include "scene/cornell.h"
#include "scene/scene.h"

using namespace candela;

namespace {

// One plastic triangle under one emitting triangle.
SceneDescription plastic_scene(float alpha) {
    SceneDescription d;
    d.source = "<plastic>";
    PlasticBsdf p;
    p.alpha = alpha;
    d.materials.push_back({"plastic", p, false});
    d.emitters.push_back({vec3(1.f)});
    d.add_shape("floor", {vec3(-1, 0, -1), vec3(1, 0, -1), vec3(0, 0, 1)}, {}, {uvec3(0, 2, 1)}, 0, -1);
    d.add_shape("lamp", {vec3(-1, 2, -1), vec3(1, 2, -1), vec3(0, 2, 1)}, {}, {uvec3(0, 1, 2)}, 0, 0);
    d.settings.width = d.settings.height = 8;
    return d;
}

const PlasticBsdf& plastic_of(const Scene& s) { return std::get<PlasticBsdf>(s.materials[0].bsdf); }

}  // namespace

TEST(SceneSplit, AnEditSharesTheGeometryAndTheAccelerator) {
    auto box = prepare_scene("", {});
    SceneParams p = box->params();
    p.camera.fov_deg = 20.f;
    p.settings.max_depth = 3;
    std::get<DiffuseBsdf>(p.materials[1].bsdf).albedo = vec3(0.1f);
    auto edited = box->with_params(p);
    EXPECT_EQ(edited->geometry.get(), box->geometry.get());
    EXPECT_EQ(edited->accel.get(), box->accel.get());
    EXPECT_EQ(edited->light_set.get(), box->light_set.get()) << "the emitters did not change";
    EXPECT_EQ(edited->camera.fov_deg, 20.f);
    EXPECT_EQ(edited->settings.max_depth, 3);
    EXPECT_EQ(std::get<DiffuseBsdf>(edited->materials[1].bsdf).albedo, vec3(0.1f));
    // The original is untouched.
    EXPECT_NE(box->camera.fov_deg, 20.f);
    EXPECT_NE(std::get<DiffuseBsdf>(box->materials[1].bsdf).albedo, vec3(0.1f));
}

TEST(SceneSplit, AnEmitterEditRebuildsTheLightSet) {
    auto box = prepare_scene("", {});
    SceneParams p = box->params();
    p.emitters[0].radiance = vec3(0.f);
    auto dark = box->with_params(p);
    EXPECT_NE(dark->light_set.get(), box->light_set.get());
    EXPECT_TRUE(dark->lights.empty()) << "a black light is never sampled";
    EXPECT_FALSE(box->lights.empty());
}

TEST(SceneSplit, MaterialsArePreparedWhenTheSceneIsBuilt) {
    auto s = build_scene(plastic_scene(0.3f));
    ASSERT_TRUE(plastic_of(*s).prepared());
    // The viewer edits the roughness in its parameters, which are not prepared; the built scene is.
    SceneParams p = s->params();
    std::get<PlasticBsdf>(p.materials[0].bsdf).alpha = 0.45f;
    EXPECT_FALSE(std::get<PlasticBsdf>(p.materials[0].bsdf).prepared());
    auto edited = s->with_params(p);
    ASSERT_TRUE(plastic_of(*edited).prepared());
    EXPECT_EQ(plastic_of(*edited).tables->alpha, 0.45f);
    EXPECT_EQ(plastic_of(*s).tables->alpha, 0.3f);
}

TEST(SceneSplit, TheCoatCacheKeepsOnlyTablesInUse) {
    auto s = build_scene(plastic_scene(0.2f));
    const size_t base = coat_table_cache_size();
    // A roughness slider dragged through 40 values: each edit builds a scene and drops the last.
    std::shared_ptr<const Scene> current = s;
    for (int i = 1; i <= 40; ++i) {
        SceneParams p = current->params();
        std::get<PlasticBsdf>(p.materials[0].bsdf).alpha = 0.2f + 0.01f * float(i);
        current = s->with_params(p);
        // In use: the first scene's table and the current one's; at most one more, expired since the
        // last insertion (they are dropped on the next). An unbounded cache would hold base + i.
        EXPECT_LE(coat_table_cache_size(), base + 2) << "after " << i << " edits";
    }
    current.reset();
    auto again = s->with_params(s->params());
    EXPECT_EQ(plastic_of(*again).tables.get(), plastic_of(*s).tables.get()) << "one coat, one table";
}

TEST(SceneSplit, ParametersThatDoNotFitTheGeometryAreRefused) {
    auto box = prepare_scene("", {});
    SceneParams p = box->params();
    p.materials.pop_back();
    EXPECT_THROW(box->with_params(p), Error);
    p = box->params();
    p.emitters.clear();
    EXPECT_THROW(box->with_params(p), Error);
    p = box->params();
    p.settings.width = 0;
    EXPECT_THROW(box->with_params(p), Error);
    p = box->params();
    p.settings.max_depth = -2;
    EXPECT_THROW(box->with_params(p), Error);
}

TEST(SceneSplit, ABuiltSceneKeepsItsCameraReadyForItsFilm) {
    SceneDescription d = make_cornell_box();
    d.settings.width = 40;
    d.settings.height = 20;
    auto s = build_scene(d);
    // The ray through the image centre is the view axis, whatever the film's aspect.
    Ray r = s->camera.generate_ray(vec2(20.f, 10.f));
    EXPECT_NEAR(r.d.z, 1.f, 1e-6f);
}
