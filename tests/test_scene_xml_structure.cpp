// The scene file's structure (src/scene/xml/parser.cpp): <include>, <path>, <default> in included
// files, $name, forward refs and <alias>, version upgrades, <spectrum> against Mitsuba 3.9.1, every
// <transform> operation against Mitsuba's matrices, and the errors for each.
#include <gtest/gtest.h>
#include <filesystem>
#include <fstream>
#include <string>
#include "core/error.h"
#include "scene/loaders.h"
#include "scene/xml/spectrum.h"

using namespace candela;
namespace fs = std::filesystem;

namespace {

// A fresh folder per test: <TempDir>/candela_xmls_<test>/.
std::string test_dir() {
    std::string d = ::testing::TempDir();
    if (!d.empty() && d.back() != '/') d += '/';
    d += std::string("candela_xmls_") + ::testing::UnitTest::GetInstance()->current_test_info()->name() + "/";
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

void write(const std::string& path, const std::string& text) {
    fs::create_directories(fs::path(path).parent_path());
    std::ofstream(path) << text;
}

std::string scene(const std::string& body, const std::string& version = "3.0.0") {
    return "<scene version=\"" + version + "\">\n" + body + "</scene>\n";
}

std::string load_error(const std::string& path, const Defines& defines = {}) {
    try {
        load_mitsuba_xml(path, defines);
    } catch (const Error& e) {
        return e.what();
    }
    return "<no error>";
}

void expect_error(const std::string& path, const std::string& where, const std::string& what) {
    std::string msg = load_error(path);
    EXPECT_EQ(msg.rfind(where, 0), 0u) << "message: " << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << "message: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
}

vec3 reflectance(const SceneDescription& s, uint32_t shape) {
    return std::get<DiffuseBsdf>(s.materials[s.shapes[shape].material].bsdf).albedo;
}

void expect_rgb(vec3 got, vec3 want, float tol) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], tol) << "component " << c;
}

const char* kRect = "<shape type=\"rectangle\"/>\n";

}  // namespace

TEST(SceneXmlStructure, IncludeRelativeToIncludingFileWithDefaultsAndVariables) {
    std::string d = test_dir();
    // main -> parts/a.xml -> parts/deeper/b.xml (each relative to the file that includes it).
    write(d + "parts/deeper/b.xml", scene("<default name=\"r\" value=\"0.7\"/>\n"
                                          "<bsdf type=\"diffuse\" id=\"$name\"><rgb name=\"reflectance\" value=\"$r\"/></bsdf>\n"));
    write(d + "parts/a.xml", scene("<include filename=\"deeper/b.xml\"/>\n<shape type=\"rectangle\"><ref id=\"m\"/></shape>\n"));
    write(d + "main.xml", scene("<default name=\"name\" value=\"m\"/>\n<include filename=\"parts/a.xml\"/>\n"));
    SceneDescription s = load_mitsuba_xml(d + "main.xml", {});
    ASSERT_EQ(s.shapes.size(), 1u);
    expect_rgb(reflectance(s, 0), vec3(0.7f), 0.f);
    // -D wins over the included file's <default>.
    SceneDescription o = load_mitsuba_xml(d + "main.xml", {{"r", "0.25"}});
    expect_rgb(reflectance(o, 0), vec3(0.25f), 0.f);
}

TEST(SceneXmlStructure, IncludeInsideAnObjectAndSingleObjectFiles) {
    std::string d = test_dir();
    // An included <scene>'s children join the element holding the <include> (Mitsuba splices them).
    write(d + "mat.xml", scene("<rgb name=\"reflectance\" value=\"0.1 0.2 0.3\"/>\n"));
    // A file whose root is one object contributes that object.
    write(d + "shape.xml", "<shape version=\"3.0.0\" type=\"rectangle\"><bsdf type=\"diffuse\"><include filename=\"mat.xml\"/></bsdf></shape>\n");
    write(d + "main.xml", scene("<include filename=\"shape.xml\"/>\n<include filename=\"shape.xml\"/>\n"));
    SceneDescription s = load_mitsuba_xml(d + "main.xml", {});
    ASSERT_EQ(s.shapes.size(), 2u);
    expect_rgb(reflectance(s, 1), vec3(0.1f, 0.2f, 0.3f), 0.f);
}

