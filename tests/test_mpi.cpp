// Distributed rendering under mpirun on this machine (docs/distributed.md): 1, 2 and 3 ranks give
// the plain program's image bit for bit (EXR and the checkpoint's double sums), the image passes
// the Cornell box z-test against the Mitsuba reference, a slowed rank does fewer chunks, SIGTERM to
// mpirun writes the image so far, a rank that dies fails the run naming it, and checkpoints resume
// with another number of ranks. Built only with CANDELA_MPI.
#ifdef CANDELA_HAS_MPI
#include <gtest/gtest.h>
#include <cstdio>
#include <filesystem>
#include <cstring>
#include <regex>
#include <sstream>
#include "film/film.h"
#include "film/image_io.h"
#include "support/run.h"
#include "support/spawn.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::test;

namespace {

const std::string kMpirun = std::string(CANDELA_MPIRUN) + " --oversubscribe --allow-run-as-root";
const std::string kBox = "--width 32 --height 32 --threads 1 --seed 3 --quiet";

// candela under mpirun with `np` ranks; `env` ("NAME=value ...") reaches every rank.
RunResult run_mpi(int np, const std::string& args, const std::string& env = "") {
    return run_shell("env -u DISPLAY -u WAYLAND_DISPLAY " + env + " " + kMpirun + " -np " + std::to_string(np) + " " +
                     CANDELA_BIN + " " + args);
}

bool same_file(const std::string& a, const std::string& b) {
    std::string x = read_bytes(a), y = read_bytes(b);
    return !x.empty() && x == y;
}

// Samples per pixel in a checkpoint (header offset 24, src/app/checkpoint.cpp), -1 if unreadable.
long checkpoint_spp(const std::string& path) {
    std::string b = read_bytes(path);
    if (b.size() < 64) return -1;
    uint32_t spp;
    std::memcpy(&spp, b.data() + 24, 4);
    return long(spp);
}

// The chunks each rank rendered, from rank 0's summary ("chunks of 1 spp per rank: 10 3 3").
std::vector<int> chunks_per_rank(const std::string& out) {
    std::smatch m;
    std::vector<int> v;
    if (!std::regex_search(out, m, std::regex("per rank: ([0-9 ]+);"))) return v;
    std::istringstream in(m[1].str());
    for (int c; in >> c;) v.push_back(c);
    return v;
}

// cbox_filter.xml with the aov integrator (depth and albedo layers) and an RGBA film, written to
// dir: every array a layer message carries (weights, AOVs, alpha).
std::string cbox_with_aovs_and_alpha(const std::string& dir) {
    std::string text = read_bytes(std::string(CANDELA_TEST_DATA) + "/scenes/cbox_filter.xml");
    size_t b = text.find("    <integrator"), e = text.find("</integrator>") + std::string("</integrator>").size();
    text = text.substr(0, b) +
           "<integrator type=\"aov\"><string name=\"aovs\" value=\"dd:depth,aa:albedo\"/>"
           "<integrator type=\"path\" name=\"my_image\"/></integrator>" +
           text.substr(e);
    for (size_t at; (at = text.find("../../../scenes/")) != std::string::npos;)
        text.replace(at, 16, std::string(CANDELA_SOURCE_DIR) + "/scenes/");
    const std::string rgb = "<string name=\"pixel_format\" value=\"rgb\"/>";
    text.replace(text.find(rgb), rgb.size(), "<string name=\"pixel_format\" value=\"rgba\"/>");
    write_text(dir + "/aov.xml", text);
    return dir + "/aov.xml";
}

}  // namespace

