// Checkpoints through the program: a resumed render equals an uninterrupted one bit for bit (also
// after SIGKILL), and a checkpoint of another scene or settings, or a damaged one, is refused with
// a one-line error.
#include <gtest/gtest.h>
#include <cstring>
#include "film/image_io.h"
#include "support/run.h"
#include "support/spawn.h"

using namespace candela;
using namespace candela::test;

namespace {

// The cornell box, small and quick; every run of a test shares these options.
const std::string kScene = "--width 24 --height 20 --quiet";

// Samples per pixel recorded in a checkpoint (header offset 24, see src/app/checkpoint.cpp), or
// -1 when the file is missing or short.
long checkpoint_spp(const std::string& path) {
    std::string b = read_bytes(path);
    if (b.size() < 64) return -1;
    uint32_t spp;
    std::memcpy(&spp, b.data() + 24, 4);
    return long(spp);
}

void expect_same_image(const std::string& a, const std::string& b) {
    Image ia = read_linear_image(a), ib = read_linear_image(b);
    ASSERT_EQ(ia.width, ib.width);
    ASSERT_EQ(ia.height, ib.height);
    ASSERT_EQ(ia.rgb.size(), ib.rgb.size());
    EXPECT_EQ(std::memcmp(ia.rgb.data(), ib.rgb.data(), ia.rgb.size() * sizeof(float)), 0) << a << " vs " << b;
}

// Exactly one line naming `needle`, and a clean non-zero exit.
void expect_clean_error(const RunResult& r, const std::string& needle) {
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << "expected '" << needle << "' in: " << r.output;
    size_t lines = 0;
    for (char c : r.output) lines += c == '\n';
    EXPECT_EQ(lines, 1u) << r.output;
}

}  // namespace

TEST(Checkpoint, ResumedRenderEqualsUninterrupted) {
    std::string d = temp_dir("ckpt-resume");
    ASSERT_EQ(run_candela(kScene + " --frames 9 --out " + d + "/full.exr --checkpoint " + d + "/full.ck").exit_code, 0);
    EXPECT_EQ(checkpoint_spp(d + "/full.ck"), 9);

    // 4 passes, then the rest; the resume may use other threads and another pass size (the image
    // depends only on the samples taken), and it continues from, and saves to, the same file.
    RunResult a = run_candela(kScene + " --frames 4 --threads 1 --out " + d + "/part.exr --checkpoint " + d + "/part.ck");
    ASSERT_EQ(a.exit_code, 0) << a.output;
    EXPECT_EQ(checkpoint_spp(d + "/part.ck"), 4);
    RunResult b = run_candela(kScene + " --frames 3 --spp-per-frame 3 --threads 3 --out " + d + "/part.exr --checkpoint " +
                              d + "/part.ck --resume " + d + "/part.ck");
    ASSERT_EQ(b.exit_code, 0) << b.output;
    expect_same_image(d + "/full.exr", d + "/part.exr");
    // The saved films (double sums, counts, non-finite count) are identical too.
    EXPECT_EQ(read_bytes(d + "/full.ck"), read_bytes(d + "/part.ck"));

    // Resuming a finished render just writes its image again.
    ASSERT_EQ(run_candela(kScene + " --frames 9 --out " + d + "/again.exr --resume " + d + "/full.ck").exit_code, 0);
    expect_same_image(d + "/full.exr", d + "/again.exr");
}

// With a stratified sampler the checkpoint holds the sampler and the sample count its sets are made
// of: a resume continues the same sets (bit for bit), another sampler or sample count is refused.
TEST(Checkpoint, ResumeWithAStratifiedSampler) {
    std::string d = temp_dir("ckpt-sampler");
    const std::string opts = kScene + " --sampler zsobol --sample-count 8";
    ASSERT_EQ(run_candela(opts + " --frames 8 --out " + d + "/full.exr").exit_code, 0);
    ASSERT_EQ(run_candela(opts + " --frames 3 --out " + d + "/part.exr --checkpoint " + d + "/part.ck").exit_code, 0);
    RunResult b = run_candela(opts + " --frames 8 --threads 1 --out " + d + "/part.exr --resume " + d + "/part.ck");
    ASSERT_EQ(b.exit_code, 0) << b.output;
    expect_same_image(d + "/full.exr", d + "/part.exr");
    const std::string resume = " --frames 8 --out " + d + "/c.exr --resume " + d + "/part.ck";
    expect_clean_error(run_candela(kScene + " --sampler zsobol --sample-count 16" + resume), "another scene or other settings");
    expect_clean_error(run_candela(kScene + " --sampler ldsampler --sample-count 8" + resume), "another scene or other settings");
    expect_clean_error(run_candela(kScene + resume), "another scene or other settings");
}

TEST(Checkpoint, ResumeAfterSigkillEqualsUninterrupted) {
    std::string d = temp_dir("ckpt-kill");
    // A render that would run for ages, saving after every pass; killed once it has saved two.
    {
        Child c(kScene + " --frames 1000000 --checkpoint-every 0 --out " + d + "/killed.exr --checkpoint " + d +
                    "/run.ck",
                d + "/killed.log");
        ASSERT_TRUE(c.wait_until([&] { return checkpoint_spp(d + "/run.ck") >= 2; })) << read_bytes(d + "/killed.log");
        c.signal(SIGKILL);
        EXPECT_EQ(c.wait(), 128 + SIGKILL);
    }
    EXPECT_FALSE(file_exists(d + "/killed.exr"));  // killed: no image, and no torn one
    long k = checkpoint_spp(d + "/run.ck");
    ASSERT_GE(k, 2);
    const std::string frames = " --frames " + std::to_string(k + 5);

    RunResult r = run_candela(kScene + frames + " --out " + d + "/resumed.exr --checkpoint " + d + "/run.ck --resume " +
                              d + "/run.ck");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ASSERT_EQ(run_candela(kScene + frames + " --out " + d + "/full.exr --checkpoint " + d + "/full.ck").exit_code, 0);
    expect_same_image(d + "/full.exr", d + "/resumed.exr");
    EXPECT_EQ(read_bytes(d + "/full.ck"), read_bytes(d + "/run.ck"));
}

