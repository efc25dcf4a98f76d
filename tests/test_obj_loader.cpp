// Plain OBJ + MTL scenes: materials from Kd/Ke, grouping, normals, default camera, and the errors
// (with the line of the offending statement).
#include <gtest/gtest.h>
#include <fstream>
#include <string>
#include "core/error.h"
#include "scene/loaders.h"
#include "scene/obj.h"

using namespace candela;

namespace {

std::string write_temp(const std::string& name, const std::string& text) {
    std::string d = ::testing::TempDir();
    if (!d.empty() && d.back() != '/') d += '/';
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string path = d + "candela_obj_" + info->name() + "_" + name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

std::string load_error(const std::string& path) {
    try {
        load_obj_scene(path);
    } catch (const Error& e) {
        return e.what();
    }
    return "<no error>";
}

void expect_error(const std::string& text, int line, const std::string& what) {
    std::string path = write_temp("bad.obj", text);
    std::string msg = load_error(path);
    std::string where = line > 0 ? path + ":" + std::to_string(line) + ": " : path + ": ";
    EXPECT_NE(msg.find(where), std::string::npos) << "message: " << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << "message: " << msg;
}

vec3 albedo(const SceneDescription& s, const Shape& sh) { return std::get<DiffuseBsdf>(s.materials[sh.material].bsdf).albedo; }

void expect_near(vec3 a, vec3 b, float eps = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}

}  // namespace

TEST(ObjLoader, MaterialsEmittersAndGroups) {
    SceneDescription s = load_obj_scene(std::string(CANDELA_TEST_DATA) + "/scenes/lights.obj");
    ASSERT_EQ(s.shapes.size(), 3u);  // floor (no material), wall/red, wall/lamp
    EXPECT_EQ(s.shapes[0].name, "floor");
    EXPECT_EQ(s.shapes[0].triangle_count, 2u);
    expect_near(albedo(s, s.shapes[0]), vec3(0.5f));
    EXPECT_EQ(s.shapes[0].emitter, -1);
    EXPECT_EQ(s.shapes[1].name, "wall/red");
    expect_near(albedo(s, s.shapes[1]), vec3(0.8f, 0.1f, 0.1f));
    EXPECT_EQ(s.shapes[1].emitter, -1);
    EXPECT_EQ(s.shapes[2].name, "wall/lamp");
    ASSERT_GE(s.shapes[2].emitter, 0);
    expect_near(s.emitters[size_t(s.shapes[2].emitter)].radiance, vec3(4.f, 3.f, 2.f));
    EXPECT_EQ(s.emitters.size(), 1u);
    for (const Material& m : s.materials) EXPECT_TRUE(m.two_sided);
    for (const Shape& sh : s.shapes) EXPECT_FALSE(sh.smooth);
    EXPECT_TRUE(s.warnings.empty());
    // Fan triangulation keeps the polygon's winding: f 1 4 3 2 faces +y.
    vec3 a, b, c;
    s.mesh.vertices(0, a, b, c);
    expect_near(glm::normalize(glm::cross(b - a, c - a)), vec3(0, 1, 0));

    EXPECT_EQ(s.settings.width, 512);
    EXPECT_EQ(s.settings.height, 512);
    EXPECT_EQ(s.settings.spp, 64);
    EXPECT_EQ(s.settings.max_depth, -1);
    EXPECT_EQ(build_scene(s)->lights.triangle_count(), 1u);
}

TEST(ObjLoader, DefaultCameraFramesBounds) {
    std::string path = write_temp("box.obj", "v -1 -1 -1\nv 3 -1 -1\nv 3 1 1\nf 1 2 3\n");
    SceneDescription s = load_obj_scene(path);
    vec3 origin = vec3(s.camera.to_world[3]);
    vec3 centre(1.f, 0.f, 0.f);
    float r = 0.5f * glm::length(vec3(4.f, 2.f, 2.f));
    EXPECT_NEAR(origin.x, centre.x, 1e-4f);
    EXPECT_NEAR(origin.y, centre.y, 1e-4f);
    EXPECT_NEAR(centre.z - origin.z, r / std::sin(glm::radians(22.5f)), 1e-3f);
    expect_near(vec3(s.camera.to_world[2]), vec3(0, 0, 1));
    EXPECT_FLOAT_EQ(s.camera.fov_deg, 45.f);
    EXPECT_LT(s.camera.near_clip, centre.z - origin.z - r);
    EXPECT_GT(s.camera.far_clip, centre.z - origin.z + r);
}

TEST(ObjLoader, VertexNormalsWhereGiven) {
    std::string path = write_temp("n.obj",
                                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 2\nvn 1 1 1\n"
                                  "g smooth\nf 1//1 2//1 3//2\n"
                                  "g flat\nf 1 2 4\n"
                                  "g mixed\nf 1//1 3 4\n");
    SceneDescription s = load_obj_scene(path);
    ASSERT_EQ(s.shapes.size(), 3u);
    EXPECT_TRUE(s.shapes[0].smooth);
    EXPECT_FALSE(s.shapes[1].smooth);
    EXPECT_FALSE(s.shapes[2].smooth);  // a face without normals: face normals for the group
    uvec3 t = s.mesh.triangles[0];
    expect_near(s.mesh.normals[t.x], vec3(0, 0, 1));  // normalised
    expect_near(s.mesh.normals[t.z], glm::normalize(vec3(1.f)));
}

TEST(ObjLoader, RelativeIndicesAndPolygons) {
    std::string path = write_temp("rel.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 1.5 0\nv 0 1 0\nf -5 -4 -3 -2 -1\n");
    SceneDescription s = load_obj_scene(path);
    ASSERT_EQ(s.mesh.triangles.size(), 3u);  // a pentagon becomes a fan of three
    vec3 a, b, c;
    s.mesh.vertices(2, a, b, c);
    expect_near(a, vec3(0, 0, 0));
    expect_near(b, vec3(0.5f, 1.5f, 0));
    expect_near(c, vec3(0, 1, 0));
}

TEST(ObjLoader, DegenerateTrianglesAreKept) {
    std::string path = write_temp("deg.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\nf 1 1 1\n");
    SceneDescription s = load_obj_scene(path);
    EXPECT_EQ(s.mesh.triangles.size(), 3u);
    auto built = build_scene(s);
    Ray r;
    r.o = vec3(0.25f, 0.25f, 1.f);
    r.d = vec3(0, 0, -1);
    Hit h;
    EXPECT_TRUE(built->accel->intersect(r, h));
    EXPECT_EQ(h.prim, 1u);
}

TEST(ObjLoader, MissingMtlIsAWarning) {
    std::string path = write_temp("nomtl.obj", "mtllib does_not_exist.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
    SceneDescription s = load_obj_scene(path);
    ASSERT_EQ(s.shapes.size(), 1u);
    expect_near(albedo(s, s.shapes[0]), vec3(0.5f));
    EXPECT_FALSE(s.warnings.empty());
}

TEST(ObjLoader, OutOfRangeIndices) {
    std::string path = std::string(CANDELA_TEST_DATA) + "/scenes/bad_index.obj";
    EXPECT_EQ(load_error(path), path + ":6: vertex index 4 out of range (3 defined so far)");
    expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", 4, "vertex index -4 out of range");
    expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", 4, "vertex index 0 out of range");
    expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\n\nf 1//1 2//1 3//2\n", 6, "normal index 2 out of range");
    expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n", 4, "texture coordinate index 1 out of range");
}

TEST(ObjLoader, NonFiniteVertexNamesItsLine) {
    std::string path = std::string(CANDELA_TEST_DATA) + "/scenes/nan_vertex.obj";
    EXPECT_EQ(load_error(path), path + ":4: vertex has a NaN or infinite coordinate");
    expect_error("v 0 0 0\nv 1 0 0\nv 0 1 -inf\nf 1 2 3\n", 3, "NaN or infinite");
    expect_error("v 0 0 0\nv 1 0 0\nv 0 1 1e999\nf 1 2 3\n", 3, "NaN or infinite");
    expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn nan 0 1\nf 1 2 3\n", 4, "normal has a NaN");
}

TEST(ObjLoader, MalformedFiles) {
    expect_error("", 0, "empty OBJ file");
    expect_error("# only a comment\n\n", 0, "empty OBJ file");
    expect_error("v 0 0 0\nv 1 0 0\n", 0, "no faces");
    expect_error("v 0 0 0\nhello world\n", 2, "unknown OBJ statement 'hello'");
    expect_error("v 0 0 0\nv 1 x 0\n", 2, "could not parse number 'x'");
    expect_error("v 0 0\n", 1, "'v' needs 3 coordinates");
    expect_error("v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "at least 3 vertices");
    expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2/3/4 2 3\n", 4, "malformed face vertex");
    expect_error(std::string("v 0 0 0\n\x01\x02\x00\xff garbage", 19), 2, "binary data");
    expect_error("cstype bspline\n", 1, "free-form geometry");
    std::string missing = ::testing::TempDir() + "/no_such_file.obj";
    EXPECT_NE(load_error(missing).find("cannot open file"), std::string::npos);
}

TEST(ObjLoader, ReadObjMergesOnlySharedCorners) {
    // Mitsuba merges vertices by their (v, vt, vn) triple: the two faces share corners 1 and 3.
    std::string path = write_temp("share.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
    ObjData d = read_obj(path, false);
    EXPECT_EQ(d.positions.size(), 4u);
    ASSERT_EQ(d.groups.size(), 1u);
    EXPECT_EQ(d.groups[0].triangles.size(), 2u);
    std::vector<vec3> n = compute_vertex_normals(d.positions, d.groups[0].triangles);
    for (vec3 v : n) expect_near(v, vec3(0, 0, 1));
}