TEST(Mpi, OneTwoThreeRanksGiveThePlainImageBitForBit) {
    std::string d = temp_dir("mpi-exact");
    // The box filter with one sample index per chunk, and a wide gaussian with 2 per chunk (its
    // layers are merged tiles, not single samples).
    const std::string box = kBox + " --frames 12";
    const std::string gauss = std::string(CANDELA_TEST_DATA) +
                              "/scenes/cbox_filter.xml -D res=20 -D filter=gaussian --threads 1 --seed 3 --quiet "
                              "--frames 5 --spp-per-frame 2";
    const std::string aov = cbox_with_aovs_and_alpha(d) + " -D res=16 -D filter=gaussian --threads 1 --seed 3 --quiet --frames 4";
    // The light tracer's splats (and their light-path count) travel in the layers too; the sobol
    // sampler's numbers depend on the sample index only, not on the rank that draws them.
    const std::string ptracer = kBox + " --frames 4 --integrator ptracer";
    const std::string sobol = kBox + " --frames 6 --sampler sobol";
    for (auto [name, args] : {std::pair<std::string, std::string>{"box", box}, {"gauss", gauss}, {"aov", aov},
                              {"ptracer", ptracer}, {"sobol", sobol}}) {
        const std::string plain = d + "/" + name + "-plain";
        const bool ck = name != "aov";  // checkpoints do not hold AOV layers
        RunResult p = run_candela(args + " --out " + plain + ".exr" + (ck ? " --checkpoint " + plain + ".ck" : ""));
        ASSERT_EQ(p.exit_code, 0) << p.output;
        for (int np : {1, 2, 3}) {
            if (name != "box" && np != 3) continue;  // one run of each other layout is enough
            const std::string m = d + "/" + name + "-np" + std::to_string(np);
            RunResult r = run_mpi(np, args + " --out " + m + ".exr" + (ck ? " --checkpoint " + m + ".ck" : ""));
            ASSERT_EQ(r.exit_code, 0) << r.output;
            EXPECT_TRUE(same_file(plain + ".exr", m + ".exr")) << name << " with " << np << " ranks";
            if (ck) {
                EXPECT_TRUE(same_file(plain + ".ck", m + ".ck")) << name << " with " << np << " ranks (double sums)";
            }
        }
    }
    // Control: the comparison sees a change of one seed.
    RunResult other = run_mpi(2, "--width 32 --height 32 --threads 1 --seed 4 --quiet --frames 12 --out " + d + "/seed4.exr");
    ASSERT_EQ(other.exit_code, 0) << other.output;
    EXPECT_FALSE(same_file(d + "/box-plain.exr", d + "/seed4.exr"));
}

// The image test of test_image_cornell.cpp (8 batches of 64 spp, seeds 1..8, 64 x 64, against the
// committed Mitsuba 3 reference) with every batch rendered by 3 ranks. Control: the same estimate
// 3% darker is rejected (measured: whole-image p ~ 1e-30; the passing image p > 0.01).
TEST(Mpi, CornellBoxPassesTheMitsubaZTest) {
    std::string d = temp_dir("mpi-cornell");
    std::vector<std::unique_ptr<Film>> films;
    std::vector<const Film*> ptrs;
    std::vector<std::unique_ptr<Film>> dark_films;
    std::vector<const Film*> dark_ptrs;
    for (int b = 1; b <= 8; ++b) {
        const std::string out = d + "/b" + std::to_string(b) + ".exr";
        RunResult r = run_mpi(3, "--width 64 --height 64 --threads 1 --quiet --frames 64 --seed " + std::to_string(b) +
                                     " --out " + out);
        ASSERT_EQ(r.exit_code, 0) << r.output;
        Image img = read_linear_image(out);
        ASSERT_EQ(img.width, 64);
        const size_t n = size_t(img.width) * size_t(img.height);
        std::vector<dvec3> sums(n), dark_sums(n);
        for (size_t i = 0; i < n; ++i) {
            sums[i] = 64.0 * dvec3(img.rgb[3 * i], img.rgb[3 * i + 1], img.rgb[3 * i + 2]);
            dark_sums[i] = 0.97 * sums[i];
        }
        films.push_back(std::make_unique<Film>(64, 64));
        films.back()->restore(std::move(sums), std::vector<uint32_t>(n, 64u), 0);
        ptrs.push_back(films.back().get());
        dark_films.push_back(std::make_unique<Film>(64, 64));
        dark_films.back()->restore(std::move(dark_sums), std::vector<uint32_t>(n, 64u), 0);
        dark_ptrs.push_back(dark_films.back().get());
    }
    using namespace candela::stats;
    const ImageEstimate ref = ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/cornell64");
    const ImageEstimate test = ImageEstimate::from_batches(ptrs), control = ImageEstimate::from_batches(dark_ptrs);
    BlockTestResult r = block_z_test(test, ref, 8, 0.01);
    const double p = whole_image_p(test, ref), p_dark = whole_image_p(control, ref);
    BlockTestResult rd = block_z_test(control, ref, 8, 0.01);
    std::printf("  3 ranks: blocks %s, whole image p = %.3g; 3%% darker: blocks %s, p = %.3g\n", r.describe().c_str(), p,
                rd.describe().c_str(), p_dark);
    EXPECT_TRUE(r.passed(0.01)) << r.describe();
    EXPECT_GE(p, 0.01);
    EXPECT_LT(p_dark, 0.01);
}

