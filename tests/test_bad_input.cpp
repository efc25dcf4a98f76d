// Bad input end to end through the program: each row of the table in docs/reliability.md that is
// not already covered by test_cli.cpp, test_scene_xml.cpp or test_obj_loader.cpp. Every case must
// give one line naming the file (and the line where there is one) and exit 1, never a crash.
#include <gtest/gtest.h>
#include <unistd.h>
#include "support/run.h"

using namespace candela::test;

namespace {

// Exactly one line of output containing every needle, and exit code `code` (not a signal).
void expect_clean_error(const RunResult& r, std::initializer_list<std::string> needles, int code = 1) {
    EXPECT_EQ(r.exit_code, code) << r.output;
    for (const std::string& n : needles)
        EXPECT_NE(r.output.find(n), std::string::npos) << "expected '" << n << "' in: " << r.output;
    size_t lines = 0;
    for (char c : r.output) lines += c == '\n';
    EXPECT_EQ(lines, 1u) << r.output;
}

// Renders `scene` (a path) headless, tiny, and returns the result.
RunResult render(const std::string& scene, const std::string& dir, const std::string& extra = "") {
    return run_candela(scene + " --width 8 --height 8 --frames 1 --quiet --out " + dir + "/out.exr " + extra);
}

std::string xml(const std::string& body) { return "<scene version=\"3.0.0\">\n" + body + "</scene>\n"; }

const char* kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

}  // namespace

TEST(BadInput, MissingFiles) {
    std::string d = temp_dir("bad-missing");
    expect_clean_error(render(d + "/nope.obj", d), {d + "/nope.obj: cannot open file"});
    write_text(d + "/s.xml", xml("<shape type=\"obj\">\n<string name=\"filename\" value=\"gone.obj\"/></shape>\n"));
    expect_clean_error(render(d + "/s.xml", d), {d + "/s.xml:3: ", "cannot open OBJ file 'gone.obj'"});
    EXPECT_FALSE(access((d + "/out.exr").c_str(), F_OK) == 0);  // no image from a failed load
}

TEST(BadInput, UnreadableFiles) {
    std::string d = temp_dir("bad-unreadable");
    // A directory where a file is expected: unreadable for every user, root included.
    ASSERT_EQ(system(("mkdir -p '" + d + "/dir.xml' '" + d + "/dir.obj'").c_str()), 0);
    expect_clean_error(render(d + "/dir.xml", d), {d + "/dir.xml: is a directory"});
    expect_clean_error(render(d + "/dir.obj", d), {d + "/dir.obj: is a directory"});
    // The same for an XML obj shape, which reads the OBJ itself.
    write_text(d + "/s.xml", xml("<shape type=\"obj\">\n<string name=\"filename\" value=\"dir.obj\"/></shape>\n"));
    expect_clean_error(render(d + "/s.xml", d), {d + "/dir.obj: is a directory", d + "/s.xml:2"});
    if (geteuid() != 0) {  // permissions do not stop root
        write_text(d + "/locked.xml", xml("<shape type=\"cube\"/>\n"));
        ASSERT_EQ(chmod((d + "/locked.xml").c_str(), 0), 0);
        expect_clean_error(render(d + "/locked.xml", d), {d + "/locked.xml"});
    }
}

TEST(BadInput, EmptyFiles) {
    std::string d = temp_dir("bad-empty");
    write_text(d + "/e.xml", "");
    write_text(d + "/e.obj", "");
    write_text(d + "/ws.xml", "  \n\n");
    expect_clean_error(render(d + "/e.xml", d), {d + "/e.xml"});
    expect_clean_error(render(d + "/ws.xml", d), {d + "/ws.xml"});
    expect_clean_error(render(d + "/e.obj", d), {d + "/e.obj: empty OBJ file"});
}

TEST(BadInput, BinaryGarbage) {
    std::string d = temp_dir("bad-binary");
    std::string junk;
    for (int i = 0; i < 4096; ++i) junk += char((i * 2654435761u) >> 13);
    write_text(d + "/g.xml", junk);
    write_text(d + "/g.obj", junk);
    expect_clean_error(render(d + "/g.xml", d), {d + "/g.xml"});
    expect_clean_error(render(d + "/g.obj", d), {d + "/g.obj:1: binary data"});
    // A valid start, then garbage: the error names the first bad line.
    write_text(d + "/tail.obj", std::string(kTriangle) + std::string("\x89PNG\r\n\x1a\n\0\0", 10));
    expect_clean_error(render(d + "/tail.obj", d), {d + "/tail.obj:5: "});
    write_text(d + "/tail.xml", xml("<shape type=\"cube\"/>\n").substr(0, 30) + std::string("\0\x01\x02\xff", 4));
    expect_clean_error(render(d + "/tail.xml", d), {d + "/tail.xml:"});
}

