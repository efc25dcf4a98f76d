// The table of what each integrator reads (integrator/caps.h) against what the integrators do, and
// the one depth convention (Mitsuba's, integrator/depth.h) of scene files and the command line.
#include <gtest/gtest.h>
#include <algorithm>
#include <cstring>
#include <functional>
#include "core/error.h"
#include "integrator/caps.h"
#include "integrator/integrator.h"
#include "render/launch.h"
#include "render/renderer.h"
#include "support/run.h"

using namespace candela;
using namespace candela::test;

namespace {

constexpr int kSize = 16, kSpp = 4;

// The film's resolved image, as bytes.
std::string render_bytes(const Scene& scene) {
    Film film(kSize, kSize);
    configure_film(film, scene.settings);
    Renderer::render_pass(scene, film, 0, kSpp, 2);
    const std::vector<float> rgb = film.resolve();
    return std::string(reinterpret_cast<const char*>(rgb.data()), rgb.size() * sizeof(float));
}

struct Variation {
    const char* name;
    bool IntegratorCaps::*read;
    std::function<void(RenderSettings&)> change;  // from the base settings to another value
};

const Variation kVariations[] = {
    {"sampling", &IntegratorCaps::sampling, [](RenderSettings& s) { s.sampling = SamplingMode::Light; }},
    {"sampler", &IntegratorCaps::sampler, [](RenderSettings& s) { s.sampler.type = SamplerType::Stratified; }},
    {"filter", &IntegratorCaps::filter, [](RenderSettings& s) { s.filter = gaussian_filter(); }},
    {"max_depth", &IntegratorCaps::max_depth, [](RenderSettings& s) { s.max_depth = max_depth_from_mitsuba(3); }},
    {"rr_depth", &IntegratorCaps::rr_depth, [](RenderSettings& s) { s.rr_depth = 1; }},
    {"hide_emitters", &IntegratorCaps::hide_emitters, [](RenderSettings& s) { s.integrator.hide_emitters = true; }},
};

std::string cornell_xml() { return std::string(CANDELA_SOURCE_DIR) + "/scenes/cornell-box/scene.xml"; }

}  // namespace

// For every integrator and every setting: two values give the same image bit for bit when the
// table says the integrator does not read the setting, and different images when it says it does.
// The built-in Cornell box at 16 x 16, 4 spp: the light is in view (hide_emitters), paths bounce
// (depths, Russian roulette), and every setting changes the path tracer's image.
TEST(Caps, TableTellsTheTruth) {
    SceneOverrides ov;
    ov.width = ov.height = kSize;
    const auto base_scene = prepare_scene("", ov);
    SceneParams base = base_scene->params();
    base.settings.spp = kSpp;  // what the stratified sampler stratifies over
    base.settings.max_depth = -1;
    base.settings.rr_depth = 5;
    base.settings.sampling = SamplingMode::Mis;
    base.settings.sampler.type = SamplerType::Independent;
    base.settings.filter = box_filter();
    base.settings.integrator.hide_emitters = false;
    base.settings.integrator.mlt.bootstrap_samples = 4000;  // small, for a 16 x 16 image
    base.settings.integrator.mlt.chains = 32;
    for (IntegratorType t : kIntegratorTypes) {
        const char* name = integrator_type_name(t);
        SceneParams p = base;
        p.settings.integrator.type = t;
        const auto a = base_scene->with_params(p);
        const std::string img_a = render_bytes(*a);
        // The control of "differs": the same settings give the same image.
        ASSERT_EQ(img_a, render_bytes(*a)) << name << ": not deterministic";
        double sum = 0;
        for (size_t k = 0; k < img_a.size() / sizeof(float); ++k) {
            float v;
            std::memcpy(&v, img_a.data() + k * sizeof(float), sizeof v);
            sum += v;
        }
        EXPECT_GT(sum, 0.0) << name << ": black image";
        for (const Variation& v : kVariations) {
            SceneParams q = p;
            v.change(q.settings);
            const auto b = base_scene->with_params(q);
            const bool same = img_a == render_bytes(*b);
            if (reads(t).*v.read)
                EXPECT_FALSE(same) << name << " reads " << v.name << " (integrator/caps.h) but its image does not change";
            else
                EXPECT_TRUE(same) << name << " does not read " << v.name << " (integrator/caps.h) but its image changes";
        }
    }
}

