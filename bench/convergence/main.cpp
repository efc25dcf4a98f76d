// candela-converge: the speed/accuracy trade in numbers. Renders one scene under several
// configurations, each for a wall-clock budget, one sample per pixel per pass, and after passes 5%
// apart in sample count (and the last) records the error of the running image against a reference:
//   RMSE    sqrt(mean over pixels and channels of (x - r)^2)
//   relMSE  mean of (x - r)^2 / (r^2 + 1e-2)     (the 1e-2 keeps black pixels from dominating)
// Writes PREFIX.csv (config, pass, spp, seconds, rmse, relmse), PREFIX.svg (log-log relMSE against
// time, one line per configuration) and PREFIX.md (per configuration: final error, efficiency
// 1 / (relMSE x time), and the time to reach a common target error).
//
// A configuration is "label:key=value,key=value" with keys sampling (light|bsdf|mis), integrator
// (path|bdpt|ptracer|direct), max_depth, rr_depth (Mitsuba's, as --max-depth and --rr-depth), accel
// (auto|kdtree|hybrid|brute), threads, seed. Biased settings (finite max_depth)
// converge to the wrong image: their error flattens at the bias, and the table marks them.
//
// --depth-bias D1..D2 instead measures the energy lost by truncation: for each max depth (Mitsuba's,
// >= 1) it renders
// the same samples (same seed, so every truncated path is a prefix of the unbounded one) and
// reports the whole-image mean against the unbounded render.
#include <CLI/CLI.hpp>
#include <chrono>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include "core/error.h"
#include "film/film.h"
#include "film/image_io.h"
#include "render/launch.h"
#include "render/renderer.h"

using namespace candela;