TEST(SceneXmlStructure, PathFoldersForIncludesAndMeshes) {
    std::string d = test_dir();
    write(d + "lib/old/m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    write(d + "lib/new/m.obj", "v 0 0 0\nv 2 0 0\nv 0 2 0\nv 2 2 0\nf 1 2 3\nf 2 4 3\n");
    write(d + "lib/inc/shape.xml", scene("<shape type=\"obj\"><string name=\"filename\" value=\"m.obj\"/></shape>\n"));
    // The later <path> is searched first (Mitsuba prepends it); relative to the file it is in.
    write(d + "scenes/main.xml", scene("<path value=\"../lib/old\"/>\n<path value=\"../lib/new\"/>\n<path value=\"../lib/inc\"/>\n"
                                       "<include filename=\"shape.xml\"/>\n"));
    SceneDescription s = load_mitsuba_xml(d + "scenes/main.xml", {});
    ASSERT_EQ(s.shapes.size(), 1u);
    EXPECT_EQ(s.mesh.triangles.size(), 2u);  // lib/new/m.obj
    // Without the paths neither file is found.
    write(d + "scenes/nopath.xml", scene("<shape type=\"obj\">\n<string name=\"filename\" value=\"m.obj\"/></shape>\n"));
    expect_error(d + "scenes/nopath.xml", d + "scenes/nopath.xml:3: ", "cannot open OBJ file 'm.obj'");
    // A <path> naming no folder is only a place with nothing to find: a note, and the file loads
    // (issue 43: Mitsuba 3 also searches its working directory, where the author had the folder).
    write(d + "scenes/badpath.xml", scene("\n<path value=\"nowhere\"/>\n<shape type=\"rectangle\"/>\n"));
    SceneDescription b = load_mitsuba_xml(d + "scenes/badpath.xml", {});
    EXPECT_EQ(b.shapes.size(), 1u);
    ASSERT_EQ(b.warnings.size(), 1u);
    EXPECT_EQ(b.warnings[0].rfind(d + "scenes/badpath.xml:3: ", 0), 0u) << b.warnings[0];
    EXPECT_NE(b.warnings[0].find("folder 'nowhere' not found"), std::string::npos) << b.warnings[0];
}

TEST(SceneXmlStructure, ForwardRefsAcrossIncludesAnyNameAndAlias) {
    std::string d = test_dir();
    write(d + "mats.xml", scene("<bsdf type=\"diffuse\" id=\"late\"><float name=\"reflectance\" value=\"0.3\"/></bsdf>\n"));
    write(d + "main.xml", scene(
        "<shape type=\"rectangle\"><ref name=\"anything\" id=\"late\"/></shape>\n"    // defined in a later include
        "<shape type=\"rectangle\"><ref id=\"inner\"/></shape>\n"                      // nested in a later shape
        "<shape type=\"rectangle\"><ref id=\"other\"/></shape>\n"                      // through an alias
        "<include filename=\"mats.xml\"/>\n"
        "<shape type=\"cube\"><bsdf type=\"diffuse\" id=\"inner\"><float name=\"reflectance\" value=\"0.6\"/></bsdf></shape>\n"
        "<alias id=\"late\" as=\"other\"/>\n"));
    SceneDescription s = load_mitsuba_xml(d + "main.xml", {});
    ASSERT_EQ(s.shapes.size(), 4u);
    expect_rgb(reflectance(s, 0), vec3(0.3f), 0.f);
    expect_rgb(reflectance(s, 1), vec3(0.6f), 0.f);
    expect_rgb(reflectance(s, 2), vec3(0.3f), 0.f);
    EXPECT_EQ(s.shapes[0].material, s.shapes[2].material);  // one object, built once
    EXPECT_EQ(s.shapes[1].material, s.shapes[3].material);
    EXPECT_EQ(s.materials.size(), 2u);
}

TEST(SceneXmlStructure, IncludeAndRefErrorsNameFileAndLine) {
    std::string d = test_dir();
    write(d + "missing.xml", scene("\n<include filename=\"nope.xml\"/>\n"));
    expect_error(d + "missing.xml", d + "missing.xml:3: ", "included file 'nope.xml' not found");
    write(d + "a.xml", scene("<include filename=\"b.xml\"/>\n"));
    write(d + "b.xml", scene("\n\n<include filename=\"a.xml\"/>\n"));
    expect_error(d + "a.xml", d + "b.xml:4: ", "include cycle");
    write(d + "self.xml", scene("<include filename=\"self.xml\"/>\n"));
    expect_error(d + "self.xml", d + "self.xml:2: ", "include cycle");
    write(d + "broken.xml", "<scene version=\"3.0.0\">\n<shape type=\"cube\">\n</scene>\n");
    write(d + "inc_broken.xml", scene("<include filename=\"broken.xml\"/>\n"));
    expect_error(d + "inc_broken.xml", d + "broken.xml:3: ", "malformed XML");
    write(d + "inc_dir.xml", scene("<include filename=\"/\"/>\n"));
    expect_error(d + "inc_dir.xml", d + "inc_dir.xml:2: ", "not a regular file");
    write(d + "inc_dev.xml", scene("<include filename=\"/dev/zero\"/>\n"));
    expect_error(d + "inc_dev.xml", d + "inc_dev.xml:2: ", "not a regular file");
    write(d + "unknown.xml", scene(std::string(kRect) + "<shape type=\"cube\">\n<ref id=\"ghost\"/></shape>\n"));
    expect_error(d + "unknown.xml", d + "unknown.xml:4: ", "reference to unknown id 'ghost'");
    write(d + "kinds.xml", scene("<shape type=\"cube\" id=\"box\"/>\n<bsdf type=\"twosided\">\n<ref id=\"box\"/></bsdf>\n"));
    expect_error(d + "kinds.xml", d + "kinds.xml:4: ", "id 'box' is a <shape> (line 2), not a <bsdf>");
    write(d + "other.xml", scene("<shape type=\"cube\" id=\"box\"/>\n"));
    write(d + "kinds2.xml", scene("<include filename=\"other.xml\"/>\n<shape type=\"cube\">\n<ref id=\"box\"/></shape>\n"));
    expect_error(d + "kinds2.xml", d + "kinds2.xml:4: ", "id 'box' is a <shape> (" + d + "other.xml:line 2)");
    write(d + "dup.xml", scene("<include filename=\"other.xml\"/>\n<bsdf type=\"diffuse\" id=\"box\"/>\n"));
    expect_error(d + "dup.xml", d + "dup.xml:3: ", "duplicate id 'box'");
    write(d + "deflevel.xml", scene("<shape type=\"cube\">\n<path value=\".\"/></shape>\n"));
    expect_error(d + "deflevel.xml", d + "deflevel.xml:3: ", "only allowed directly inside <scene>");
    write(d + "under.xml", scene("<bsdf type=\"diffuse\" id=\"_x\"/>\n"));
    expect_error(d + "under.xml", d + "under.xml:2: ", "leading underscore");
}

TEST(SceneXmlStructure, SubstitutionFollowsMitsubasRules) {
    std::string d = test_dir();
    // The longest name is replaced first: $ab is "0.5", not "$a" followed by "b".
    write(d + "s.xml", scene("<default name=\"a\" value=\"0.1\"/>\n<default name=\"ab\" value=\"0.5\"/>\n"
                             "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"$ab, $a, $a\"/></bsdf></shape>\n"));
    SceneDescription s = load_mitsuba_xml(d + "s.xml", {});
    expect_rgb(reflectance(s, 0), vec3(0.5f, 0.1f, 0.1f), 1e-7f);
}

TEST(SceneXmlStructure, VersionsAndTheUpgradeOfOldScenes) {
    std::string d = test_dir();
    write(d + "v2.xml", scene(kRect, "2.1.0"));
    EXPECT_EQ(load_mitsuba_xml(d + "v2.xml", {}).shapes.size(), 1u);
    // Mitsuba 0.x: camelCase names, <lookAt>, a diffuse's diffuseReflectance (Mitsuba 3's upgrade_tree).
    write(d + "old.xml", scene("<sensor type=\"perspective\"><float name=\"nearClip\" value=\"0.5\"/><float name=\"fov\" value=\"40\"/>"
                               "<string name=\"fovAxis\" value=\"y\"/>"
                               "<transform name=\"toWorld\"><lookAt origin=\"0 0 5\" target=\"0 0 0\" up=\"0 1 0\"/></transform>"
                               "<sampler type=\"independent\"><integer name=\"sampleCount\" value=\"9\"/></sampler></sensor>\n"
                               "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><rgb name=\"diffuseReflectance\" value=\"0.2\"/></bsdf></shape>\n",
                               "0.6.0"));
    SceneDescription s = load_mitsuba_xml(d + "old.xml", {});
    EXPECT_FLOAT_EQ(s.camera.near_clip, 0.5f);
    EXPECT_EQ(s.camera.fov_axis, FovAxis::Y);
    EXPECT_EQ(s.settings.spp, 9);
    EXPECT_FLOAT_EQ(s.camera.to_world[3][2], 5.f);
    expect_rgb(reflectance(s, 0), vec3(0.2f), 0.f);
    // What the rules do not cover is an ordinary error that says the file was upgraded.
    write(d + "old_bad.xml", scene("<integrator type=\"path\">\n\n<integer name=\"strictNormals\" value=\"1\"/></integrator>\n", "0.5.0"));
    expect_error(d + "old_bad.xml", d + "old_bad.xml:4: ", "unused parameter 'strict_normals'");
    EXPECT_NE(load_error(d + "old_bad.xml").find("is version 0.5.0, read with Mitsuba 3's upgrade rules"), std::string::npos);
    write(d + "v4.xml", scene(kRect, "4.0.0"));
    expect_error(d + "v4.xml", d + "v4.xml:1: ", "unsupported scene version '4.0.0'");
    write(d + "vbad.xml", scene(kRect, "3.0"));
    expect_error(d + "vbad.xml", d + "vbad.xml:1: ", "could not parse version '3.0'");
}

// Expected values: Mitsuba 3.9.1 scalar_rgb, the converted texture read back with mi.traverse
// (tests/data/spectra_reference.py prints them).
TEST(SceneXmlStructure, SpectraMatchMitsuba) {
    struct Case {
        const char* where;  // "bsdf", "emitter" or "eta"
        const char* value;
        vec3 want;
    };
    const Case cases[] = {
        {"bsdf", "400:0.1, 500:0.5, 600:0.8, 700:0.3", vec3(0.7521866f, 0.6452694f, 0.2717064f)},
        {"bsdf", "360:0.5, 830:0.5", vec3(0.4994926f, 0.4994369f, 0.4994008f)},
        {"bsdf", "540:0, 550:1, 560:0", vec3(0.f, 0.140577f, 0.f)},  // out of gamut: clamped
        {"bsdf", "300:0.2 900:0.9", vec3(0.5988878f, 0.4829548f, 0.3638638f)},
        {"bsdf", "0.25", vec3(0.25f)},
        {"emitter", "400:1, 700:2", vec3(2.14f, 1.404241f, 1.01714f)},
        {"emitter", "500:0, 550:10, 600:0", vec3(0.4403634f, 5.825714f, 0.f)},
        {"emitter", "3", vec3(3.614382f, 2.844873f, 2.726748f)},
        {"eta", "400:1.5, 550:0.9, 700:0.2", vec3(0.4732967f, 0.9254529f, 1.330516f)},
    };
    std::string d = test_dir();
    int k = 0;
    for (const Case& c : cases) {
        std::string w = c.where, body;
        if (w == "bsdf")
            body = "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"" + std::string(c.value) + "\"/></bsdf></shape>\n";
        else if (w == "eta")
            body = "<shape type=\"rectangle\"><bsdf type=\"conductor\"><spectrum name=\"eta\" value=\"" + std::string(c.value) + "\"/></bsdf></shape>\n";
        else
            body = "<shape type=\"rectangle\"><emitter type=\"area\"><spectrum name=\"radiance\" value=\"" + std::string(c.value) + "\"/></emitter></shape>\n";
        std::string path = d + "s" + std::to_string(k++) + ".xml";
        write(path, scene(body));
        SceneDescription s = load_mitsuba_xml(path, {});
        SCOPED_TRACE(std::string(c.where) + " " + c.value);
        vec3 got = w == "bsdf"  ? reflectance(s, 0)
                   : w == "eta" ? std::get<ConductorBsdf>(s.materials[0].bsdf).eta
                                : s.emitters.at(0).radiance;
        expect_rgb(got, c.want, 2e-6f * std::max(1.f, c.want.y));
    }
    // The same list from a file (one "wavelength value" per line, '#' comments).
    write(d + "r.spd", "# wavelength value\n400 0.1\n500 0.5\n600 0.8\n700 0.3\n");
    write(d + "f.xml", scene("<shape type=\"rectangle\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" filename=\"r.spd\"/></bsdf></shape>\n"));
    expect_rgb(reflectance(load_mitsuba_xml(d + "f.xml", {}), 0), cases[0].want, 2e-6f);
    // A control: the same list read as an emitter (no D65) differs clearly.
    EXPECT_GT(std::abs(xml::spectrum_list_to_srgb({400, 500, 600, 700}, {0.1, 0.5, 0.8, 0.3}, true, false).x - cases[0].want.x), 0.05f);
}

TEST(SceneXmlStructure, SpectrumErrors) {
    std::string d = test_dir();
    auto check = [&](const std::string& value, const std::string& what) {
        write(d + "e.xml", scene("<shape type=\"rectangle\"><bsdf type=\"diffuse\">\n<spectrum name=\"reflectance\" " + value +
                                 "/></bsdf></shape>\n"));
        expect_error(d + "e.xml", d + "e.xml:3: ", what);
    };
    check("value=\"500:0.5\"", "at least two");
    check("value=\"600:0.5, 500:0.2\"", "must increase");
    check("value=\"500:x, 600:1\"", "could not parse wavelength:value pair '500:x'");
    check("value=\"500-0.5 600:1\"", "expected wavelength:value pairs");
    check("value=\"nan\"", "could not parse constant spectrum");
    check("value=\"1\" filename=\"x.spd\"", "one of 'value' or 'filename'");
    check("filename=\"none.spd\"", "cannot open spectrum file 'none.spd'");
    write(d + "bad.spd", "400 0.1\n500 zz\n");
    write(d + "f.xml", scene("<shape type=\"rectangle\"><bsdf type=\"diffuse\">\n<spectrum name=\"reflectance\" filename=\"bad.spd\"/></bsdf></shape>\n"));
    expect_error(d + "f.xml", d + "bad.spd:2: ", "(spectrum at " + d + "f.xml:3)");
    // A spectrum where a float is wanted is a type error, as in Mitsuba.
    write(d + "t.xml", scene("<sensor type=\"perspective\">\n<spectrum name=\"fov\" value=\"30\"/></sensor>\n"));
    expect_error(d + "t.xml", d + "t.xml:3: ", "must be <float>, not <spectrum>");
}

// Expected matrices: Mitsuba 3.9.1's to_world of a rectangle with the same <transform>.
TEST(SceneXmlStructure, TransformOperationsMatchMitsuba) {
    std::string d = test_dir();
    write(d + "id.xml", scene("<shape type=\"cube\"/>\n"));
    const std::vector<vec3> local = load_mitsuba_xml(d + "id.xml", {}).mesh.positions;
    auto check = [&](const std::string& ops, const float (&rows)[12]) {
        write(d + "t.xml", scene("<shape type=\"cube\"><transform name=\"to_world\">" + ops + "</transform></shape>\n"));
        std::vector<vec3> got = load_mitsuba_xml(d + "t.xml", {}).mesh.positions;
        ASSERT_EQ(got.size(), local.size());
        SCOPED_TRACE(ops);
        for (size_t i = 0; i < local.size(); ++i) {
            vec3 p = local[i];
            for (int r = 0; r < 3; ++r)
                EXPECT_NEAR(got[i][r], rows[4 * r] * p.x + rows[4 * r + 1] * p.y + rows[4 * r + 2] * p.z + rows[4 * r + 3], 2e-6f);
        }
    };
    // lookat without up: Mitsuba takes coordinate_system(forward)'s first tangent.
    check("<lookat origin=\"1 2 3\" target=\"4 -1 5\"/>",
          {-0.2867993f, 0.7132007f, 0.6396021f, 1.f, -0.7132007f, 0.2867993f, -0.6396021f, 2.f, -0.6396021f, -0.6396021f, 0.4264014f, 3.f});
    check("<lookat origin=\"0 0 0\" target=\"0 0 -2\"/>", {0.f, 1.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 0.f, 0.f, -1.f, 0.f});
    // One value for all three components of a translate, each operation after the previous ones.
    check("<translate value=\"2\"/><rotate x=\"0.6\" y=\"0.8\" angle=\"30\"/><scale x=\"2\"/>",
          {1.828513f, 0.1286156f, 0.8f, 5.514256f, 0.06430781f, 0.9517692f, -0.3f, 1.432154f, -0.4f, 0.3f, 0.8660254f, 1.532051f});
    check("<matrix value=\"0 -1 0 1 0 0 0 0 1\"/><translate y=\"3\"/>", {0.f, -1.f, 0.f, 0.f, 1.f, 0.f, 0.f, 3.f, 0.f, 0.f, 1.f, 0.f});
}

// Spectral integration: a flat reflectance of 1 is white to the table's rounding, a flat emitter
// is xyz_to_srgb(1, 1, 1), and the matching functions interpolate the published samples.
TEST(SceneXmlStructure, SpectrumIntegrationIdentities) {
    vec3 white = xml::spectrum_list_to_srgb({360, 830}, {1, 1}, false, true);
    expect_rgb(white, vec3(0.998983f, 0.998872f, 0.998802f), 1e-5f);  // Mitsuba sums in float
    vec3 flat = xml::spectrum_list_to_srgb({360, 830}, {1, 1}, false, false);
    expect_rgb(flat, vec3(1.20488f, 0.948229f, 0.909267f), 1e-5f);
    expect_rgb(xml::cie1931_xyz(362.5), vec3(0.000181f, 5.441e-06f, 0.00084605f), 1e-9f);
    EXPECT_EQ(xml::cie1931_xyz(831.0), vec3(0.f));
    EXPECT_NEAR(xml::cie_d65(560.0), 1.0101273, 1e-6);
}

// A shape may <ref> a top-level area emitter by id, as Mitsuba's own scenes do (the cbox
// "fragments" scene): the shape emits, and its default bsdf is the black one of an emitter.
TEST(SceneXmlStructure, ShapesReferenceAreaEmittersById) {
    const std::string d = test_dir();
    write(d + "ok.xml", scene("<shape type=\"rectangle\"><ref id=\"lamp\"/></shape>\n"
                              "<emitter type=\"area\" id=\"lamp\"><rgb name=\"radiance\" value=\"2, 3, 4\"/></emitter>\n"
                              "<shape type=\"rectangle\"><ref id=\"white\"/><ref name=\"emitter\" id=\"lamp\"/></shape>\n"
                              "<bsdf type=\"diffuse\" id=\"white\"/>\n"));
    SceneDescription s = load_mitsuba_xml(d + "ok.xml", {});
    ASSERT_EQ(s.shapes.size(), 2u);
    ASSERT_EQ(s.emitters.size(), 2u);
    for (const Shape& sh : s.shapes) {
        ASSERT_GE(sh.emitter, 0);
        EXPECT_EQ(s.emitters[size_t(sh.emitter)].radiance, vec3(2.f, 3.f, 4.f));
    }
    expect_rgb(reflectance(s, 0), vec3(0.f), 0.f);    // emits, no bsdf: black
    expect_rgb(reflectance(s, 1), vec3(0.5f), 0.f);   // its own bsdf
    write(d + "bare.xml", scene("<emitter type=\"area\"/>\n"));
    expect_error(d + "bare.xml", d + "bare.xml:2: ", "must be nested inside a <shape> or referenced by one");
    write(d + "two.xml", scene("<emitter type=\"area\" id=\"lamp\"/>\n"
                               "<shape type=\"rectangle\"><emitter type=\"area\"/><ref id=\"lamp\"/></shape>\n"));
    expect_error(d + "two.xml", d + "two.xml:3: ", "a shape takes one emitter");
}