// Options the integrator does not read are refused when given on the command line (a usage
// error naming the option and the integrator); those it reads are taken.
TEST(Caps, CommandLineRefusesWhatTheIntegratorDoesNotRead) {
    struct Option {
        const char* flag;
        bool IntegratorCaps::*read;
        std::function<void(SceneOverrides&)> set;
    };
    const Option options[] = {
        {"--sampling", &IntegratorCaps::sampling, [](SceneOverrides& o) { o.sampling = SamplingMode::Light; }},
        {"--sampler", &IntegratorCaps::sampler, [](SceneOverrides& o) { o.sampler = SamplerType::Stratified; }},
        {"--max-depth", &IntegratorCaps::max_depth, [](SceneOverrides& o) { o.max_depth = 3; }},
        {"--rr-depth", &IntegratorCaps::rr_depth, [](SceneOverrides& o) { o.rr_depth = 2; }},
    };
    int refused = 0;
    for (IntegratorType t : kIntegratorTypes)
        for (const Option& o : options) {
            SceneOverrides ov;
            ov.width = ov.height = 4;
            ov.integrator = t;
            o.set(ov);
            const std::string what = std::string(integrator_type_name(t)) + " " + o.flag;
            if (reads(t).*o.read) {
                EXPECT_NO_THROW(prepare_scene("", ov)) << what;
                continue;
            }
            ++refused;
            try {
                prepare_scene("", ov);
                ADD_FAILURE() << what << " accepted";
            } catch (const UsageError& e) {
                const std::string m = e.what();
                EXPECT_NE(m.find(o.flag), std::string::npos) << m;
                EXPECT_NE(m.find(std::string("the ") + integrator_type_name(t) + " integrator"), std::string::npos) << m;
            }
        }
    EXPECT_GE(refused, 6);  // direct: 3, ptracer, bdpt: sampling, pssmlt: sampler, mmlt: 2
    // The program: exit status 2 and one line.
    const RunResult r = run_candela("--integrator bdpt --sampling light --width 4 --height 4 --out /tmp/unused.exr");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--sampling: the bdpt integrator does not read it"), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

// A scene-file value the integrator ignores is a one-line note, never a refusal.
TEST(Caps, SceneValuesTheIntegratorIgnoresAreNoted) {
    const std::string d = temp_dir("caps-note");
    write_text(d + "/mlt.xml",
               "<scene version=\"3.0.0\"><integrator type=\"pssmlt\"><integer name=\"bootstrap_samples\" value=\"500\"/>"
               "<integer name=\"chains\" value=\"8\"/></integrator>"
               "<sensor type=\"perspective\"><sampler type=\"stratified\"><integer name=\"sample_count\" value=\"4\"/>"
               "</sampler><film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" "
               "value=\"8\"/></film></sensor>"
               "<shape type=\"sphere\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>"
               "</scene>");
    const auto scene = prepare_scene(d + "/mlt.xml", {});
    // The sampler only: the film's default gaussian filter is read (the splats go through it).
    ASSERT_EQ(scene->warnings.size(), 1u);
    EXPECT_NE(scene->warnings[0].find("the pssmlt integrator ignores the scene's sampler stratified"), std::string::npos)
        << scene->warnings[0];
    // The path tracer reads both: nothing to note.
    SceneOverrides path;
    path.integrator = IntegratorType::Path;
    EXPECT_TRUE(prepare_scene(d + "/mlt.xml", path)->warnings.empty());
    // The file's own depth, ignored by an integrator the command line chose, is noted too.
    SceneOverrides direct;
    direct.integrator = IntegratorType::Direct;
    direct.defines = {{"max_depth", "4"}};
    const auto c = prepare_scene(cornell_xml(), direct);
    ASSERT_EQ(c->warnings.size(), 1u);
    EXPECT_NE(c->warnings[0].find("the direct integrator ignores the scene's max_depth 4"), std::string::npos)
        << c->warnings[0];
}

// Features around the integrator: refused with a usage error where the table says so.
TEST(Caps, FeaturesFollowTheTable) {
    const std::string d = temp_dir("caps-features");
    for (IntegratorType t : kIntegratorTypes) {
        RenderSettings st;
        st.integrator.type = t;
        const IntegratorCaps& c = reads(t);
        const struct {
            RunFeatures f;
            bool supported;
        } cases[] = {{{true, false, false, false}, c.mpi},
                     {{false, true, false, false}, c.adaptive},
                     {{false, false, true, false}, c.checkpoint},
                     {{false, false, false, true}, c.time_limit}};
        for (const auto& k : cases) {
            if (k.supported) EXPECT_NO_THROW(check_run_features(st, k.f)) << integrator_type_name(t);
            else EXPECT_THROW(check_run_features(st, k.f), UsageError) << integrator_type_name(t);
        }
    }
    // The program: adaptive sampling with bdpt is a usage error; with the path tracer it renders.
    RunResult r = run_candela("--integrator bdpt --target-error 0.5 --width 8 --height 8 --out " + d + "/a.exr");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--target-error: not available with the bdpt integrator"), std::string::npos) << r.output;
    r = run_candela("--integrator path --target-error 0.5 --sample-count 16 --width 8 --height 8 --quiet --out " + d +
                    "/b.exr");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    // AOVs: only the integrators that trace camera rays per pixel take the aov wrapper.
    write_text(d + "/aov.xml",
               "<scene version=\"3.0.0\"><integrator type=\"aov\"><string name=\"aovs\" value=\"dd:depth\"/>"
               "<integrator type=\"path\"/></integrator>"
               "<sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/>"
               "<integer name=\"height\" value=\"4\"/></film></sensor>"
               "<shape type=\"sphere\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>"
               "</scene>");
    for (IntegratorType t : kIntegratorTypes) {
        SceneOverrides ov;
        ov.integrator = t;
        if (reads(t).aovs) EXPECT_NO_THROW(prepare_scene(d + "/aov.xml", ov)) << integrator_type_name(t);
        else EXPECT_THROW(prepare_scene(d + "/aov.xml", ov), Error) << integrator_type_name(t);
    }
}

// --max-depth is Mitsuba's max_depth, the scene file's: -D max_depth=3 and --max-depth 3 render
// the same image bit for bit. Control: --max-depth 4 renders another.
TEST(Depth, FileAndCommandLineAgree) {
    auto image = [](SceneOverrides ov) {
        ov.defines.emplace_back("res", std::to_string(kSize));
        return render_bytes(*prepare_scene(cornell_xml(), ov));
    };
    SceneOverrides file, cli, cli4;
    file.defines = {{"max_depth", "3"}};
    cli.max_depth = 3;
    cli4.max_depth = 4;
    const std::string a = image(file);
    EXPECT_EQ(a, image(cli));
    EXPECT_NE(a, image(cli4));
    EXPECT_EQ(prepare_scene(cornell_xml(), cli)->settings.max_depth, 2);  // two scattering events

    // The program, byte for byte in the written files.
    const std::string d = temp_dir("depth-cli");
    const std::string common = cornell_xml() + " -D res=8 --frames 2 --quiet --out " + d;
    ASSERT_EQ(run_candela(common + "/file.pfm -D max_depth=3").exit_code, 0);
    ASSERT_EQ(run_candela(common + "/cli.pfm --max-depth 3").exit_code, 0);
    ASSERT_EQ(run_candela(common + "/cli4.pfm --max-depth 4").exit_code, 0);
    EXPECT_EQ(read_bytes(d + "/file.pfm"), read_bytes(d + "/cli.pfm"));
    EXPECT_NE(read_bytes(d + "/file.pfm"), read_bytes(d + "/cli4.pfm"));
}

// One rule for the depths of files and command line (Mitsuba 3's: rr_depth > 0; max_depth -1 or
// >= 1, 0 being a black image): the same values are refused by both, with the same reason.
TEST(Depth, OneRuleForFileAndCommandLine) {
    const std::string d = temp_dir("depth-rule");
    auto scene = [&](const char* param, int value) {
        const std::string path = d + "/" + param + std::to_string(value + 10) + ".xml";
        write_text(path, std::string("<scene version=\"3.0.0\"><integrator type=\"path\"><integer name=\"") + param +
                             "\" value=\"" + std::to_string(value) + "\"/></integrator></scene>");
        return path;
    };
    struct Case {
        const char* param;
        const char* flag;
        int value;
        bool valid;
    } cases[] = {{"rr_depth", "--rr-depth", 0, false},   {"rr_depth", "--rr-depth", -1, false},
                 {"rr_depth", "--rr-depth", 1, true},    {"max_depth", "--max-depth", 0, false},
                 {"max_depth", "--max-depth", -2, false}, {"max_depth", "--max-depth", 1, true},
                 {"max_depth", "--max-depth", -1, true}};
    for (const Case& c : cases) {
        const std::string what = std::string(c.param) + " " + std::to_string(c.value);
        const char* reason = std::string(c.param) == "rr_depth" ? rr_depth_error(c.value) : max_depth_error(c.value);
        EXPECT_EQ(reason == nullptr, c.valid) << what;
        SceneOverrides ov;
        (std::string(c.param) == "rr_depth" ? ov.rr_depth : ov.max_depth) = c.value;
        std::string file_error, cli_error;
        try {
            load_scene(scene(c.param, c.value));
        } catch (const Error& e) {
            file_error = e.what();
        }
        try {
            prepare_scene("", ov);
        } catch (const UsageError& e) {
            cli_error = e.what();
        }
        EXPECT_EQ(file_error.empty(), c.valid) << what << ": " << file_error;
        EXPECT_EQ(cli_error.empty(), c.valid) << what << ": " << cli_error;
        if (!c.valid) {
            EXPECT_NE(file_error.find(reason), std::string::npos) << file_error;
            EXPECT_NE(cli_error.find(reason), std::string::npos) << cli_error;
            EXPECT_NE(cli_error.find(c.flag), std::string::npos) << cli_error;
        }
    }
    const RunResult r = run_candela("--rr-depth 0 --out " + d + "/x.exr");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(std::string("--rr-depth: ") + rr_depth_error(0)), std::string::npos) << r.output;
}