namespace {

struct Config {
    std::string label;
    SceneOverrides ov;
    int threads = 0;
    bool biased = false;
};

Config parse_config(const std::string& s, const SceneOverrides& base) {
    Config c;
    c.ov = base;
    size_t colon = s.find(':');
    c.label = s.substr(0, colon);
    if (colon == std::string::npos) return c;
    std::stringstream ss(s.substr(colon + 1));
    std::string kv;
    while (std::getline(ss, kv, ',')) {
        size_t eq = kv.find('=');
        if (eq == std::string::npos) throw Error("bad config item '" + kv + "' (expected key=value)");
        std::string k = kv.substr(0, eq), v = kv.substr(eq + 1);
        if (k == "sampling") c.ov.sampling = parse_sampling_mode(v);
        else if (k == "max_depth") c.ov.max_depth = std::stoi(v);
        else if (k == "rr_depth") c.ov.rr_depth = std::stoi(v);
        else if (k == "accel") c.ov.accel = v;
        else if (k == "threads") c.threads = std::stoi(v);
        else if (k == "seed") c.ov.seed = std::stoull(v);
        else if (k == "integrator") c.ov.integrator = parse_integrator_type(v);
        else throw Error("unknown config key '" + k + "'");
    }
    c.biased = c.ov.max_depth && *c.ov.max_depth >= 0;
    return c;
}

struct Point {
    int spp;
    double seconds, rmse, relmse;
};

void errors(const std::vector<float>& img, const Image& ref, double& rmse, double& relmse) {
    double se = 0, rel = 0;
    for (size_t i = 0; i < img.size(); ++i) {
        double d = double(img[i]) - double(ref.rgb[i]);
        se += d * d;
        rel += d * d / (double(ref.rgb[i]) * double(ref.rgb[i]) + 1e-2);
    }
    rmse = std::sqrt(se / double(img.size()));
    relmse = rel / double(img.size());
}

// Time (seconds) from which a curve stays at or below `target` relMSE, interpolated log-log
// between the last pass above it and the next; negative when it ends above. (Not the first time it
// dips below: a heavy-tailed estimator's early passes can miss its rare large samples and look
// better than they are for a while.)
double time_to(const std::vector<Point>& pts, double target) {
    if (pts.empty() || pts.back().relmse > target) return -1;
    size_t i = pts.size() - 1;
    while (i > 0 && pts[i - 1].relmse <= target) --i;
    if (i == 0) return pts[0].seconds;
    double l0 = std::log(pts[i - 1].relmse), l1 = std::log(pts[i].relmse), lt = std::log(target);
    double f = l1 == l0 ? 1.0 : (lt - l0) / (l1 - l0);
    return std::exp(std::log(pts[i - 1].seconds) + f * (std::log(pts[i].seconds) - std::log(pts[i - 1].seconds)));
}

void write_svg(const std::string& path, const std::string& title, const std::vector<Config>& cfgs,
               const std::vector<std::vector<Point>>& curves) {
    double tmin = 1e30, tmax = 0, emin = 1e30, emax = 0;
    for (const auto& c : curves)
        for (const Point& p : c) {
            if (p.seconds <= 0 || p.relmse <= 0) continue;
            tmin = std::min(tmin, p.seconds), tmax = std::max(tmax, p.seconds);
            emin = std::min(emin, p.relmse), emax = std::max(emax, p.relmse);
        }
    if (tmax <= 0) return;
    // Whole decades on both axes.
    double lt0 = std::floor(std::log10(tmin)), lt1 = std::ceil(std::log10(tmax));
    double le0 = std::floor(std::log10(emin)), le1 = std::ceil(std::log10(emax));
    if (lt1 == lt0) lt1 += 1;
    if (le1 == le0) le1 += 1;
    const double W = 720, H = 480, L = 80, R = 220, T = 40, B = 60;
    auto X = [&](double t) { return L + (std::log10(t) - lt0) / (lt1 - lt0) * (W - L - R); };
    auto Y = [&](double e) { return T + (le1 - std::log10(e)) / (le1 - le0) * (H - T - B); };
    const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                            "#bcbd22", "#17becf"};
    std::ofstream f(path);
    f << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H
      << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' fill='white'/>\n";
    f << "<text x='" << L << "' y='20' font-size='14'>" << title << "</text>\n";
    for (double d = lt0; d <= lt1; ++d) {
        double x = X(std::pow(10, d));
        f << "<line x1='" << x << "' y1='" << T << "' x2='" << x << "' y2='" << H - B << "' stroke='#ddd'/>\n";
        f << "<text x='" << x << "' y='" << H - B + 16 << "' text-anchor='middle'>1e" << d << "</text>\n";
    }
    for (double d = le0; d <= le1; ++d) {
        double y = Y(std::pow(10, d));
        f << "<line x1='" << L << "' y1='" << y << "' x2='" << W - R << "' y2='" << y << "' stroke='#ddd'/>\n";
        f << "<text x='" << L - 6 << "' y='" << y + 4 << "' text-anchor='end'>1e" << d << "</text>\n";
    }
    f << "<rect x='" << L << "' y='" << T << "' width='" << W - L - R << "' height='" << H - T - B
      << "' fill='none' stroke='black'/>\n";
    f << "<text x='" << (L + W - R) / 2 << "' y='" << H - 20 << "' text-anchor='middle'>render time (s)</text>\n";
    f << "<text transform='translate(20," << (T + H - B) / 2 << ") rotate(-90)' text-anchor='middle'>relMSE</text>\n";
    for (size_t i = 0; i < curves.size(); ++i) {
        const char* col = colors[i % 10];
        f << "<polyline fill='none' stroke='" << col << "' stroke-width='1.8'"
          << (cfgs[i].biased ? " stroke-dasharray='6,3'" : "") << " points='";
        for (const Point& p : curves[i])
            if (p.seconds > 0 && p.relmse > 0) f << X(p.seconds) << "," << Y(p.relmse) << " ";
        f << "'/>\n";
        double ly = T + 10 + 18 * double(i);
        f << "<line x1='" << W - R + 10 << "' y1='" << ly << "' x2='" << W - R + 34 << "' y2='" << ly << "' stroke='"
          << col << "' stroke-width='2'" << (cfgs[i].biased ? " stroke-dasharray='6,3'" : "") << "/>\n";
        f << "<text x='" << W - R + 40 << "' y='" << ly + 4 << "'>" << cfgs[i].label
          << (cfgs[i].biased ? " (biased)" : "") << "</text>\n";
    }
    f << "</svg>\n";
}

