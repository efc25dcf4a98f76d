// candela's command line: parses options, then runs the viewer (when there is a display and no
// --out) or a headless render that writes an image.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include "app/headless_run.h"
#include "core/error.h"
#ifdef CANDELA_HAS_MPI
#include "app/mpi_run.h"
#endif
#ifdef CANDELA_HAS_VIEWER
#include "viewer/viewer.h"
#endif

using namespace candela;

int main(int argc, char** argv) {
    CLI::App app{"candela: an interactive, progressive path tracer for the CPU.\n"
                 "With no SCENE it renders the built-in Cornell box. With --out it renders headless;\n"
                 "otherwise it opens the viewer when a display is available.\n"
                 "Under mpirun or srun (built with MPI) the ranks share one headless render; rank 0 writes\n"
                 "the image, which equals the one-process image bit for bit (docs/distributed.md)."};
    HeadlessOptions opt;
    SceneOverrides& ov = opt.overrides;
    std::vector<std::string> defines;
    int width = 0, height = 0, max_depth = -2, rr_depth = -2;
    uint64_t seed = 0;
    std::string sampling, sampler_name;
    int sample_count = 0;
    app.add_option("scene", opt.scene, "Scene file: Mitsuba 3 XML subset (.xml) or OBJ+MTL (.obj)");
    app.add_option("--frames", opt.frames, "Passes to render (default: the scene's sample_count / spp-per-frame)")
        ->check(CLI::Range(1, 1 << 30));
    app.add_option("--spp-per-frame", opt.spp_per_frame, "Samples per pixel in each pass")->check(CLI::Range(1, 1 << 20));
    app.add_option("--out", opt.out, "Write the image and exit: .png (sRGB through the display shaders), .exr or .pfm (linear)");
    auto* w_opt = app.add_option("--width", width, "Image width in pixels (overrides the scene)");
    auto* h_opt = app.add_option("--height", height, "Image height in pixels (overrides the scene)");
    auto* d_opt = app.add_option("--max-depth", max_depth,
                                 "Mitsuba's max_depth, path segments: 1 emitters only, 2 direct light, -1 unbounded\n"
                                 "(default; overrides the scene). A finite depth is biased: it drops longer paths");
    auto* r_opt = app.add_option("--rr-depth", rr_depth,
                                 "Mitsuba's rr_depth (>= 1, default 5): the path vertex from which Russian roulette\n"
                                 "may end a path (overrides the scene)");
    auto* s_opt = app.add_option("--seed", seed, "Sampler seed (overrides the scene)");
    app.add_option("--threads", opt.threads, "Render threads (default: all cores)")->check(CLI::Range(0, 1024));
    app.add_option("--time-limit", opt.time_limit, "Stop after this many seconds (the image has the passes done by then)")
        ->check(CLI::PositiveNumber);
    auto* te_opt = app.add_option("--target-error", opt.target_error,
                                  "Headless: adaptive sampling; stop each pixel once the estimated relative error of\n"
                                  "its luminance is below E, and the render when all have stopped (the scene's\n"
                                  "sample count and --time-limit are the other bounds; docs/adaptive.md)")
                      ->type_name("E")
                      ->check(CLI::PositiveNumber);
    app.add_option("--adaptive-min-spp", opt.adaptive_min_spp, "Samples a pixel takes before it may stop (default 16)")
        ->check(CLI::Range(4, 1 << 24))
        ->needs(te_opt);
    app.add_option("--exposure", opt.display.exposure, "Exposure in stops for PNG output and the viewer");
    app.add_option("-D", defines, "Scene parameter name=value (overrides <default> in XML scenes)")->allow_extra_args(false);
    std::string integrator;
    auto* i_opt = app.add_option("--integrator", integrator,
                                 "Integrator: path (the path tracer), volpath and volpathmis (participating media,\n"
                                 "docs/media.md), direct (direct lighting), ptracer (light tracing: light paths\n"
                                 "splatted through the camera, Mitsuba's ptracer), bdpt (bidirectional path tracing,\n"
                                 "every (s, t) strategy, MIS) or pssmlt (primary-sample-space\n"
                                 "Metropolis over the path tracer) or mmlt (multiplexed Metropolis over BDPT; for both\n"
                                 "the sample count is mutations per pixel, docs/mlt.md);\n"
                                 "replaces the scene's <integrator> type, keeping its depths and hide_emitters")
                      ->check(CLI::IsMember({"path", "volpath", "volpathmis", "direct", "ptracer", "bdpt", "pssmlt", "mmlt"}));
    auto* m_opt = app.add_option("--sampling", sampling,
                                 "The path tracer's emission sampling (path, pssmlt): light, bsdf or mis (default mis)");
    auto* sampler_opt = app.add_option("--sampler", sampler_name,
                                       "Sampler (overrides the scene): independent, stratified, multijitter, ldsampler,\n"
                                       "sobol (Owen-scrambled per pixel), zsobol (Z-order blue noise) or orthogonal\n"
                                       "(orthogonal arrays, p^2 spp); docs/samplers.md. Not for pssmlt and mmlt");
    auto* count_opt = app.add_option("--sample-count", sample_count,
                                     "The scene's sample_count (overrides it): the default total spp, and what the\n"
                                     "stratified samplers stratify over (rounded up as the sampler needs)")
                          ->check(CLI::Range(1, 1 << 24));
    app.add_option("--accel", ov.accel, "Ray accelerator: auto, kdtree, hybrid, brute (embree when built with it)");
    app.add_flag("--quiet,-q", opt.quiet, "No progress or summary output");
    app.add_option("--bdpt-strategies", opt.bdpt_strategies,
                   "After a headless render, write one EXR per BDPT strategy (s, t) into this directory,\n"
                   "weighted and unweighted (pbrt's visualizestrategies), path lengths up to max depth");
    auto* ck_opt = app.add_option("--checkpoint", opt.checkpoint,
                                  "Headless: save the render's state to FILE (atomically) periodically, at the end and "
                                  "when stopped by a signal")
                       ->type_name("FILE");
    app.add_option("--checkpoint-every", opt.checkpoint_every,
                   "Seconds between checkpoints (default 60; 0: after every pass)")
        ->check(CLI::NonNegativeNumber)
        ->needs(ck_opt);
    auto* resume_opt = app.add_option("--resume", opt.resume,
                                      "Headless: continue the render saved in checkpoint FILE (same scene and options; "
                                      "--frames is the total)")
                           ->type_name("FILE");
    app.add_flag("--denoise", opt.denoise,
                 "Denoise with Intel Open Image Denoise (docs/denoising.md): headless, --out gets the denoised\n"
                 "image and the raw beauty and the auxiliaries (albedo, normal) are layers of the EXR (--out\n"
                 "itself, or OUT.layers.exr beside a .png or .pfm); in the viewer, the denoised view is on at start.\n"
                 "Biased: it trades noise for blur");
    std::string denoise_quality;
    auto* dq_opt = app.add_option("--denoise-quality", denoise_quality,
                                  "fast, balanced or high (OIDN's quality modes; default high headless, balanced "
                                  "in the viewer)")
                       ->check(CLI::IsMember({"fast", "balanced", "high"}));
    bool aov_layers = false;
    app.add_flag("--aov", aov_layers,
                 "Render the denoiser's auxiliary images (albedo and normal of the first non-specular surface)\n"
                 "and write them as layers albedo.R/G/B and normal.X/Y/Z of an .exr output");
    std::string priority;
    auto* prio_opt = app.add_option("--render-priority", priority,
                                    "Viewer: CPU priority of the render threads: idle (default for a window: the "
                                    "window and other programs first), low (nice 19) or normal (default for "
                                    "--screenshot-after)")
                         ->check(CLI::IsMember({"normal", "low", "idle"}));
    // --screenshot-after N FILE: one option with two values (a pair: CLI11 checks both types).
    std::pair<int, std::string> shot_args{0, ""};
    auto* shot = app.add_option("--screenshot-after", shot_args,
                                "Viewer: render N passes, save the window (panel included) to the PNG FILE, exit")
                     ->type_name("N FILE");

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "candela: %s (see --help)\n", e.what());
        return 2;
    }

    try {
        for (const std::string& d : defines) {
            size_t eq = d.find('=');
            if (eq == std::string::npos || eq == 0) throw Error("-D expects name=value, got '" + d + "'");
            ov.defines.emplace_back(d.substr(0, eq), d.substr(eq + 1));
        }
        if (*w_opt) ov.width = width;
        if (*h_opt) ov.height = height;
        if (*d_opt) ov.max_depth = max_depth;
        if (*r_opt) ov.rr_depth = rr_depth;
        if (*s_opt) ov.seed = seed;
        if (*m_opt) ov.sampling = parse_sampling_mode(sampling);
        if (*sampler_opt) ov.sampler = parse_sampler_name(sampler_name);
        if (*count_opt) ov.sample_count = sample_count;
        if (*i_opt) {
            ov.integrator = parse_integrator_type(integrator);
            ov.spectral_mis = integrator == "volpathmis";
        }
        if (*dq_opt) parse_denoise_quality(denoise_quality, opt.denoise_quality);
        ov.denoise_aux = opt.denoise || aov_layers;
        ov.denoise_box_filter = opt.denoise;

#ifdef CANDELA_HAS_MPI
        // Under mpirun or srun every rank renders a share of one headless render.
        if (launched_by_mpi()) return run_headless_mpi(opt);
#endif
        bool has_display = std::getenv("DISPLAY") || std::getenv("WAYLAND_DISPLAY");
        std::string why_headless = has_display ? "built without the viewer" : "no display";
#ifdef CANDELA_HAS_VIEWER
        if (opt.out.empty() && (has_display || *shot)) {
            if (*ck_opt || *resume_opt) throw Error("--checkpoint and --resume are for headless renders: give --out");
            if (*te_opt) throw Error("--target-error is for headless renders: give --out (the viewer has a target error in its Render panel)");
            ViewerOptions vo;
            vo.scene = opt.scene;
            vo.overrides = ov;
            vo.threads = opt.threads;
            vo.display = opt.display;
            vo.spp_per_frame = opt.spp_per_frame;
            vo.denoise = opt.denoise;
            vo.denoise_quality = *dq_opt ? opt.denoise_quality : DenoiseQuality::Balanced;
            vo.screenshot_after = shot_args.first;
            vo.screenshot = shot_args.second;
            if (*prio_opt) vo.render_priority = parse_render_priority(priority);
            if (*shot && vo.screenshot_after < 1) throw Error("--screenshot-after expects N >= 1 passes");
            try {
                return run_viewer(vo);
            } catch (const DisplayUnavailable& e) {
                if (*shot) throw;  // a screenshot of the window needs the window
                // DISPLAY is set but unusable (no server, a refused connection, no GL): as with none.
                why_headless = std::string("cannot use the display (") + e.what() + ")";
            }
        }
#else
        (void)shot;
        (void)resume_opt;
        (void)te_opt;
        (void)prio_opt;
#endif
        if (opt.out.empty()) {
            opt.out = "candela.png";
            if (!opt.quiet)
                std::fprintf(stderr, "candela: %s; rendering headless to %s\n", why_headless.c_str(), opt.out.c_str());
        }
        return run_headless(opt);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "candela: %s (see --help)\n", e.what());
        return 2;
    } catch (const Error& e) {
        std::fprintf(stderr, "candela: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "candela: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "candela: internal error: %s\n", e.what());
        return 1;
    }
}
