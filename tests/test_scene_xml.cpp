// The Mitsuba 3 XML subset: defaults and substitution, transforms, shapes, refs, and one test per
// error class with the exact file:line of the message.
#include <gtest/gtest.h>
#include <cstdio>
#include <fstream>
#include <string>
#include "core/error.h"
#include "scene/cornell.h"
#include "scene/loaders.h"

using namespace candela;

namespace {

std::string temp_dir() {
    std::string d = ::testing::TempDir();
    if (!d.empty() && d.back() != '/') d += '/';
    return d;
}

// Writes `text` to a fresh file in the test's temp directory and returns its path.
std::string write_temp(const std::string& name, const std::string& text) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string path = temp_dir() + "candela_xml_" + info->name() + "_" + name;
    std::ofstream(path) << text;
    return path;
}

// A scene file around `body`: line 1 is <scene>, so body line k is file line k + 1.
std::string scene_xml(const std::string& body) { return "<scene version=\"3.0.0\">\n" + body + "</scene>\n"; }

std::string load_error(const std::string& path, const Defines& defines = {}) {
    try {
        load_mitsuba_xml(path, defines);
    } catch (const Error& e) {
        return e.what();
    }
    return "<no error>";
}

// Loads `body` (see scene_xml) and expects an error at file line `line` containing `what`.
void expect_error(const std::string& body, int line, const std::string& what, const Defines& defines = {}) {
    std::string path = write_temp("scene.xml", scene_xml(body));
    std::string msg = load_error(path, defines);
    EXPECT_NE(msg.find(path + ":" + std::to_string(line) + ": "), std::string::npos) << "message: " << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << "message: " << msg;
}

const char* kQuadObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

void expect_near(vec3 a, vec3 b, float eps = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}

vec3 geometric_normal(const SceneDescription& s, uint32_t tri) {
    vec3 a, b, c;
    s.mesh.vertices(tri, a, b, c);
    return glm::normalize(glm::cross(b - a, c - a));
}

const DiffuseBsdf& diffuse_of(const SceneDescription& s, uint32_t shape) {
    return std::get<DiffuseBsdf>(s.materials[s.shapes[shape].material].bsdf);
}

// Loads a rectangle with the given <transform> body; returns its four corners in world space.
std::vector<vec3> transformed_rectangle(const std::string& ops) {
    std::string path = write_temp("rect.xml", scene_xml("<shape type=\"rectangle\"><transform name=\"to_world\">" + ops +
                                                        "</transform></shape>\n"));
    SceneDescription s = load_mitsuba_xml(path, {});
    return s.mesh.positions;
}

void expect_transform(const std::string& ops, const mat4& expected) {
    std::vector<vec3> got = transformed_rectangle(ops);
    const vec3 corners[4] = {vec3(-1, -1, 0), vec3(1, -1, 0), vec3(1, 1, 0), vec3(-1, 1, 0)};
    ASSERT_EQ(got.size(), 4u);
    for (int i = 0; i < 4; ++i) expect_near(got[size_t(i)], vec3(expected * glm::vec4(corners[i], 1.f)));
}

// Column-major construction from the rows as one reads them.
mat4 rows(std::initializer_list<float> v) {
    mat4 m(0.f);
    auto it = v.begin();
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[c][r] = *it++;
    return m;
}

}  // namespace

TEST(SceneXml, CornellBoxMatchesBuiltIn) {
    SceneDescription xml = load_mitsuba_xml(std::string(CANDELA_SOURCE_DIR) + "/scenes/cornell-box/scene.xml", {});
    SceneDescription ref = make_cornell_box();

    ASSERT_EQ(xml.shapes.size(), ref.shapes.size());
    ASSERT_EQ(xml.mesh.triangles.size(), ref.mesh.triangles.size());
    for (size_t i = 0; i < ref.shapes.size(); ++i) {
        const Shape& a = xml.shapes[i];
        const Shape& b = ref.shapes[i];
        EXPECT_EQ(a.name, b.name + ".obj");
        EXPECT_EQ(a.first_triangle, b.first_triangle);
        EXPECT_EQ(a.triangle_count, b.triangle_count);
        EXPECT_EQ(a.smooth, b.smooth) << a.name;
        EXPECT_EQ(a.emitter >= 0, b.emitter >= 0) << a.name;
        if (a.emitter >= 0) expect_near(xml.emitters[size_t(a.emitter)].radiance, ref.emitters[size_t(b.emitter)].radiance);
        const Material& ma = xml.materials[a.material];
        const Material& mb = ref.materials[b.material];
        EXPECT_EQ(ma.two_sided, mb.two_sided);
        expect_near(std::get<DiffuseBsdf>(ma.bsdf).albedo, std::get<DiffuseBsdf>(mb.bsdf).albedo);
    }
    for (size_t t = 0; t < ref.mesh.triangles.size(); ++t) {
        vec3 a[3], b[3];
        xml.mesh.vertices(uint32_t(t), a[0], a[1], a[2]);
        ref.mesh.vertices(uint32_t(t), b[0], b[1], b[2]);
        for (int k = 0; k < 3; ++k) expect_near(a[k], b[k], 1e-4f);
    }
    // Named materials as in the built-in box.
    EXPECT_EQ(xml.materials[xml.shapes[0].material].name, "white");
    EXPECT_EQ(xml.emitters.size(), 1u);

    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_NEAR(xml.camera.to_world[c][r], ref.camera.to_world[c][r], 1e-5f);
    EXPECT_FLOAT_EQ(xml.camera.fov_deg, ref.camera.fov_deg);
    EXPECT_EQ(xml.camera.fov_axis, ref.camera.fov_axis);
    EXPECT_FLOAT_EQ(xml.camera.near_clip, ref.camera.near_clip);
    EXPECT_FLOAT_EQ(xml.camera.far_clip, ref.camera.far_clip);

    EXPECT_EQ(xml.settings.width, ref.settings.width);
    EXPECT_EQ(xml.settings.height, ref.settings.height);
    EXPECT_EQ(xml.settings.spp, ref.settings.spp);
    EXPECT_EQ(xml.settings.seed, ref.settings.seed);
    EXPECT_EQ(xml.settings.max_depth, ref.settings.max_depth);
    EXPECT_EQ(xml.settings.rr_depth, ref.settings.rr_depth);
    EXPECT_TRUE(xml.warnings.empty());
    EXPECT_EQ(build_scene(xml)->lights.triangle_count(), 2u);
}