// Rank 2 sleeps 250 ms per chunk: the others take its share (a static split would give it 20 of
// the 60 chunks and make the render last 5 s), and the image is still the plain one.
TEST(Mpi, SlowRankDoesFewerChunks) {
    std::string d = temp_dir("mpi-slow");
    const std::string args = kBox + " --frames 60";
    ASSERT_EQ(run_candela(args + " --out " + d + "/plain.exr").exit_code, 0);
    RunResult r = run_mpi(3, "--width 32 --height 32 --threads 1 --seed 3 --frames 60 --out " + d + "/slow.exr",
                          "CANDELA_MPI_TEST_SLOW_RANK=2:250");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::vector<int> c = chunks_per_rank(r.output);
    ASSERT_EQ(c.size(), 3u) << r.output;
    EXPECT_EQ(c[0] + c[1] + c[2], 60);
    EXPECT_LT(c[2], c[0]);
    EXPECT_LT(c[2], c[1]);
    EXPECT_LE(c[2], 6) << r.output;
    EXPECT_TRUE(same_file(d + "/plain.exr", d + "/slow.exr"));
}

// SIGTERM to mpirun: rank 0 gathers the chunks in flight and writes the image; the checkpoint (whole
// sample indices) resumes on 2 ranks and on 1 plain process to the uninterrupted image.
TEST(Mpi, SigtermWritesTheImageAndTheCheckpointResumesWithOtherRankCounts) {
    std::string d = temp_dir("mpi-sigterm");
    const std::string ck = d + "/run.ck";
    Child child("--oversubscribe --allow-run-as-root -np 3 " + std::string(CANDELA_BIN) +
                    " --width 32 --height 32 --threads 1 --seed 3"
                    " --frames 1000000 --checkpoint-every 0 --checkpoint " + ck + " --out " + d + "/cut.exr",
                d + "/log.txt", CANDELA_MPIRUN);
    ASSERT_TRUE(child.wait_until([&] { return checkpoint_spp(ck) >= 16; }, 120)) << read_bytes(d + "/log.txt");
    child.signal(SIGTERM);
    const int code = child.wait(60);
    const std::string log = read_bytes(d + "/log.txt");
    EXPECT_NE(code, -1) << log;
    EXPECT_NE(log.find("terminated: "), std::string::npos) << log;
    Image cut = read_linear_image(d + "/cut.exr");
    EXPECT_EQ(cut.width, 32);
    const long spp = checkpoint_spp(ck);
    ASSERT_GE(spp, 16) << log;
    const std::string total = " --frames " + std::to_string(spp + 6);
    ASSERT_EQ(run_candela(kBox + total + " --out " + d + "/full.exr").exit_code, 0);
    RunResult two = run_mpi(2, kBox + total + " --resume " + ck + " --out " + d + "/two.exr");
    ASSERT_EQ(two.exit_code, 0) << two.output;
    RunResult one = run_candela(kBox + total + " --resume " + ck + " --out " + d + "/one.exr");
    ASSERT_EQ(one.exit_code, 0) << one.output;
    EXPECT_TRUE(same_file(d + "/full.exr", d + "/two.exr"));
    EXPECT_TRUE(same_file(d + "/full.exr", d + "/one.exr"));
}

