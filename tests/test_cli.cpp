// The command line: exit codes and one-line messages for bad input; never a crash.
#include <gtest/gtest.h>
#include "support/run.h"

using namespace candela::test;

namespace {

// Exactly one line of output that names `needle`, and a clean non-zero exit (not a signal).
void expect_clean_error(const RunResult& r, const std::string& needle) {
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_LT(r.exit_code, 128) << "killed by a signal: " << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << "expected '" << needle << "' in: " << r.output;
    size_t lines = 0;
    for (char c : r.output) lines += c == '\n';
    EXPECT_EQ(lines, 1u) << r.output;
}

}  // namespace

TEST(Cli, HelpExitsZero) {
    RunResult r = run_candela("--help");
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.output.find("--frames"), std::string::npos);
    EXPECT_NE(r.output.find("--out"), std::string::npos);
}

TEST(Cli, UnknownOptionIsUsageError) {
    RunResult r = run_candela("--no-such-option");
    EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST(Cli, MissingSceneFile) {
    std::string d = temp_dir("missing");
    RunResult r = run_candela("/nonexistent/scene.xml --out " + d + "/x.exr");
    expect_clean_error(r, "/nonexistent/scene.xml");
}

TEST(Cli, MalformedXmlNamesFileAndLine) {
    std::string d = temp_dir("malformed");
    write_text(d + "/bad.xml", "<scene version=\"3.0.0\">\n  <integrator type=\"path\">\n    <integer name=\"max_depth\" value=\"3\">\n</scene>\n");
    RunResult r = run_candela(d + "/bad.xml --out " + d + "/x.exr");
    expect_clean_error(r, d + "/bad.xml:");
}

TEST(Cli, UnknownPluginTypeNamesFileAndLine) {
    std::string d = temp_dir("plugin");
    write_text(d + "/s.xml",
               "<scene version=\"3.0.0\">\n"
               "  <integrator type=\"path\"/>\n"
               "  <shape type=\"teapot\"/>\n"
               "</scene>\n");
    RunResult r = run_candela(d + "/s.xml --out " + d + "/x.exr");
    expect_clean_error(r, d + "/s.xml:3:");
    EXPECT_NE(r.output.find("teapot"), std::string::npos) << r.output;
}

TEST(Cli, ZeroAndNegativeSizes) {
    std::string d = temp_dir("sizes");
    expect_clean_error(run_candela("--width 0 --out " + d + "/x.exr"), "image size must be positive");
    expect_clean_error(run_candela("--height -4 --out " + d + "/x.exr"), "image size must be positive");
}

TEST(Cli, AbsurdSizeRefusedBeforeAllocating) {
    std::string d = temp_dir("absurd");
    RunResult r = run_candela("--width 200000 --height 200000 --out " + d + "/x.exr");
    expect_clean_error(r, "GB");
}

TEST(Cli, UnknownOutputFormat) {
    std::string d = temp_dir("ext");
    expect_clean_error(run_candela("--width 8 --height 8 --frames 1 --out " + d + "/x.bmp"), "x.bmp");
}

TEST(Cli, BadSamplingMode) {
    std::string d = temp_dir("mode");
    expect_clean_error(run_candela("--sampling fancy --out " + d + "/x.exr"), "fancy");
}

TEST(Cli, BadSampler) {
    std::string d = temp_dir("sampler");
    expect_clean_error(run_candela("--sampler fancy --out " + d + "/x.exr"), "unknown sampler 'fancy'");
    EXPECT_EQ(run_candela("--sampler orthogonal --width 8 --height 8 --frames 1 --quiet --out " + d + "/x.exr").exit_code, 0);
    EXPECT_NE(run_candela("--sample-count 0 --out " + d + "/x.exr").exit_code, 0);
}

TEST(Cli, HeadlessRenderWritesEveryFormat) {
    std::string d = temp_dir("formats");
    for (const char* ext : {"exr", "pfm", "png"}) {
        std::string out = d + "/img." + ext;
        RunResult r = run_candela("--width 32 --height 24 --frames 2 --quiet --out " + out);
        EXPECT_EQ(r.exit_code, 0) << r.output;
        EXPECT_EQ(r.output, "");  // --quiet prints nothing on success
        EXPECT_GT(read_bytes(out).size(), 100u) << out;
    }
}

TEST(Cli, SummaryLineWhenNotATerminal) {
    std::string d = temp_dir("summary");
    RunResult r = run_candela("--width 16 --height 16 --frames 3 --out " + d + "/x.exr");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("Msamples/s"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("Mrays/s"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("3 spp"), std::string::npos) << r.output;
    // The memory report of the built-in box (32 triangles, lights present, no vertex normals).
    EXPECT_NE(r.output.find("candela: 32 triangles,"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("B/triangle: mesh "), std::string::npos) << r.output;
}