TEST(SceneXml, CornellBoxDefinesOverrideDefaults) {
    std::string path = std::string(CANDELA_SOURCE_DIR) + "/scenes/cornell-box/scene.xml";
    SceneDescription s = load_mitsuba_xml(path, {{"res", "64"}, {"spp", "3"}, {"max_depth", "4"}, {"seed", "7"}});
    EXPECT_EQ(s.settings.width, 64);  // width's <default> is "$res"
    EXPECT_EQ(s.settings.height, 64);
    EXPECT_EQ(s.settings.spp, 3);
    EXPECT_EQ(s.settings.max_depth, 3);  // Mitsuba's 4 segments = 3 scattering events
    EXPECT_EQ(s.settings.seed, 7u);
    SceneDescription w = load_mitsuba_xml(path, {{"width", "100"}});
    EXPECT_EQ(w.settings.width, 100);
    EXPECT_EQ(w.settings.height, 512);
}

TEST(SceneXml, DefaultsWithoutFilmSamplerIntegrator) {
    std::string path = write_temp("s.xml", scene_xml("<sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/></sensor>\n"
                                                     "<shape type=\"rectangle\"/>\n"));
    SceneDescription s = load_mitsuba_xml(path, {});
    EXPECT_EQ(s.settings.width, 768);
    EXPECT_EQ(s.settings.height, 576);
    EXPECT_EQ(s.settings.spp, 4);
    EXPECT_EQ(s.settings.seed, 0u);
    EXPECT_EQ(s.settings.max_depth, -1);
    EXPECT_EQ(s.settings.rr_depth, 5);
    EXPECT_FLOAT_EQ(s.camera.fov_deg, 30.f);
    EXPECT_EQ(s.camera.fov_axis, FovAxis::X);
    EXPECT_FLOAT_EQ(s.camera.near_clip, 1e-2f);
    EXPECT_FLOAT_EQ(s.camera.far_clip, 1e4f);
    // The rectangle got Mitsuba's default BSDF: one-sided diffuse 0.5.
    expect_near(diffuse_of(s, 0).albedo, vec3(0.5f));
    EXPECT_FALSE(s.materials[s.shapes[0].material].two_sided);
}

TEST(SceneXml, SensorWithoutFovUsesMitsubaFocalLength) {
    std::string path = write_temp("s.xml", scene_xml("<sensor type=\"perspective\"/>\n"));
    SceneDescription s = load_mitsuba_xml(path, {});
    EXPECT_EQ(s.camera.fov_axis, FovAxis::Diagonal);
    // Mitsuba reports an x fov of 38.1848 degrees for this camera on its default 768 x 576 film.
    float tan_diag = std::tan(glm::radians(0.5f * s.camera.fov_deg));
    float x_fov = 2.f * glm::degrees(std::atan(tan_diag * 768.f / std::hypot(768.f, 576.f)));
    EXPECT_NEAR(x_fov, 38.18484f, 1e-3f);
}

TEST(SceneXml, SensorFilmSamplerIntegratorValues) {
    std::string path = write_temp("s.xml", scene_xml(
        "<integrator type=\"path\"><integer name=\"max_depth\" value=\"1\"/><integer name=\"rr_depth\" value=\"9\"/>"
        "<boolean name=\"hide_emitters\" value=\"false\"/></integrator>\n"
        "<sensor type=\"perspective\"><float name=\"fov\" value=\"50\"/><string name=\"fov_axis\" value=\"smaller\"/>"
        "<float name=\"near_clip\" value=\"0.5\"/><float name=\"far_clip\" value=\"99\"/>"
        "<film type=\"hdrfilm\"><integer name=\"width\" value=\"32\"/><integer name=\"height\" value=\"16\"/>"
        "<string name=\"component_format\" value=\"float32\"/><string name=\"pixel_format\" value=\"rgba\"/>"
        "<string name=\"file_format\" value=\"openexr\"/><rfilter type=\"box\"/></film>"
        "<sampler type=\"independent\"><integer name=\"sample_count\" value=\"17\"/><integer name=\"seed\" value=\"5\"/></sampler>"
        "</sensor>\n"));
    SceneDescription s = load_mitsuba_xml(path, {});
    EXPECT_EQ(s.settings.max_depth, 0);  // one segment: emitters seen directly only
    EXPECT_EQ(s.settings.rr_depth, 9);
    EXPECT_EQ(s.camera.fov_axis, FovAxis::Smaller);
    EXPECT_FLOAT_EQ(s.camera.fov_deg, 50.f);
    EXPECT_FLOAT_EQ(s.camera.near_clip, 0.5f);
    EXPECT_FLOAT_EQ(s.camera.far_clip, 99.f);
    EXPECT_EQ(s.settings.width, 32);
    EXPECT_EQ(s.settings.height, 16);
    EXPECT_EQ(s.settings.spp, 17);
    EXPECT_EQ(s.settings.seed, 5u);
    EXPECT_EQ(s.settings.sampler, SamplerDesc());
}