TEST(BadInput, TruncatedFilesAtEveryByte) {
    // A file cut anywhere either still loads (a shorter valid file) or fails with one line; each
    // cut is a separate run of the program, so the loaders see exactly what a user would give.
    std::string d = temp_dir("bad-truncated");
    const std::string obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n";
    for (size_t n : {size_t(3), size_t(20), obj.size() - 12, obj.size() - 5, obj.size() - 2}) {
        std::string path = d + "/cut" + std::to_string(n) + ".obj";
        write_text(path, obj.substr(0, n));
        RunResult r = render(path, d);
        if (r.exit_code != 0) expect_clean_error(r, {path});
    }
    write_text(d + "/face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2");  // cut in the last face
    expect_clean_error(render(d + "/face.obj", d), {d + "/face.obj:4: a face needs at least 3 vertices"});
    write_text(d + "/num.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1.5e");  // cut in a number
    expect_clean_error(render(d + "/num.obj", d), {d + "/num.obj:5: could not parse number '1.5e'"});

    const std::string scene = xml("<shape type=\"rectangle\">\n<bsdf type=\"diffuse\"/>\n</shape>\n");
    for (size_t n = 1; n < scene.size(); n += 7) {
        std::string path = d + "/cut" + std::to_string(n) + ".xml";
        write_text(path, scene.substr(0, n));
        expect_clean_error(render(path, d), {path});
    }
}