// A rank killed part-way (SIGKILL at its 5th chunk): the run fails with mpirun's message naming the
// rank, and the last checkpoint resumes to the uninterrupted image. Rank 0 renders its own chunks
// without a round trip, so a worker gets far fewer than a third of them (here 15% of 150 one-spp
// chunks, and fewer than 10 on a faster or busier machine): the render is long enough that rank 1
// reaches its 5th chunk on any machine.
TEST(Mpi, DeadRankFailsNamingItAndTheCheckpointResumes) {
    std::string d = temp_dir("mpi-dead");
    const int frames = 600;
    const std::string args = kBox + " --frames " + std::to_string(frames);
    RunResult r = run_mpi(3, args + " --checkpoint-every 0 --checkpoint " + d + "/c.ck --out " + d + "/dead.exr",
                          "CANDELA_MPI_TEST_DIE_RANK=1:5");
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("rank 1"), std::string::npos) << r.output;
    EXPECT_FALSE(file_exists(d + "/dead.exr"));
    const long spp = checkpoint_spp(d + "/c.ck");
    ASSERT_GT(spp, 0) << r.output;
    EXPECT_LT(spp, frames);
    ASSERT_EQ(run_candela(args + " --out " + d + "/full.exr").exit_code, 0);
    RunResult resumed = run_mpi(2, args + " --resume " + d + "/c.ck --out " + d + "/resumed.exr");
    ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
    EXPECT_TRUE(same_file(d + "/full.exr", d + "/resumed.exr"));
}

TEST(Mpi, TimeLimitAndSetupErrors) {
    std::string d = temp_dir("mpi-limit");
    RunResult r = run_mpi(3, "--width 32 --height 32 --threads 1 --frames 1000000 --time-limit 0.5 --out " + d + "/t.exr");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("time limit: "), std::string::npos) << r.output;
    EXPECT_EQ(read_linear_image(d + "/t.exr").width, 32);
    // A scene that does not load: every rank fails, rank 0 says so once.
    RunResult bad = run_mpi(2, d + "/missing.xml --quiet --out " + d + "/x.exr");
    EXPECT_NE(bad.exit_code, 0);
    size_t first = bad.output.find("missing.xml");
    ASSERT_NE(first, std::string::npos) << bad.output;
    EXPECT_EQ(bad.output.find("candela:", bad.output.find("candela:") + 1), std::string::npos) << bad.output;
    // Adaptive sampling's decision half is not in the layers: refused in one line, nothing written.
    RunResult adaptive = run_mpi(2, "--width 16 --height 16 --threads 1 --quiet --target-error 0.1 --out " + d + "/a.exr");
    EXPECT_NE(adaptive.exit_code, 0);
    EXPECT_NE(adaptive.output.find("--target-error is not available under MPI"), std::string::npos) << adaptive.output;
    EXPECT_FALSE(std::filesystem::exists(d + "/a.exr"));
    // MLT's chains run from one sample index to the next: refused in one line at any rank count
    // (before issue 41 each rank replayed the others' mutations).
    for (const char* mlt : {"pssmlt", "mmlt"}) {
        RunResult r = run_mpi(2, std::string("--width 16 --height 16 --threads 1 --quiet --integrator ") + mlt + " --out " + d + "/m.exr");
        EXPECT_NE(r.exit_code, 0);
        EXPECT_NE(r.output.find(std::string(mlt) + " does not run under MPI"), std::string::npos) << r.output;
        EXPECT_EQ(r.output.find("candela:", r.output.find("candela:") + 1), std::string::npos) << r.output;
        EXPECT_FALSE(std::filesystem::exists(d + "/m.exr"));
    }
}

#endif  // CANDELA_HAS_MPI