// The sampler plugins: the type, jitter, and the sample count rounded up to what the sampler
// stratifies over, with a warning naming the file and line (Mitsuba rounds the same way).
TEST(SceneXml, SamplerPlugins) {
    auto load = [](const std::string& sampler) {
        return load_mitsuba_xml(write_temp("smp.xml", scene_xml("<sensor type=\"perspective\">\n" + sampler + "</sensor>\n")), {});
    };
    SceneDescription a = load("<sampler type=\"stratified\"><integer name=\"sample_count\" value=\"10\"/>"
                              "<boolean name=\"jitter\" value=\"false\"/><integer name=\"seed\" value=\"3\"/></sampler>");
    EXPECT_EQ(a.settings.sampler.type, SamplerType::Stratified);
    EXPECT_FALSE(a.settings.sampler.jitter);
    EXPECT_EQ(a.settings.spp, 16);
    EXPECT_EQ(a.settings.seed, 3u);
    ASSERT_EQ(a.warnings.size(), 1u);
    EXPECT_NE(a.warnings[0].find("smp.xml:"), std::string::npos) << a.warnings[0];
    EXPECT_NE(a.warnings[0].find("rounded up to 16"), std::string::npos) << a.warnings[0];
    const std::pair<const char*, int> cases[] = {{"multijitter", 12}, {"ldsampler", 16}, {"sobol", 10}, {"zsobol", 16}, {"orthogonal", 25}};
    for (const auto& [name, spp] : cases) {
        SceneDescription b = load(std::string("<sampler type=\"") + name + "\"><integer name=\"sample_count\" value=\"10\"/></sampler>");
        SamplerType t;
        ASSERT_TRUE(parse_sampler_type(name, t));
        EXPECT_EQ(b.settings.sampler.type, t) << name;
        EXPECT_TRUE(b.settings.sampler.jitter) << name;
        EXPECT_EQ(b.settings.spp, spp) << name;
    }
}

TEST(SceneXml, SubstitutionInEveryAttribute) {
    std::string path = write_temp("s.xml", scene_xml(
        "<default name=\"fov\" value=\"33\"/>\n<default name=\"kind\" value=\"perspective\"/>\n"
        "<default name=\"r\" value=\"0.25\"/>\n<default name=\"mat\" value=\"m1\"/>\n"
        "<sensor type=\"$kind\"><float name=\"fov\" value=\"$fov\"/></sensor>\n"
        "<bsdf type=\"diffuse\" id=\"$mat\"><rgb name=\"reflectance\" value=\"$r, $r 0.75\"/></bsdf>\n"
        "<shape type=\"rectangle\"><ref id=\"m1\"/></shape>\n"));
    SceneDescription s = load_mitsuba_xml(path, {});
    EXPECT_FLOAT_EQ(s.camera.fov_deg, 33.f);
    expect_near(diffuse_of(s, 0).albedo, vec3(0.25f, 0.25f, 0.75f));
    SceneDescription d = load_mitsuba_xml(path, {{"fov", "12"}, {"r", "0.5"}});
    EXPECT_FLOAT_EQ(d.camera.fov_deg, 12.f);
    expect_near(diffuse_of(d, 0).albedo, vec3(0.5f, 0.5f, 0.75f));
}

TEST(SceneXml, UndefinedParameterIsAnError) {
    expect_error("<sensor type=\"perspective\">\n<float name=\"fov\" value=\"$nope\"/></sensor>\n", 3, "undefined parameter $nope");
    // A define alone is enough.
    std::string path = write_temp("ok.xml", scene_xml("<sensor type=\"perspective\"><float name=\"fov\" value=\"$f\"/></sensor>\n"));
    EXPECT_FLOAT_EQ(load_mitsuba_xml(path, {{"f", "20"}}).camera.fov_deg, 20.f);
}

TEST(SceneXml, TransformOps) {
    expect_transform("<translate x=\"1\" y=\"2\" z=\"3\"/>", rows({1, 0, 0, 1, 0, 1, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1}));
    expect_transform("<translate value=\"1, 2 3\"/>", rows({1, 0, 0, 1, 0, 1, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1}));
    expect_transform("<translate y=\"-4\"/>", rows({1, 0, 0, 0, 0, 1, 0, -4, 0, 0, 1, 0, 0, 0, 0, 1}));
    expect_transform("<scale value=\"2\"/>", rows({2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1}));
    expect_transform("<scale value=\"2 3 4\"/>", rows({2, 0, 0, 0, 0, 3, 0, 0, 0, 0, 4, 0, 0, 0, 0, 1}));
    expect_transform("<scale x=\"5\"/>", rows({5, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}));
    // Right-handed: 90 degrees about +z takes +x to +y.
    expect_transform("<rotate z=\"1\" angle=\"90\"/>", rows({0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}));
    expect_transform("<rotate x=\"1\" angle=\"90\"/>", rows({1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1}));
    // A non-unit axis is used as given, as Mitsuba 3.9 (c I + s [a]x + (1 - c) a a^T; values printed by
    // mi.ScalarTransform4f().rotate([0, 1, 1], 90) and rotate([0, 2, 0], 180)).
    expect_transform("<rotate value=\"0 2 0\" angle=\"180\"/>", rows({-1, 0, 0, 0, 0, 7, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1}));
    expect_transform("<rotate x=\"0\" y=\"1\" z=\"1\" angle=\"90\"/>", rows({0, -1, 1, 0, 1, 1, 1, 0, -1, 1, 1, 0, 0, 0, 0, 1}));
    expect_transform("<matrix value=\"2 1 0 4  0 3 1 5  1 0 2 6  0 0 0 1\"/>",
                     rows({2, 1, 0, 4, 0, 3, 1, 5, 1, 0, 2, 6, 0, 0, 0, 1}));
    expect_transform("<matrix value=\"0 -1 0  1 0 0  0 0 1\"/>", rows({0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}));
    // lookat: columns left = up x forward, up, forward, origin.
    expect_transform("<lookat origin=\"1 2 3\" target=\"1 2 4\" up=\"0 1 0\"/>",
                     rows({1, 0, 0, 1, 0, 1, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1}));
    expect_transform("<lookat origin=\"0 0 0\" target=\"5 0 0\" up=\"0 0 1\"/>",
                     rows({0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1}));
    // Later operations apply after earlier ones: scale then translate = T * S.
    expect_transform("<scale value=\"2\"/><translate x=\"1\"/>", rows({2, 0, 0, 1, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1}));
    expect_transform("<translate x=\"1\"/><scale value=\"2\"/>", rows({2, 0, 0, 2, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1}));
    expect_transform("<translate x=\"1\"/><rotate z=\"1\" angle=\"90\"/>", rows({0, -1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 1}));
}