TEST(BadInput, IndicesOutOfRange) {
    std::string d = temp_dir("bad-index");
    write_text(d + "/i.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    expect_clean_error(render(d + "/i.obj", d), {d + "/i.obj:4: vertex index 4 out of range (3 defined so far)"});
    write_text(d + "/huge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999999\n");
    expect_clean_error(render(d + "/huge.obj", d), {d + "/huge.obj:4: ", "out of range"});
    write_text(d + "/neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -9223372036854775808\n");
    expect_clean_error(render(d + "/neg.obj", d), {d + "/neg.obj:4: ", "out of range"});
    // The same through an XML obj shape: both files are named.
    write_text(d + "/s.xml", xml("\n<shape type=\"obj\"><string name=\"filename\" value=\"i.obj\"/></shape>\n"));
    expect_clean_error(render(d + "/s.xml", d), {d + "/i.obj:4: vertex index 4", d + "/s.xml:3"});
}

TEST(BadInput, NanAndInfCoordinates) {
    std::string d = temp_dir("bad-nan");
    write_text(d + "/n.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    expect_clean_error(render(d + "/n.obj", d), {d + "/n.obj:2: vertex has a NaN or infinite coordinate"});
    write_text(d + "/i.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt inf 0\nf 1/1 2/1 3/1\n");
    expect_clean_error(render(d + "/i.obj", d), {d + "/i.obj:4: texture coordinate has a NaN or infinite"});
    // Finite numbers whose transform overflows, and NaN in transforms and parameters.
    write_text(d + "/t.xml", xml("<shape type=\"rectangle\">\n<transform name=\"to_world\">\n"
                                 "<translate value=\"nan 0 0\"/></transform></shape>\n"));
    expect_clean_error(render(d + "/t.xml", d), {d + "/t.xml:"});
    write_text(d + "/s.xml", xml("<shape type=\"rectangle\">\n<transform name=\"to_world\">\n"
                                 "<scale value=\"1e30\"/><scale value=\"1e30\"/></transform></shape>\n"));
    expect_clean_error(render(d + "/s.xml", d), {d + "/s.xml"});
    write_text(d + "/f.xml", xml("<sensor type=\"perspective\">\n<float name=\"fov\" value=\"inf\"/></sensor>\n"
                                 "<shape type=\"cube\"/>\n"));
    expect_clean_error(render(d + "/f.xml", d), {d + "/f.xml:3: "});
    write_text(d + "/r.xml", xml("<shape type=\"cube\">\n<bsdf type=\"diffuse\">\n"
                                 "<rgb name=\"reflectance\" value=\"nan 0 0\"/></bsdf></shape>\n"));
    expect_clean_error(render(d + "/r.xml", d), {d + "/r.xml:4: "});
}

TEST(BadInput, XmlTagsAttributesPluginsAndRefs) {
    std::string d = temp_dir("bad-xml");
    auto check = [&](const std::string& body, int line, const std::string& what) {
        std::string path = d + "/s" + std::to_string(line) + ".xml";
        write_text(path, xml(body));
        expect_clean_error(render(path, d), {path + ":" + std::to_string(line) + ": ", what});
    };
    check("<shape type=\"cube\">\n<sphere/></shape>\n", 3, "unknown tag <sphere>");
    check("\n<shape type=\"cube\" colour=\"red\"/>\n", 3, "unexpected attribute 'colour'");
    check("<shape type=\"cube\"/>\n\n<shape type=\"bsplinecurve\"/>\n", 4, "unsupported shape type 'bsplinecurve'");
    check("<bsdf type=\"velvet\" id=\"v\"/>\n", 2, "unsupported bsdf type 'velvet'");
    check("<sensor type=\"perspective\">\n<flaot name=\"fov\" value=\"30\"/></sensor>\n", 3, "unknown tag <flaot>");
    check("<sensor type=\"perspective\">\n<float name=\"fvo\" value=\"30\"/></sensor>\n", 3, "unused parameter 'fvo'");
    check("<shape type=\"cube\">\n<ref id=\"nothing\"/></shape>\n", 3, "unknown id 'nothing'");
    check("<shape type=\"cube\" id=\"box\"/>\n<shape type=\"cube\">\n<ref id=\"box\"/></shape>\n", 4, "not a <bsdf>");
    check("<shape type=\"cube\">\n<integer name=\"n\" value=\"$count\"/></shape>\n", 3, "$count");
}

TEST(BadInput, UnsupportedFeatures) {
    std::string d = temp_dir("bad-unsupported");
    write_text(d + "/inc.xml", xml("\n<include filename=\"other.xml\"/>\n"));
    expect_clean_error(render(d + "/inc.xml", d), {d + "/inc.xml:3: ", "include"});
    write_text(d + "/aov.xml", xml("<integrator type=\"aov\">\n<string name=\"aovs\" value=\"u:duv_dx\"/>"
                                   "<integrator type=\"path\"/></integrator>\n"));
    expect_clean_error(render(d + "/aov.xml", d), {d + "/aov.xml:3: ", "not supported"});
    write_text(d + "/nurbs.obj", "v 0 0 0\ncstype bspline\n");
    expect_clean_error(render(d + "/nurbs.obj", d), {d + "/nurbs.obj:2: free-form geometry"});
    write_text(d + "/scene.ply", "ply\n");
    expect_clean_error(render(d + "/scene.ply", d), {d + "/scene.ply: unknown scene format '.ply'"});
}

TEST(BadInput, CommandLineValues) {
    std::string d = temp_dir("bad-cli");
    expect_clean_error(run_candela("-D novalue --out " + d + "/x.exr"), {"-D expects name=value"});
    expect_clean_error(run_candela("--frames 1073741824 --spp-per-frame 1048576 --out " + d + "/x.exr"),
                       {"more than 2^32 - 1"});
    // Usage errors (a value of the wrong type or out of range) exit 2, as CLI11 parse errors do.
    expect_clean_error(run_candela("--max-depth -7 --out " + d + "/x.exr"), {"--max-depth: max_depth must be -1"}, 2);
    expect_clean_error(run_candela("--width abc --out " + d + "/x.exr"), {"--width"}, 2);
    expect_clean_error(run_candela("--frames 0 --out " + d + "/x.exr"), {"--frames"}, 2);
    // An output that cannot be written is refused before rendering, not after.
    expect_clean_error(run_candela("--width 8 --height 8 --frames 1 --quiet --out /nonexistent/dir/x.exr"),
                       {"/nonexistent/dir/x.exr: directory '/nonexistent/dir' does not exist"});
    // The size check runs on the scene file's resolution too, before any film is allocated.
    write_text(d + "/big.xml", xml("<sensor type=\"perspective\"><film type=\"hdrfilm\">\n"
                                   "<integer name=\"width\" value=\"1000000\"/><integer name=\"height\" "
                                   "value=\"1000000\"/></film></sensor>\n<shape type=\"cube\"/>\n"));
    expect_clean_error(run_candela(d + "/big.xml --quiet --out " + d + "/x.exr"), {d + "/big.xml", "GB"});
}

TEST(BadInput, CyclicRefsAndDeepNesting) {
    // Both used to overflow the stack (a crash): refs resolve recursively through wrappers.
    std::string d = temp_dir("bad-cycle");
    write_text(d + "/self.xml", xml("<bsdf type=\"twosided\" id=\"a\">\n<ref id=\"a\"/></bsdf>\n"
                                    "<shape type=\"cube\"><ref id=\"a\"/></shape>\n"));
    expect_clean_error(render(d + "/self.xml", d), {d + "/self.xml:3: cyclic reference: bsdf 'a' (line 2)"});
    write_text(d + "/pair.xml", xml("<bsdf type=\"twosided\" id=\"a\"><ref id=\"b\"/></bsdf>\n"
                                    "<bsdf type=\"twosided\" id=\"b\">\n<ref id=\"a\"/></bsdf>\n"));
    expect_clean_error(render(d + "/pair.xml", d), {d + "/pair.xml:4: cyclic reference: bsdf 'a' (line 2)"});
    std::string open, close;
    for (int i = 0; i < 20000; ++i) {
        open += "<bsdf type=\"twosided\">";
        close += "</bsdf>";
    }
    write_text(d + "/deep.xml", xml("<shape type=\"cube\">" + open + "<bsdf type=\"diffuse\"/>" + close + "</shape>\n"));
    expect_clean_error(render(d + "/deep.xml", d), {d + "/deep.xml:2: bsdfs nested more than 64 deep"});
}