int run_depth_bias(const std::string& scene_path, const SceneOverrides& base, int d0, int d1, int spp, int batches,
                   int threads) {
    // Per depth: whole-image mean luminance per batch. Same seeds for every depth, so the lost
    // energy (unbounded minus truncated) is estimated from paired samples.
    auto render_means = [&](int depth, std::vector<double>& lum) {
        SceneOverrides ov = base;
        ov.max_depth = depth;
        auto base_scene = prepare_scene(scene_path, ov);
        for (int b = 0; b < batches; ++b) {
            SceneParams p = base_scene->params();
            p.settings.seed = uint64_t(1000 + b);
            auto sc = base_scene->with_params(p);
            Film film(sc->settings.width, sc->settings.height);
            Renderer::render_pass(*sc, film, 0, spp, threads);
            if (film.nonfinite_count()) std::fprintf(stderr, "warning: %llu non-finite samples\n",
                                                     (unsigned long long)film.nonfinite_count());
            double m = 0;
            for (int y = 0; y < film.height(); ++y)
                for (int x = 0; x < film.width(); ++x) m += luminance(film.pixel(x, y));
            lum.push_back(m / double(film.width() * film.height()));
        }
    };
    std::vector<double> inf;
    render_means(-1, inf);
    double mean_inf = 0;
    for (double v : inf) mean_inf += v / double(batches);
    std::printf("| max depth | mean luminance | energy lost | +- (1 s.e.) |\n|---:|---:|---:|---:|\n");
    for (int d = d0; d <= d1; ++d) {
        std::vector<double> lum;
        render_means(d, lum);
        double m = 0, mf = 0, sd = 0;
        for (int b = 0; b < batches; ++b) m += lum[size_t(b)] / batches;
        for (int b = 0; b < batches; ++b) {
            double f = 1.0 - lum[size_t(b)] / inf[size_t(b)];
            mf += f / batches;
        }
        for (int b = 0; b < batches; ++b) {
            double f = 1.0 - lum[size_t(b)] / inf[size_t(b)];
            sd += (f - mf) * (f - mf);
        }
        double se = std::sqrt(sd / (batches - 1) / batches);
        std::printf("| %d | %.5f | %.3f%% | %.3f%% |\n", d, m, 100 * mf, 100 * se);
        std::fflush(stdout);
    }
    std::printf("| unbounded | %.5f | 0 | |\n", mean_inf);
    return 0;
}

}  // namespace