TEST(SceneXml, TransformErrors) {
    expect_error("<shape type=\"rectangle\"><transform name=\"to_world\">\n<lookat origin=\"1 1 1\" target=\"1 1 1\" up=\"0 1 0\"/>"
                 "</transform></shape>\n", 3, "target equals origin");
    expect_error("<shape type=\"rectangle\"><transform name=\"to_world\">\n\n<lookat origin=\"0 0 0\" target=\"0 2 0\" up=\"0 1 0\"/>"
                 "</transform></shape>\n", 4, "parallel");
    expect_error("<shape type=\"rectangle\"><transform name=\"to_world\">\n<skew value=\"1\"/></transform></shape>\n", 3,
                 "unknown transform operation <skew>");
    expect_error("<shape type=\"rectangle\"><transform name=\"to_world\">\n<matrix value=\"1 2 3\"/></transform></shape>\n", 3,
                 "needs 16 or 9 numbers");
    expect_error("<shape type=\"rectangle\"><transform name=\"to_world\">\n<translate value=\"1 a 2\"/></transform></shape>\n", 3,
                 "could not parse");
    expect_error("<shape type=\"rectangle\"><transform name=\"to_world\">\n<rotate angle=\"3\"/></transform></shape>\n", 3,
                 "non-zero axis");
    expect_error("<sensor type=\"perspective\">\n<transform name=\"to_world\"><scale value=\"2\"/></transform></sensor>\n", 3,
                 "must not scale");
}

TEST(SceneXml, RectangleCubeAndFlipNormals) {
    std::string path = write_temp("s.xml", scene_xml(
        "<shape type=\"rectangle\"/>\n"
        "<shape type=\"rectangle\"><boolean name=\"flip_normals\" value=\"true\"/></shape>\n"
        "<shape type=\"rectangle\"><transform name=\"to_world\"><rotate x=\"1\" angle=\"90\"/></transform></shape>\n"
        "<shape type=\"rectangle\"><transform name=\"to_world\"><scale z=\"-1\"/></transform></shape>\n"
        "<shape type=\"cube\"><transform name=\"to_world\"><translate x=\"10\"/></transform></shape>\n"
        "<shape type=\"cube\"><boolean name=\"flip_normals\" value=\"true\"/></shape>\n"));
    SceneDescription s = load_mitsuba_xml(path, {});
    ASSERT_EQ(s.shapes.size(), 6u);
    for (uint32_t t = 0; t < 2; ++t) expect_near(geometric_normal(s, s.shapes[0].first_triangle + t), vec3(0, 0, 1));
    for (uint32_t t = 0; t < 2; ++t) expect_near(geometric_normal(s, s.shapes[1].first_triangle + t), vec3(0, 0, -1));
    expect_near(geometric_normal(s, s.shapes[2].first_triangle), vec3(0, -1, 0));  // R_x(90) (0,0,1)
    // Under a mirroring transform Mitsuba's rectangle keeps the winding's geometric normal but
    // shades with M^-T (0,0,1): candela reproduces both.
    expect_near(geometric_normal(s, s.shapes[3].first_triangle), vec3(0, 0, 1));
    EXPECT_TRUE(s.shapes[3].smooth);
    expect_near(s.mesh.normals[s.mesh.triangles[s.shapes[3].first_triangle].x], vec3(0, 0, -1));
    EXPECT_FALSE(s.shapes[0].smooth);
    EXPECT_FALSE(s.shapes[4].smooth);
    ASSERT_EQ(s.shapes[4].triangle_count, 12u);
    for (int k = 4; k <= 5; ++k) {
        const Shape& sh = s.shapes[size_t(k)];
        vec3 centre = k == 4 ? vec3(10, 0, 0) : vec3(0.f);
        for (uint32_t t = sh.first_triangle; t < sh.first_triangle + sh.triangle_count; ++t) {
            vec3 a, b, c;
            s.mesh.vertices(t, a, b, c);
            float side = glm::dot(geometric_normal(s, t), (a + b + c) / 3.f - centre);
            EXPECT_GT(k == 4 ? side : -side, 0.5f) << "cube " << k << " triangle " << t;
            EXPECT_NEAR(s.mesh.triangle_area(t), 2.f, 1e-5f);
        }
    }
}

