#pragma once
// What each integrator reads of the render settings and which render features it takes part in:
// ONE table, so that what the user may set and what changes the image cannot drift apart. The
// command line refuses an option the integrator does not read (render/launch.cpp), the loader
// notes a scene-file value it ignores, the headless and MPI runs refuse the features it lacks, and
// the viewer greys out its controls (viewer/window_panel.cpp). Features to come (participating
// media, path guiding) add their field here, false where they are not supported.
//
// (Depth, integrator/depth.h: Mitsuba's max_depth and rr_depth everywhere users see them.)
//
// The table tells the truth: Caps.TableTellsTheTruth (tests/test_caps.cpp) renders a small scene
// with two values of every setting for every integrator and checks that an unread setting gives
// the same image bit for bit and a read one a different image.
#include "integrator/depth.h"
#include "integrator/desc.h"

namespace candela {

struct IntegratorCaps {
    // Settings the image depends on (RenderSettings).
    bool sampling;       // sampling: light | bsdf | mis (the path tracer's emission strategies)
    bool sampler;        // sampler: where the random numbers come from (and sample_count's strata)
    bool filter;         // filter: the film's reconstruction filter
    bool max_depth;      // max_depth
    bool rr_depth;       // rr_depth
    bool hide_emitters;  // integrator.hide_emitters
    // Features of the render around the integrator.
    bool mpi;         // one render across MPI ranks, the one-process image bit for bit (docs/distributed.md)
    bool adaptive;    // --target-error: per-pixel stopping (camera samples per pixel)
    bool aovs;        // the aov and moment wrappers (values of the camera ray's first hit)
    bool checkpoint;  // --checkpoint, --resume
    bool time_limit;  // --time-limit cuts the pass in flight
    bool media;       // participating media (medium/medium.h); the others refuse a scene with media
    bool guiding;     // path guiding (none yet)
};

// clang-format off
//                                     sampling sampler filter max_d  rr_d   hide   mpi    adapt  aovs   ckpt   time   media  guide
inline constexpr IntegratorCaps kPathCaps    {true,   true,   true,  true,  true,  true,  true,  true,  true,  true,  true,  false, false};
// volpath: the path tracer's settings and features (it is the path tracer in a scene without media).
inline constexpr IntegratorCaps kVolpathCaps {true,   true,   true,  true,  true,  true,  true,  true,  true,  true,  true,  true,  false};
// direct: emitter_samples and bsdf_samples instead of the sampling mode; one scattering event.
inline constexpr IntegratorCaps kDirectCaps  {false,  true,   true,  false, false, true,  true,  true,  true,  true,  true,  false, false};
// ptracer: its splats go through the film's filter (film/splat_filter.h).
inline constexpr IntegratorCaps kPtracerCaps {false,  true,   true,  true,  true,  true,  true,  false, false, true,  true,  false, false};
// bdpt: every (s, t) strategy weighted by MIS, whatever the sampling mode; t = 1 splats filtered.
inline constexpr IntegratorCaps kBdptCaps    {false,  true,   true,  true,  true,  true,  true,  false, false, true,  true,  false, false};
// pssmlt: the path tracer (with its sampling mode) on the chains' own primary samples, splats
// through the film's filter.
// No MPI: the chains carry state from one sample index to the next and the film is scaled by a b
// refined as they run, so sample indices cannot go to ranks independently (docs/distributed.md).
inline constexpr IntegratorCaps kPssmltCaps  {true,   false,  true,  true,  true,  true,  false, false, false, true,  true,  false, false};
// mmlt: BDPT's strategies on the chains' own primary samples, filtered splats; no MPI, as pssmlt.
inline constexpr IntegratorCaps kMmltCaps    {false,  false,  true,  true,  true,  true,  false, false, false, true,  true,  false, false};
// clang-format on

constexpr const IntegratorCaps& reads(IntegratorType t) {
    switch (t) {
        case IntegratorType::Direct: return kDirectCaps;
        case IntegratorType::Ptracer: return kPtracerCaps;
        case IntegratorType::Bdpt: return kBdptCaps;
        case IntegratorType::Pssmlt: return kPssmltCaps;
        case IntegratorType::Mmlt: return kMmltCaps;
        case IntegratorType::Volpath: return kVolpathCaps;
        case IntegratorType::Path: break;
    }
    return kPathCaps;
}

// Every integrator, in the command line's order, and its name there (path, direct, ...).
inline constexpr IntegratorType kIntegratorTypes[] = {IntegratorType::Path, IntegratorType::Volpath, IntegratorType::Direct,
                                                      IntegratorType::Ptracer, IntegratorType::Bdpt,
                                                      IntegratorType::Pssmlt, IntegratorType::Mmlt};

}  // namespace candela
