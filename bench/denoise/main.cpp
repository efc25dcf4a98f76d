// candela-denoise: the trade of denoising in numbers (docs/denoising.md).
//
//   candela-denoise trade [SCENE] --res W H --ref-spp N [--images DIR] [--box-filter]
// renders a reference of N spp (seed 1, its own samples), then the scene with seed 0 one sample
// per pixel per pass, and at 1, 4, 16, 64 and 256 spp denoises the running film (high quality,
// albedo and normal prefiltered) and prints the relMSE of the raw and the denoised image against
// the reference, as a Markdown table row per spp:
//   relMSE = mean over pixels and channels of (x - r)^2 / (r^2 + 1e-2)
// (candela-converge's definition). With --images it writes the raw and denoised images at each spp
// as PNGs (sRGB through the display shaders, as --out does) into DIR. --box-filter renders with the
// box filter, as --denoise does; without it the scene's own filter is kept (to show what a wider
// one does to the denoiser).
//
//   candela-denoise time --res W H [--repeat K]
// times Denoiser::denoise on the built-in Cornell box at W x H (4 spp, with auxiliaries) for each
// quality: the first call (device and filters built), the mean wall time of the K calls after it,
// and their CPU time (all threads), which depends less on what else the machine runs.
#include <CLI/CLI.hpp>
#include <time.h>
#include <chrono>
#include <cstdio>
#include "core/error.h"
#include "denoise/denoiser.h"
#include "film/image_io.h"
#include "headless/headless.h"
#include "integrator/integrator.h"
#include "render/launch.h"
#include "render/renderer.h"

using namespace candela;

namespace {

double rel_mse(const std::vector<float>& x, const std::vector<float>& r) {
    double s = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        const double d = double(x[i]) - double(r[i]);
        s += d * d / (double(r[i]) * double(r[i]) + 1e-2);
    }
    return s / double(x.size());
}

// CPU seconds of the whole process (all threads): what a denoise costs whatever else the machine runs.
double cpu_now() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

bool g_box = false;  // --box-filter

std::shared_ptr<const Scene> load(const std::string& path, int w, int h, uint64_t seed) {
    SceneOverrides ov;
    ov.denoise_box_filter = g_box;
    ov.width = w;
    ov.height = h;
    ov.seed = seed;
    ov.denoise_aux = true;
    return prepare_scene(path, ov);
}

void progress(const char* what, int done, int total) {
    std::fprintf(stderr, "\r  %s %d/%d spp ", what, done, total);
    std::fflush(stderr);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"candela-denoise: relMSE of raw and denoised images against a reference, and denoise times"};
    app.require_subcommand(1);
    std::string scene_path, images;
    std::vector<int> res{256, 256};
    int ref_spp = 4096, repeat = 5;
    auto* trade = app.add_subcommand("trade", "relMSE of raw and denoised images at 1, 4, 16, 64, 256 spp");
    trade->add_option("scene", scene_path, "Scene (default: the built-in Cornell box)");
    trade->add_option("--res", res, "Image size W H")->expected(2);
    trade->add_option("--ref-spp", ref_spp, "Samples per pixel of the reference");
    trade->add_option("--images", images, "Write the raw and denoised PNGs here");
    trade->add_flag("--box-filter", g_box, "Render with the box filter, as --denoise does (else the scene's filter)");
    auto* timing = app.add_subcommand("time", "Time per denoise at one size, per quality");
    timing->add_option("--res", res, "Image size W H")->expected(2);
    timing->add_option("--repeat", repeat, "Timed calls after the first");
    CLI11_PARSE(app, argc, argv);
    try {
        const std::string why = denoiser_unavailable_reason();
        if (!why.empty()) throw Error(why);
        if (*trade) {
            auto ref_scene = load(scene_path, res[0], res[1], 1);
            Film ref(res[0], res[1]);
            configure_film(ref, ref_scene->settings);
            for (int s = 0; s < ref_spp; s += 16) {
                Renderer::render_pass(*ref_scene, ref, uint32_t(s), 16, 0);
                progress("reference", s + 16, ref_spp);
            }
            const std::vector<float> r = ref.resolve();
            auto scene = load(scene_path, res[0], res[1], 0);
            Film film(res[0], res[1]);
            configure_film(film, scene->settings);
            Denoiser dn(DenoiseQuality::High);
            std::vector<float> out;
            std::printf("\n| scene | spp | relMSE raw | relMSE denoised | raw / denoised |\n|---|---:|---:|---:|---:|\n");
            const std::string name = scene_path.empty() ? "cornell (built-in)" : scene_path;
            int done = 0;
            for (int spp : {1, 4, 16, 64, 256}) {
                Renderer::render_pass(*scene, film, uint32_t(done), spp - done, 0);
                done = spp;
                dn.denoise(denoise_inputs(film, scene->settings.integrator.aovs), out);
                const std::vector<float> raw = film.resolve();
                const double er = rel_mse(raw, r), ed = rel_mse(out, r);
                std::printf("| %s | %d | %.4g | %.4g | %.2g |\n", name.c_str(), spp, er, ed, er / ed);
                std::fflush(stdout);
                if (!images.empty()) {
                    DisplaySettings ds;
                    const std::string base = images + "/" + std::to_string(spp) + "spp";
                    write_png_headless(base + "_raw.png", Image{res[0], res[1], raw, {}}, ds);
                    write_png_headless(base + "_denoised.png", Image{res[0], res[1], out, {}}, ds);
                }
            }
            if (!images.empty()) write_png_headless(images + "/reference.png", Image{res[0], res[1], r, {}}, DisplaySettings{});
        } else {
            auto scene = load("", res[0], res[1], 0);
            Film film(res[0], res[1]);
            configure_film(film, scene->settings);
            Renderer::render_pass(*scene, film, 0, 4, 0);
            const DenoiseImages in = denoise_inputs(film, scene->settings.integrator.aovs);
            std::printf("| size | quality | first call (s) | per denoise (s, mean of %d) | CPU per denoise (s, all threads) |\n"
                        "|---|---|---:|---:|---:|\n", repeat);
            for (DenoiseQuality q : {DenoiseQuality::Fast, DenoiseQuality::Balanced, DenoiseQuality::High}) {
                Denoiser dn(q);
                std::vector<float> out;
                double t0 = now();
                dn.denoise(in, out);
                const double first = now() - t0;
                t0 = now();
                const double c0 = cpu_now();
                for (int k = 0; k < repeat; ++k) dn.denoise(in, out);
                const double n = double(std::max(1, repeat));
                std::printf("| %dx%d | %s | %.3f | %.3f | %.3f |\n", res[0], res[1], denoise_quality_name(q), first,
                            (now() - t0) / n, (cpu_now() - c0) / n);
                std::fflush(stdout);
            }
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "candela-denoise: %s\n", e.what());
        return 1;
    }
    return 0;
}