TEST(SceneXml, ObjShapeNormalsAndTransform) {
    std::string dir_obj = write_temp("quad.obj", kQuadObj);
    std::string with_n = write_temp("quad_n.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n");
    std::string name = dir_obj.substr(dir_obj.find_last_of('/') + 1);
    std::string name_n = with_n.substr(with_n.find_last_of('/') + 1);
    std::string path = write_temp("s.xml", scene_xml(
        "<shape type=\"obj\"><string name=\"filename\" value=\"" + name + "\"/></shape>\n"
        "<shape type=\"obj\"><string name=\"filename\" value=\"" + name + "\"/><boolean name=\"face_normals\" value=\"true\"/></shape>\n"
        "<shape type=\"obj\"><string name=\"filename\" value=\"" + name_n + "\"/>"
        "<transform name=\"to_world\"><scale value=\"1 2 4\"/><rotate y=\"1\" angle=\"90\"/></transform>"
        "<boolean name=\"flip_normals\" value=\"true\"/><boolean name=\"flip_tex_coords\" value=\"false\"/></shape>\n"));
    SceneDescription s = load_mitsuba_xml(path, {});
    ASSERT_EQ(s.shapes.size(), 3u);
    // No normals in the file: Mitsuba computes vertex normals (here all +z).
    EXPECT_TRUE(s.shapes[0].smooth);
    EXPECT_EQ(s.shapes[0].triangle_count, 2u);
    for (uint32_t v = 0; v < 4; ++v) expect_near(s.mesh.normals[v], vec3(0, 0, 1));
    EXPECT_FALSE(s.shapes[1].smooth);
    EXPECT_TRUE(s.shapes[2].smooth);
    // Scaled then rotated about y by 90: +z goes to +x, then flip_normals negates.
    const Shape& sh = s.shapes[2];
    uvec3 t = s.mesh.triangles[sh.first_triangle];
    expect_near(s.mesh.normals[t.x], vec3(-1, 0, 0));
    expect_near(geometric_normal(s, sh.first_triangle), vec3(-1, 0, 0));
    vec3 a, b, c;
    s.mesh.vertices(sh.first_triangle, a, b, c);
    expect_near(a, vec3(0, 0, 0));
    // Vertex (1,1,0) -> scale (1,2,0) -> rotate about y: (x,y,z) -> (z, y, -x) = (0, 2, -1).
    bool found = false;
    for (vec3 p : {a, b, c}) found = found || glm::length(p - vec3(0, 2, -1)) < 1e-5f;
    EXPECT_TRUE(found);
}

TEST(SceneXml, RefsAndIds) {
    std::string path = write_temp("s.xml", scene_xml(
        "<shape type=\"rectangle\"><ref id=\"later\"/></shape>\n"
        "<shape type=\"rectangle\"><ref name=\"bsdf\" id=\"later\"/></shape>\n"
        "<bsdf type=\"diffuse\" id=\"later\"><float name=\"reflectance\" value=\"0.2\"/></bsdf>\n"
        "<shape type=\"rectangle\" id=\"named\"><bsdf type=\"diffuse\" id=\"inner\"><rgb name=\"reflectance\" value=\"0.1 0.2 0.3\"/></bsdf></shape>\n"
        "<shape type=\"rectangle\"><ref id=\"inner\"/></shape>\n"
        "<shape type=\"rectangle\"><bsdf type=\"diffuse\"/><emitter type=\"area\"/></shape>\n"));
    SceneDescription s = load_mitsuba_xml(path, {});
    ASSERT_EQ(s.shapes.size(), 5u);
    EXPECT_EQ(s.shapes[0].material, s.shapes[1].material);
    EXPECT_EQ(s.materials[s.shapes[0].material].name, "later");
    expect_near(diffuse_of(s, 0).albedo, vec3(0.2f));
    EXPECT_EQ(s.shapes[2].name, "named");
    expect_near(diffuse_of(s, 2).albedo, vec3(0.1f, 0.2f, 0.3f));
    EXPECT_EQ(s.shapes[3].material, s.shapes[2].material);
    expect_near(diffuse_of(s, 4).albedo, vec3(0.5f));
    ASSERT_EQ(s.shapes[4].emitter, 0);
    expect_near(s.emitters[0].radiance, vec3(1.f));  // area radiance defaults to 1
    EXPECT_EQ(s.shapes[0].emitter, -1);
    for (const Material& m : s.materials) EXPECT_FALSE(m.two_sided);
}

TEST(SceneXml, NoSensorGivesFramingCamera) {
    std::string path = write_temp("s.xml", scene_xml("<shape type=\"cube\"><transform name=\"to_world\"><translate value=\"5 6 7\"/></transform></shape>\n"));
    SceneDescription s = load_mitsuba_xml(path, {});
    vec3 origin = vec3(s.camera.to_world[3]);
    vec3 fwd = vec3(s.camera.to_world[2]);
    EXPECT_NEAR(origin.x, 5.f, 1e-4f);
    EXPECT_NEAR(origin.y, 6.f, 1e-4f);
    EXPECT_LT(origin.z, 7.f - std::sqrt(3.f));
    expect_near(fwd, vec3(0, 0, 1));
    EXPECT_FLOAT_EQ(s.camera.fov_deg, 45.f);
    EXPECT_NO_THROW(build_scene(s));
}

