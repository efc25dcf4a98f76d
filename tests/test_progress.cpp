// The headless progress line (core/progress.h): the ETA from the measured rate and the samples
// left, or from the time limit when that comes first, and how durations are written.
#include <gtest/gtest.h>
#include <cmath>
#include <limits>
#include "core/progress.h"

using namespace candela;

TEST(Progress, FormatDuration) {
    EXPECT_EQ(format_duration(0), "0s");
    EXPECT_EQ(format_duration(0.2), "1s");  // rounded up: work left never shows as 0s
    EXPECT_EQ(format_duration(42), "42s");
    EXPECT_EQ(format_duration(59.5), "1m00s");
    EXPECT_EQ(format_duration(187), "3m07s");
    EXPECT_EQ(format_duration(3599), "59m59s");
    EXPECT_EQ(format_duration(3600), "1h00m");
    EXPECT_EQ(format_duration(7322), "2h03m");
    EXPECT_EQ(format_duration(100 * 3600.0), "100h00m");
    EXPECT_EQ(format_duration(-1), "--");
    EXPECT_EQ(format_duration(std::numeric_limits<double>::infinity()), "--");
    EXPECT_EQ(format_duration(std::nan("")), "--");
}

TEST(Progress, EtaFromRateAndTimeLimit) {
    bool limited = true;
    // 48 spp left over 100 pixels at 1000 samples/s.
    EXPECT_DOUBLE_EQ(eta_seconds(16, 64, 100, 1.6, 1000, 0, &limited), 4.8);
    EXPECT_FALSE(limited);
    // A limit further away than the samples left does not matter...
    EXPECT_DOUBLE_EQ(eta_seconds(16, 64, 100, 1.6, 1000, 60, &limited), 4.8);
    EXPECT_FALSE(limited);
    // ...a nearer one decides.
    EXPECT_DOUBLE_EQ(eta_seconds(16, 64, 100, 8, 1000, 10, &limited), 2);
    EXPECT_TRUE(limited);
    EXPECT_DOUBLE_EQ(eta_seconds(16, 64, 100, 12, 1000, 10, &limited), 0);  // past the limit
    // No rate measured yet: unknown, unless there is a limit.
    EXPECT_LT(eta_seconds(0, 64, 100, 0, 0, 0, &limited), 0);
    EXPECT_DOUBLE_EQ(eta_seconds(0, 64, 100, 0, 0, 30, &limited), 30);
    EXPECT_TRUE(limited);
    EXPECT_DOUBLE_EQ(eta_seconds(64, 64, 100, 5, 1000, 0), 0);  // done
}

TEST(Progress, Line) {
    EXPECT_EQ(progress_line(16, 64, 100, 1.6, 1000, 0),
              "[=======>                      ] 16/64 spp  0.00 Msamples/s  1.6s  ETA 5s");
    EXPECT_EQ(progress_line(1, 1000, 512 * 512, 8.04, 2.5e6, 10),
              "[>                             ] 1/1000 spp  2.50 Msamples/s  8.0s  ETA 2s (time limit)");
    EXPECT_EQ(progress_line(64, 64, 100, 3.25, 2e6, 0),
              "[==============================] 64/64 spp  2.00 Msamples/s  3.2s  ETA 0s");
    EXPECT_EQ(progress_line(0, 64, 100, 0, 0, 0),
              "[>                             ] 0/64 spp  0.00 Msamples/s  0.0s  ETA --");
}
