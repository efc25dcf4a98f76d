#pragma once
// The headless progress line, kept apart from the render loop so that its arithmetic and
// formatting are unit-tested.
#include <cstdint>
#include <string>

namespace candela {

// A duration for people: "42s", "3m07s", "2h05m"; "--" when unknown (negative or not finite).
// Rounded up to the unit shown, so a render with work left never shows "0s".
std::string format_duration(double seconds);

// Seconds until the render ends: the samples left ((total - done) spp over `pixels`) at the
// measured `samples_per_second`, or the time left of `time_limit` (seconds, 0: none) after
// `elapsed` when that is sooner. -1 when unknown (no rate measured yet and no limit).
// `limited` (may be null) says whether the time limit decided it.
double eta_seconds(uint64_t done_spp, uint64_t total_spp, uint64_t pixels, double elapsed,
                   double samples_per_second, double time_limit, bool* limited = nullptr);

// "[=========>          ] 12/64 spp  1.25 Msamples/s  3.4s  ETA 14s", with " (time limit)" after
// the ETA when the limit ends the render first. No carriage return or newline.
std::string progress_line(uint64_t done_spp, uint64_t total_spp, uint64_t pixels, double elapsed,
                          double samples_per_second, double time_limit);

}  // namespace candela