TEST(SceneXml, Errors) {
    expect_error("<shape type=\"rectangle\">\n<foo/></shape>\n", 3, "unknown tag <foo>");
    expect_error("\n<bar/>\n", 3, "unknown tag <bar>");
    expect_error("<shape type=\"bsplinecurve\"/>\n", 2, "unsupported shape type 'bsplinecurve'");
    expect_error("\n<bsdf type=\"blendbsdf\" id=\"c\"/>\n", 3, "blendbsdf' needs 'weight'");
    expect_error("<bsdf type=\"mask\" id=\"m\">\n<float name=\"opacity\" value=\"1.5\"/><bsdf type=\"diffuse\"/></bsdf>\n", 3,
                 "opacity must be in [0, 1]");
    expect_error("<bsdf type=\"blendbsdf\" id=\"b\"><float name=\"weight\" value=\"0.5\"/>\n<bsdf type=\"diffuse\"/></bsdf>\n", 2,
                 "blendbsdf takes exactly two nested BSDFs");
    expect_error("<bsdf type=\"normalmap\" id=\"n\">\n<bsdf type=\"diffuse\"/></bsdf>\n", 2, "needs a texture named 'normalmap'");
    expect_error("<shape type=\"rectangle\">\n<bsdf type=\"measured\"/></shape>\n", 3, "unsupported bsdf type 'measured'");
    expect_error("<shape type=\"rectangle\">\n<bsdf type=\"twosided\"/></shape>\n", 3, "needs a nested <bsdf>");
    expect_error("<integrator type=\"sppm\"/>\n", 2, "unsupported integrator type 'sppm'");
    expect_error("<emitter type=\"sunsky\"/>\n", 2, "unsupported emitter type 'sunsky'");  // constant is supported now
    expect_error("<sensor type=\"perspective\">\n<film type=\"hdrfilm\">\n<rfilter type=\"blackman\"/></film></sensor>\n", 4,
                 "unsupported rfilter type 'blackman'");
    expect_error("<sensor type=\"perspective\">\n<float name=\"fov\" value=\"abc\"/></sensor>\n", 3, "could not parse float 'abc'");
    expect_error("<sensor type=\"perspective\">\n<string name=\"fov\" value=\"40\"/></sensor>\n", 3, "must be <float>, not <string>");
    expect_error("<integrator type=\"path\">\n<float name=\"max_depth\" value=\"3\"/></integrator>\n", 3, "must be <integer>");
    expect_error("<integrator type=\"path\">\n<integer name=\"max_depth\" value=\"0\"/></integrator>\n", 3, "max_depth 0");
    expect_error("<integrator type=\"path\">\n\n<integer name=\"emitter_samples\" value=\"2\"/></integrator>\n", 4, "emitter_samples");
    expect_error("<integrator type=\"path\">\n<boolean name=\"hide_emitters\" value=\"yes\"/></integrator>\n", 3, "could not parse boolean");
    expect_error("<shape type=\"rectangle\">\n<rgb name=\"x\" value=\"1 2\"/></shape>\n", 3, "unused parameter 'x'");
    expect_error("<bsdf type=\"diffuse\" id=\"a\">\n<rgb name=\"reflectance\" value=\"1 2\"/></bsdf>\n", 3, "expected 1 or 3 numbers");
    expect_error("<shape type=\"rectangle\">\n<ref id=\"ghost\"/></shape>\n", 3, "unknown id 'ghost'");
    expect_error("<bsdf type=\"diffuse\" id=\"a\"/>\n\n<bsdf type=\"diffuse\" id=\"a\"/>\n", 4, "duplicate id 'a' (first defined at line 2)");
    expect_error("<shape type=\"rectangle\" id=\"s\"/>\n<shape type=\"rectangle\">\n<ref id=\"s\"/></shape>\n", 4, "not a <bsdf>");
    expect_error("<shape type=\"obj\">\n<string name=\"filename\" value=\"missing.obj\"/></shape>\n", 3, "cannot open OBJ file 'missing.obj'");
    expect_error("<shape type=\"obj\"/>\n", 2, "needs a 'filename'");
    expect_error("<shape type=\"rectangle\">\n<float name=\"a\" value=\"1\"/>\n<float name=\"a\" value=\"2\"/></shape>\n", 4, "given twice");
    expect_error("<shape type=\"rectangle\">\n<emitter type=\"area\">\n<rgb name=\"radiance\" value=\"1\"/><float name=\"scale\" value=\"2\"/>"
                 "</emitter></shape>\n", 4, "unused parameter 'scale' in emitter 'area'");
    expect_error("<sensor type=\"perspective\"/>\n<sensor type=\"perspective\"/>\n", 3, "more than one <sensor>");
    expect_error("<shape type=\"rectangle\" color=\"red\"/>\n", 2, "unexpected attribute 'color'");
    expect_error("<sensor type=\"perspective\">\n<sampler type=\"halton\"/></sensor>\n", 3, "unsupported sampler type");
    expect_error("<sensor type=\"perspective\">\n<sampler type=\"orthogonal\"><integer name=\"strength\" value=\"3\"/>"
                 "</sampler></sensor>\n", 3, "only strength 2 is supported");
    expect_error("<sensor type=\"perspective\">\n<sampler type=\"sobol\"><boolean name=\"jitter\" value=\"false\"/>"
                 "</sampler></sensor>\n", 3, "unused parameter 'jitter'");
    expect_error("<sensor type=\"perspective\">\n<film type=\"hdrfilm\"><integer name=\"width\" value=\"0\"/></film></sensor>\n", 3,
                 "width must be positive");
    expect_error("<sensor type=\"perspective\">\n<string name=\"fov_axis\" value=\"z\"/><float name=\"fov\" value=\"9\"/></sensor>\n", 3,
                 "unknown fov_axis 'z'");
    expect_error("<sensor type=\"perspective\"><shape type=\"cube\"/>\n</sensor>\n", 2, "unexpected <shape type=\"cube\"> in sensor");
}