TEST(Checkpoint, RefusesAnotherSceneOrSettings) {
    std::string d = temp_dir("ckpt-other");
    ASSERT_EQ(run_candela(kScene + " --frames 2 --out " + d + "/a.exr --checkpoint " + d + "/a.ck").exit_code, 0);
    const std::string resume = " --frames 4 --out " + d + "/b.exr --resume " + d + "/a.ck";
    expect_clean_error(run_candela(kScene + " --seed 5" + resume), "another scene or other settings");
    expect_clean_error(run_candela(kScene + " --max-depth 3" + resume), "another scene or other settings");
    expect_clean_error(run_candela(kScene + " --sampling bsdf" + resume), "another scene or other settings");
    expect_clean_error(run_candela(kScene + " --accel brute" + resume), "another scene or other settings");
    expect_clean_error(run_candela(kScene + " --sampler sobol" + resume), "another scene or other settings");
    expect_clean_error(run_candela("--width 20 --height 24 --quiet" + resume), "checkpoint is of a 24x20 image");
    write_text(d + "/rect.xml",
               "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><film type=\"hdrfilm\">"
               "<integer name=\"width\" value=\"24\"/><integer name=\"height\" value=\"20\"/></film></sensor>\n"
               "<shape type=\"rectangle\"/>\n</scene>\n");
    expect_clean_error(run_candela(d + "/rect.xml --quiet" + resume), "another scene or other settings");
    // More samples saved than asked for.
    expect_clean_error(run_candela(kScene + " --frames 1 --out " + d + "/b.exr --resume " + d + "/a.ck"),
                       "checkpoint has 2 spp, more than the 1");
    EXPECT_FALSE(file_exists(d + "/b.exr"));
}

TEST(Checkpoint, DamagedFilesAreRefused) {
    std::string d = temp_dir("ckpt-damaged");
    ASSERT_EQ(run_candela(kScene + " --frames 2 --out " + d + "/a.exr --checkpoint " + d + "/a.ck").exit_code, 0);
    const std::string good = read_bytes(d + "/a.ck");
    ASSERT_EQ(good.size(), 64u + 24u * 20u * 28u + 8u);
    auto resume = [&](const std::string& file) {
        return run_candela(kScene + " --frames 4 --out " + d + "/b.exr --resume " + file);
    };
    expect_clean_error(resume(d + "/missing.ck"), "missing.ck: cannot open checkpoint");
    expect_clean_error(resume(d), "not a regular file");
    write_text(d + "/empty.ck", "");
    expect_clean_error(resume(d + "/empty.ck"), "not a candela checkpoint");
    write_text(d + "/garbage.ck", std::string("\x7f" "ELF\x02\x01\x01\0\0\0garbage", 17));
    expect_clean_error(resume(d + "/garbage.ck"), "not a candela checkpoint");
    write_text(d + "/short.ck", good.substr(0, 40));
    expect_clean_error(resume(d + "/short.ck"), "truncated checkpoint");
    write_text(d + "/cut.ck", good.substr(0, good.size() - 100));
    expect_clean_error(resume(d + "/cut.ck"), "truncated or corrupt checkpoint");
    std::string flipped = good;
    flipped[64 + 1000] ^= 0x10;  // one bit of one sum
    write_text(d + "/flip.ck", flipped);
    expect_clean_error(resume(d + "/flip.ck"), "checksum mismatch");
    std::string version = good;
    version[8] = 9;
    write_text(d + "/version.ck", version);
    expect_clean_error(resume(d + "/version.ck"), "unsupported checkpoint version 9");
    std::string huge = good;  // a size whose film would not fit in memory: refused before allocating
    uint32_t big = 1u << 20;
    std::memcpy(&huge[16], &big, 4);
    std::memcpy(&huge[20], &big, 4);
    write_text(d + "/huge.ck", huge);
    expect_clean_error(resume(d + "/huge.ck"), "corrupt checkpoint (bad image size)");
    EXPECT_FALSE(file_exists(d + "/b.exr"));
}

TEST(Checkpoint, OptionErrors) {
    std::string d = temp_dir("ckpt-options");
    EXPECT_EQ(run_candela("--checkpoint-every 5 --out " + d + "/x.exr").exit_code, 2);  // needs --checkpoint
    EXPECT_EQ(run_candela("--checkpoint " + d + "/c.ck --checkpoint-every -1 --out " + d + "/x.exr").exit_code, 2);
    // A checkpoint that cannot be written is refused before rendering (a later failure, such as
    // a full disk, is a warning: the render goes on).
    expect_clean_error(run_candela(kScene + " --frames 2 --out " + d + "/x.exr --checkpoint /nonexistent/dir/c.ck"),
                       "/nonexistent/dir/c.ck: directory '/nonexistent/dir' does not exist");
    EXPECT_FALSE(file_exists(d + "/x.exr"));
}