int main(int argc, char** argv) try {
    CLI::App app{"candela-converge: error against a reference over time, per configuration"};
    std::string scene_path, reference, out = "converge", title;
    std::vector<std::string> config_strs;
    double budget = 10;
    double target_arg = 0;
    int width = 0, height = 0, bias_spp = 64, bias_batches = 8, threads = 0;
    std::vector<int> depth_bias;
    app.add_option("scene", scene_path, "Scene file (default: the built-in Cornell box)");
    app.add_option("--reference", reference, "Reference image (.exr or .pfm) of the same size");
    app.add_option("--config,-c", config_strs, "label:key=value,... (sampling, integrator, max_depth, rr_depth, accel, threads, seed)");
    app.add_option("--budget", budget, "Seconds of rendering per configuration");
    app.add_option("--width", width, "Image width (overrides the scene)");
    app.add_option("--height", height, "Image height (overrides the scene)");
    app.add_option("--out", out, "Output prefix: PREFIX.csv, PREFIX.svg, PREFIX.md");
    app.add_option("--title", title, "Plot title");
    app.add_option("--target", target_arg, "relMSE for the time-to-error column (default: the median final relMSE of the unbiased configurations)");
    app.add_option("--depth-bias", depth_bias, "D1 D2: energy lost at max depth D1..D2 (Mitsuba's) against unbounded")->expected(2);
    app.add_option("--bias-spp", bias_spp, "Samples per pixel per batch for --depth-bias");
    app.add_option("--bias-batches", bias_batches, "Batches for --depth-bias (standard errors)");
    app.add_option("--threads", threads, "Threads for --depth-bias");
    CLI11_PARSE(app, argc, argv);

    SceneOverrides base;
    if (width > 0) base.width = width;
    if (height > 0) base.height = height;
    if (!depth_bias.empty())
        return run_depth_bias(scene_path, base, depth_bias[0], depth_bias[1], bias_spp, bias_batches, threads);

    if (reference.empty()) throw Error("--reference is required");
    Image ref = read_linear_image(reference);
    if (!base.width) base.width = ref.width;
    if (!base.height) base.height = ref.height;
    if (*base.width != ref.width || *base.height != ref.height) throw Error("reference size differs from the render size");
    if (config_strs.empty()) config_strs = {"mis:sampling=mis", "light:sampling=light", "bsdf:sampling=bsdf"};
    std::vector<Config> cfgs;
    for (const std::string& s : config_strs) cfgs.push_back(parse_config(s, base));

    std::ofstream csv(out + ".csv");
    csv << "config,pass,spp,seconds,rmse,relmse\n";
    std::vector<std::vector<Point>> curves;
    for (const Config& c : cfgs) {
        auto sc = prepare_scene(scene_path, c.ov);
        Film film(sc->settings.width, sc->settings.height);
        std::vector<Point> pts;
        std::vector<float> img;
        double elapsed = 0;
        uint64_t rays = 0;
        // The error is recorded after passes 5% apart in sample count (and after the last one): the
        // curves are read on log-log axes, where that is smooth, and thousands of passes on a fast
        // machine would otherwise make files of megabytes.
        int next_record = 1;
        for (int pass = 0; elapsed < budget; ++pass) {
            auto t0 = std::chrono::steady_clock::now();
            PassStats ps = Renderer::render_pass(*sc, film, uint32_t(pass), 1, c.threads);
            elapsed += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            rays += ps.rays;
            if (pass + 1 < next_record && elapsed < budget) continue;
            next_record = std::max(pass + 2, int(std::ceil((pass + 1) * 1.05)));
            film.resolve_into(img);  // error computation is outside the timed part
            Point p{pass + 1, elapsed, 0, 0};
            errors(img, ref, p.rmse, p.relmse);
            pts.push_back(p);
            csv << c.label << "," << pass << "," << p.spp << "," << p.seconds << "," << p.rmse << "," << p.relmse << "\n";
        }
        const Point& last = pts.back();
        std::fprintf(stderr, "%-20s %5d spp in %6.2f s (%.2f Msamples/s, %.2f Mrays/s): RMSE %.4g relMSE %.4g%s\n",
                     c.label.c_str(), last.spp, last.seconds,
                     double(last.spp) * sc->settings.width * sc->settings.height / last.seconds * 1e-6,
                     double(rays) / last.seconds * 1e-6, last.rmse, last.relmse,
                     film.nonfinite_count() ? " NON-FINITE SAMPLES" : "");
        curves.push_back(std::move(pts));
    }
    write_svg(out + ".svg", title.empty() ? (scene_path.empty() ? "Cornell box" : scene_path) : title, cfgs, curves);

    // Common target: by default the median final error of the unbiased configurations, which about
    // half of them reach: the column then says who gets there first and how much later the others
    // would (the efficiency column extrapolates that for those that did not).
    double target = target_arg;
    if (!(target > 0)) {
        std::vector<double> finals;
        for (size_t i = 0; i < cfgs.size(); ++i)
            if (!cfgs[i].biased) finals.push_back(curves[i].back().relmse);
        if (finals.empty())
            for (const auto& c : curves) finals.push_back(c.back().relmse);
        std::sort(finals.begin(), finals.end());
        target = finals[(finals.size() - 1) / 2];
    }
    std::ofstream md(out + ".md");
    md << "| configuration | spp | time (s) | RMSE | relMSE | efficiency 1/(relMSE x s) | time to relMSE " << target
       << " (s) |\n|---|---:|---:|---:|---:|---:|---:|\n";
    for (size_t i = 0; i < cfgs.size(); ++i) {
        const Point& p = curves[i].back();
        double tt = time_to(curves[i], target);
        char buf[512];
        std::snprintf(buf, sizeof buf, "| %s%s | %d | %.2f | %.4g | %.4g | %.4g | %s |\n", cfgs[i].label.c_str(),
                      cfgs[i].biased ? " (biased)" : "", p.spp, p.seconds, p.rmse, p.relmse,
                      1.0 / (p.relmse * p.seconds), tt < 0 ? "never" : std::to_string(tt).substr(0, 6).c_str());
        md << buf;
    }
    std::fprintf(stderr, "wrote %s.csv, %s.svg, %s.md\n", out.c_str(), out.c_str(), out.c_str());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "candela-converge: %s\n", e.what());
    return 1;
}