TEST(SceneXml, MisspelledParameterFixture) {
    std::string path = std::string(CANDELA_TEST_DATA) + "/scenes/typo.xml";
    std::string msg = load_error(path);
    EXPECT_EQ(msg, path + ":3: unused parameter 'fvo' in sensor 'perspective'");
}

TEST(SceneXml, MalformedXmlAndRoot) {
    std::string path = write_temp("bad.xml", "<scene version=\"3.0.0\">\n<shape type=\"cube\">\n</scene>\n");
    std::string msg = load_error(path);
    EXPECT_NE(msg.find(path + ":3: malformed XML"), std::string::npos) << msg;
    std::string nover = write_temp("nover.xml", "\n<scene>\n</scene>\n");
    EXPECT_NE(load_error(nover).find(nover + ":2: <scene> needs a version"), std::string::npos) << load_error(nover);
    std::string root = write_temp("root.xml", "<mitsuba version=\"3.0.0\"/>\n");
    EXPECT_NE(load_error(root).find("root element must be <scene>"), std::string::npos);
    std::string missing = temp_dir() + "does_not_exist.xml";
    EXPECT_EQ(load_error(missing), missing + ": cannot open file");
}

TEST(SceneXml, ErrorsInsideObjNameBothFiles) {
    std::string obj = write_temp("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n");
    std::string name = obj.substr(obj.find_last_of('/') + 1);
    std::string path = write_temp("s.xml", scene_xml("\n<shape type=\"obj\"><string name=\"filename\" value=\"" + name + "\"/></shape>\n"));
    std::string msg = load_error(path);
    EXPECT_NE(msg.find(obj + ":3: vertex has a NaN or infinite coordinate"), std::string::npos) << msg;
    EXPECT_NE(msg.find(path + ":3"), std::string::npos) << msg;
}

// The issue-5 plugins map Mitsuba's parameters and defaults onto the BSDFs.
TEST(SceneXml, MaterialPluginsMapTheirParameters) {
    std::string path = write_temp("materials.xml", scene_xml(
        "<shape type=\"rectangle\"><bsdf type=\"conductor\"><rgb name=\"eta\" value=\"0.2 0.4 1.4\"/>"
        "<rgb name=\"k\" value=\"3.9 2.4 1.8\"/><rgb name=\"specular_reflectance\" value=\"0.9\"/></bsdf></shape>\n"
        "<shape type=\"rectangle\"><bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"ggx\"/>"
        "<float name=\"alpha\" value=\"0.25\"/></bsdf></shape>\n"
        "<shape type=\"rectangle\"><bsdf type=\"plastic\"><rgb name=\"diffuse_reflectance\" value=\"0.1 0.2 0.3\"/>"
        "<float name=\"int_ior\" value=\"1.6\"/><boolean name=\"nonlinear\" value=\"true\"/></bsdf></shape>\n"
        "<shape type=\"rectangle\"><bsdf type=\"roughplastic\"><string name=\"distribution\" value=\"ggx\"/></bsdf></shape>\n"
        "<shape type=\"rectangle\"><bsdf type=\"dielectric\"><string name=\"int_ior\" value=\"diamond\"/></bsdf></shape>\n"
        "<shape type=\"rectangle\"><bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"ggx\"/>"
        "<float name=\"alpha\" value=\"0.05\"/><float name=\"int_ior\" value=\"1.33\"/><float name=\"ext_ior\" value=\"1.1\"/>"
        "<rgb name=\"specular_transmittance\" value=\"0.5\"/></bsdf></shape>\n"
        "<shape type=\"rectangle\"><bsdf type=\"twosided\"><bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"ggx\"/></bsdf></bsdf></shape>\n"
        "<shape type=\"rectangle\"><bsdf type=\"conductor\"/></shape>\n"));
    SceneDescription s = load_mitsuba_xml(path, {});
    ASSERT_EQ(s.shapes.size(), 8u);
    auto bsdf = [&](int shape) -> const Bsdf& { return s.materials[s.shapes[size_t(shape)].material].bsdf; };

    const auto& c = std::get<ConductorBsdf>(bsdf(0));
    expect_near(c.eta, vec3(0.2f, 0.4f, 1.4f));
    expect_near(c.k, vec3(3.9f, 2.4f, 1.8f));
    expect_near(c.specular_reflectance, vec3(0.9f));
    EXPECT_EQ(c.alpha_u, 0.f);  // conductor: the ideal mirror
    EXPECT_FLOAT_EQ(std::get<ConductorBsdf>(bsdf(1)).alpha_u, 0.25f);

    const auto& p = std::get<PlasticBsdf>(bsdf(2));
    expect_near(p.diffuse_reflectance, vec3(0.1f, 0.2f, 0.3f));
    EXPECT_FLOAT_EQ(p.int_ior, 1.6f);
    EXPECT_FLOAT_EQ(p.ext_ior, 1.000277f);
    EXPECT_TRUE(p.nonlinear);
    EXPECT_EQ(p.alpha, 0.f);
    const auto& rp = std::get<PlasticBsdf>(bsdf(3));  // Mitsuba's defaults
    EXPECT_FLOAT_EQ(rp.alpha, 0.1f);
    EXPECT_FLOAT_EQ(rp.int_ior, 1.49f);
    expect_near(rp.diffuse_reflectance, vec3(0.5f));
    EXPECT_FALSE(rp.nonlinear);

    const auto& d = std::get<DielectricBsdf>(bsdf(4));
    EXPECT_NEAR(d.int_ior, 2.419f, 1e-3f);  // Mitsuba's "diamond"
    EXPECT_FLOAT_EQ(d.ext_ior, 1.000277f);
    EXPECT_EQ(d.alpha_u, 0.f);
    const auto& rd = std::get<DielectricBsdf>(bsdf(5));
    EXPECT_FLOAT_EQ(rd.alpha_u, 0.05f);
    EXPECT_FLOAT_EQ(rd.eta(), 1.33f / 1.1f);
    expect_near(rd.specular_transmittance, vec3(0.5f));
    expect_near(rd.specular_reflectance, vec3(1.f));

    EXPECT_TRUE(s.materials[s.shapes[6].material].two_sided);
    EXPECT_FLOAT_EQ(std::get<ConductorBsdf>(bsdf(6)).alpha_u, 0.1f);
    for (int i = 0; i < 6; ++i) EXPECT_FALSE(s.materials[s.shapes[size_t(i)].material].two_sided) << i;
    const auto& c0 = std::get<ConductorBsdf>(bsdf(7));  // defaults: eta 0, k 1
    expect_near(c0.eta, vec3(0.f));
    expect_near(c0.k, vec3(1.f));
}

// Every scene the project ships loads, builds and names its materials' types as written.
TEST(SceneXml, EveryShippedSceneLoads) {
    const char* files[] = {"scenes/cornell-box/scene.xml", "scenes/veach-mis/scene.xml",
                           "scenes/cornell-materials/mirror-glass.xml", "scenes/cornell-materials/rough.xml",
                           "scenes/cornell-materials/glossy-glass.xml", "scenes/caustics/scene.xml",
                           "scenes/lamp/scene.xml", "scenes/door-ajar/scene.xml"};
    for (const char* f : files) {
        SceneDescription s = load_mitsuba_xml(std::string(CANDELA_SOURCE_DIR) + "/" + f, {{"res", "16"}, {"width", "16"}, {"height", "16"}});
        EXPECT_NO_THROW(build_scene(s)) << f;
        EXPECT_GT(s.mesh.triangles.size(), 0u) << f;
        EXPECT_FALSE(s.emitters.empty()) << f;
        std::printf("  %s: %zu triangles, %zu materials, %zu emitters\n", f, s.mesh.triangles.size(), s.materials.size(),
                    s.emitters.size());
    }
    // The caustics scene: a glass sphere (IOR 1.5) and a diamond (2.42), rough plates in Veach's.
    SceneDescription c = load_mitsuba_xml(std::string(CANDELA_SOURCE_DIR) + "/scenes/caustics/scene.xml", {});
    std::vector<float> iors;
    for (const Material& m : c.materials)
        if (auto* d = std::get_if<DielectricBsdf>(&m.bsdf)) iors.push_back(d->eta());
    std::sort(iors.begin(), iors.end());
    ASSERT_EQ(iors.size(), 2u);
    EXPECT_NEAR(iors[0], 1.5f, 0.01f);
    EXPECT_NEAR(iors[1], 2.42f, 0.01f);
    SceneDescription v = load_mitsuba_xml(std::string(CANDELA_SOURCE_DIR) + "/scenes/veach-mis/scene.xml", {});
    std::vector<float> alphas;
    for (const Material& m : v.materials)
        if (auto* k = std::get_if<ConductorBsdf>(&m.bsdf)) alphas.push_back(k->alpha_u);
    std::sort(alphas.begin(), alphas.end());
    ASSERT_EQ(alphas.size(), 4u);
    EXPECT_FLOAT_EQ(alphas[0], 0.01f);
    EXPECT_FLOAT_EQ(alphas[3], 0.2f);
}

// The benchmarks' mesh scene (bench/RESULTS.md): the XML box with the bunny of assets/meshes in
// place of its blocks, found by the scene's own relative path.
TEST(SceneXml, BenchMeshSceneLoads) {
    SceneDescription s = load_mitsuba_xml(std::string(CANDELA_SOURCE_DIR) + "/bench/scenes/cornell-bunny.xml",
                                          {{"res", "16"}});
    EXPECT_NO_THROW(build_scene(s));
    EXPECT_EQ(s.mesh.triangles.size(), 69463u);  // the bunny's 69,451, the walls' 10 and the light's 2
    EXPECT_EQ(s.emitters.size(), 1u);
}

// A film without <rfilter> is filtered with Mitsuba 3's default gaussian, silently as in Mitsuba;
// an explicit box keeps the box (tests/test_filters.cpp covers the filters themselves).
TEST(SceneXml, FilmWithoutRfilterIsGaussian) {
    const std::string sensor_open = "<sensor type=\"perspective\">\n", sensor_close = "</sensor>\n";
    const std::string path = write_temp("nofilter.xml", scene_xml(sensor_open + "<film type=\"hdrfilm\"/>\n" + sensor_close));
    SceneDescription s = load_mitsuba_xml(path, {});
    EXPECT_TRUE(s.warnings.empty());
    EXPECT_EQ(s.settings.filter, gaussian_filter());
    const std::string boxed = write_temp(
        "box.xml", scene_xml(sensor_open + "<film type=\"hdrfilm\">\n<rfilter type=\"box\"/>\n</film>\n" + sensor_close));
    SceneDescription b = load_mitsuba_xml(boxed, {});
    EXPECT_TRUE(b.warnings.empty());
    EXPECT_EQ(b.settings.filter, box_filter());
}
