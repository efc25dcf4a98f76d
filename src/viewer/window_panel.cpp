// The panel: render control and statistics, integrator, camera and display, materials, lights,
// and what is under a clicked pixel.
#include <imgui.h>
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <iterator>
#include <cstdio>
#include <numeric>
#include <thread>
#include "integrator/caps.h"
#include "integrator/mlt/pssmlt.h"
#include "viewer/panel.h"
#include "viewer/window.h"

namespace candela {

namespace {

// Resamples the convergence history onto `n` points uniform in time (the value in force at each
// time), so that the plot's x axis is time, not pass index. log10, for a curve that falls ~1/sqrt(t).
std::vector<float> resample_log(const std::vector<float>& v, const std::vector<float>& t, int n) {
    std::vector<float> out;
    if (v.empty()) return out;
    float t0 = t.front(), t1 = std::max(t.back(), t0 + 1e-6f);
    size_t j = 0;
    for (int i = 0; i < n; ++i) {
        float ti = t0 + (t1 - t0) * float(i) / float(n - 1);
        while (j + 1 < t.size() && t[j + 1] <= ti) ++j;
        out.push_back(std::log10(std::max(v[j], 1e-6f)));
    }
    return out;
}

}  // namespace

void Viewer::panel() {
    const float win_w = float(fb_w_) / fb_scale_, win_h = float(fb_h_) / fb_scale_;
    ImGui::SetNextWindowPos(ImVec2(win_w - std::min(kPanelWidth, win_w), 0.f), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(std::min(kPanelWidth, win_w), win_h), ImGuiCond_Always);
    ImGui::Begin("candela", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                                         ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoSavedSettings);
    ImGui::PushItemWidth(-110.f);
    const SessionStats& stats = fe_->stats();
    ImGui::TextUnformatted(fe_->scene().source.c_str());
    ImGui::TextDisabled("%dx%d, %zu triangles, %zu lights", fe_->params().settings.width, fe_->params().settings.height,
                        fe_->scene().mesh.triangle_count(), fe_->params().emitters.size());
    if (!fe_->status().empty()) {
        if (fe_->status_is_error()) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.f, 0.4f, 0.35f, 1.f));
        ImGui::TextWrapped("%s", fe_->status().c_str());
        if (fe_->status_is_error()) ImGui::PopStyleColor();
    }
    if (fe_->loading()) ImGui::TextDisabled("loading %s ...", fe_->loading_path().c_str());

    // ---- render control and statistics (none of these widgets changes the image)
    if (ImGui::CollapsingHeader("Render", ImGuiTreeNodeFlags_DefaultOpen)) {
        bool paused = fe_->session().paused();
        if (ImGui::Button(paused ? "Resume" : "Pause", ImVec2(80, 0))) fe_->session().set_paused(!paused);
        ImGui::SameLine();
        if (ImGui::Button("Reset", ImVec2(80, 0))) {
            fe_->restart(viewer_now());
        }
        ImGui::SameLine();
        const bool done = stats.idle || (opt_.screenshot_after > 0 && stats.passes >= opt_.screenshot_after);
        ImGui::TextDisabled(paused ? "paused" : stats.preview ? "preview" : stats.target_reached ? "target error reached" : done ? "done" : "rendering");
        ImGui::Text("%.0f spp  (%d passes)", stats.spp, stats.passes);
        ImGui::Text("%.2f s   %.3f Msamples/s   %.3f Mrays/s", stats.elapsed, stats.msamples_per_s,
                    stats.mrays_per_s);
        if (stats.splats > 0)
            ImGui::Text("splats  %llu   %.3f Msplats/s", (unsigned long long)stats.splats, stats.msplats_per_s);
        if (stats.nonfinite > 0) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.f, 0.4f, 0.35f, 1.f));
        ImGui::Text("NaN/Inf samples: %llu", (unsigned long long)stats.nonfinite);
        if (stats.nonfinite > 0) ImGui::PopStyleColor();
        // The denoised view: display only (the render goes on, the toggle never restarts it).
        if (denoise_unavailable_.empty()) {
            bool dn = fe_->denoise_view();
            int q = int(fe_->denoise_quality());
            bool changed = ImGui::Checkbox("Denoised", &dn);
            ImGui::SameLine();
            ImGui::SetNextItemWidth(110.f);
            changed |= ImGui::Combo("##dnq", &q, "fast\0balanced\0high\0");
            if (changed) fe_->set_denoise_view(dn, DenoiseQuality(q));
            if (ImGui::IsItemHovered())
                ImGui::SetTooltip("Open Image Denoise's quality mode (docs/denoising.md). Started with --denoise, the\n"
                                  "render adds albedo and normal guides (box filter); otherwise the beauty alone is denoised.");
            if (dn) {
                const std::string err = fe_->session().denoise_error();
                if (!err.empty()) ImGui::TextColored(ImVec4(1.f, 0.4f, 0.35f, 1.f), "%s", err.c_str());
                else if (fe_->showing_denoised())
                    ImGui::TextDisabled("denoised at %d passes in %.0f ms", fe_->image().passes,
                                        fe_->session().denoise_seconds() * 1e3);
                else ImGui::TextDisabled("raw film (denoising)");
            }
        } else {
            ImGui::TextDisabled("no denoiser: %s", denoise_unavailable_.c_str());
        }
        std::vector<float> curve = resample_log(stats.change, stats.change_time, 120);
        char overlay[64];
        std::snprintf(overlay, sizeof overlay, "rel. change/pass %.2e",
                      stats.change.empty() ? 0.0 : double(stats.change.back()));
        ImGui::PlotLines("##convergence", curve.empty() ? nullptr : curve.data(), int(curve.size()), 0, overlay, FLT_MAX,
                         FLT_MAX, ImVec2(ImGui::GetContentRegionAvail().x, 56.f));
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Mean relative change of the image per pass, log10, over render time.\n"
                              "Monte Carlo noise falls as 1/sqrt(spp): the curve flattens as it converges.");
        std::vector<float> est = resample_log(stats.estimates, stats.estimate_time, 120);
        std::snprintf(overlay, sizeof overlay, stats.estimate >= 0 ? "est. error %.2e" : "est. error: 2 passes", stats.estimate);
        ImGui::PlotLines("##estimate", est.empty() ? nullptr : est.data(), int(est.size()), 0, overlay, FLT_MAX, FLT_MAX,
                         ImVec2(ImGui::GetContentRegionAvail().x, 56.f));
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Estimated error of the image, log10, over render time: the RMS over pixels of the\n"
                              "relative standard error, from the difference of the even and the odd passes\n"
                              "(unbiased with the independent sampler; docs/adaptive.md).");
        float target = float(fe_->session().target_error());
        if (ImGui::InputFloat("target error", &target, 0.f, 0.f, "%.4f")) fe_->session().set_target_error(std::max(0.f, target));
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Full passes stop once the estimated error is below this (0: never). No restart.");
        int max_threads = int(std::max(1u, std::thread::hardware_concurrency()));
        if (ImGui::SliderInt("threads", &threads_, 1, max_threads)) fe_->session().set_threads(threads_);
        ImGui::InputText("##png", png_path_, sizeof png_path_);
        ImGui::SameLine();
        if (ImGui::Button("Save PNG")) save_png(png_path_);
        ImGui::InputText("##exr", exr_path_, sizeof exr_path_);
        ImGui::SameLine();
        if (ImGui::Button("Save EXR")) fe_->save_exr(exr_path_);
    }

    // ---- what the image depends on: every change restarts the render
    if (ImGui::CollapsingHeader("Integrator", ImGuiTreeNodeFlags_DefaultOpen)) {
        RenderSettings& st = fe_->params().settings;
        // Switches the running render: the next pass makes the new integrator (render_pass).
        // The aov and moment wrappers need camera rays: only the integrators that take them
        // (integrator/caps.h) are offered with them.
        const bool wrapped = !st.integrator.aovs.empty();
        static const char* const kLabels[] = {"path", "volpath (media)", "direct", "ptracer (light tracing)", "bdpt (bidirectional)",
                                              "pssmlt (Metropolis)", "mmlt (multiplexed Metropolis)"};
        static_assert(std::size(kLabels) == std::size(kIntegratorTypes));
        if (ImGui::BeginCombo("integrator", kLabels[std::find(std::begin(kIntegratorTypes), std::end(kIntegratorTypes),
                                                              st.integrator.type) - std::begin(kIntegratorTypes)])) {
            for (size_t k = 0; k < std::size(kIntegratorTypes); ++k) {
                const IntegratorType t = kIntegratorTypes[k];
                if (wrapped && !reads(t).aovs) continue;
                if (ImGui::Selectable(kLabels[k], t == st.integrator.type) && t != st.integrator.type) {
                    st.integrator.type = t;
                    fe_->params_changed(viewer_now());
                }
            }
            ImGui::EndCombo();
        }
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("path: path tracing with next-event estimation and MIS\n"
                              "direct: direct lighting only (Mitsuba's direct)\n"
                              "ptracer: light tracing, every light-path vertex splatted through the camera\n"
                              "bdpt: bidirectional path tracing, every (s, t) strategy weighted by MIS\n"
                              "pssmlt: primary-sample-space Metropolis over the path tracer (docs/mlt.md)\n"
                              "mmlt: multiplexed Metropolis over BDPT's strategies, chains per path length");
        if (st.integrator.type == IntegratorType::Pssmlt || st.integrator.type == IntegratorType::Mmlt) {
            // The chains as they run: acceptance of small and large steps, and b with its error.
            const MltStats ms = pssmlt_stats();
            if (ms.valid) {
                auto rate = [](uint64_t a, uint64_t n) { return n ? 100.0 * double(a) / double(n) : 0.0; };
                ImGui::Text("MLT: accept small %.1f%%, large %.1f%%", rate(ms.small_accepted, ms.small_proposed),
                            rate(ms.large_accepted, ms.large_proposed));
                ImGui::Text("b %.4g +- %.2g (%.2f%%)", ms.b, ms.b_std_error, ms.b > 0 ? 100.0 * ms.b_std_error / ms.b : 0.0);
                if (ImGui::IsItemHovered())
                    ImGui::SetTooltip("b: the image's mean luminance, which scales it: the bootstrap (%llu paths, %.2f s) pooled\n"
                                      "with the %llu large steps so far.  %llu mutations over %zu chains.",
                                      (unsigned long long)ms.bootstrap_paths, ms.bootstrap_seconds,
                                      (unsigned long long)ms.large_steps, (unsigned long long)ms.mutations,
                                      size_t(std::accumulate(ms.chains_per_depth.begin(), ms.chains_per_depth.end(), 0)));
            }
        }
        // What the integrator does not read is greyed out (integrator/caps.h): it cannot change,
        // so it cannot restart a render for nothing.
        const IntegratorCaps& caps = reads(st.integrator.type);
        const char* unread = "not read by this integrator";
        ImGui::BeginDisabled(!caps.sampling);
        int mode = int(st.sampling);
        if (ImGui::Combo("sampling", &mode, "light sampling\0BSDF sampling\0MIS\0")) {
            st.sampling = SamplingMode(mode);
            fe_->params_changed(viewer_now());
        }
        ImGui::EndDisabled();
        if (!caps.sampling && ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("%s", unread);
        ImGui::BeginDisabled(!caps.sampler);
        int sampler = int(st.sampler.type);
        if (ImGui::Combo("sampler", &sampler, "independent\0stratified\0multijitter\0ldsampler\0sobol\0zsobol\0orthogonal\0")) {
            st.sampler.type = SamplerType(sampler);
            fe_->params_changed(viewer_now());
        }
        ImGui::EndDisabled();
        if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
            if (!caps.sampler) ImGui::SetTooltip("%s: its Markov chains draw their own random numbers", unread);
            else
                ImGui::SetTooltip("Where the random numbers come from (docs/samplers.md). The stratified ones stratify\n"
                                  "over the scene's sample_count (%d): complete sets every %u samples.",
                                  st.spp, sampler_sample_count(st.sampler.type, uint32_t(std::max(1, st.spp))));
        }
        // Mitsuba's max_depth (path segments), as in scene files and --max-depth (integrator/depth.h).
        ImGui::BeginDisabled(!caps.max_depth);
        int max_depth = max_depth_to_mitsuba(st.max_depth);
        if (ImGui::InputInt("max depth", &max_depth)) {
            // -1 or >= 1 (max_depth_error): stepping down from 1 goes to -1, up from -1 to 1.
            max_depth = max_depth == 0 ? (st.max_depth < 0 ? 1 : -1) : std::max(-1, max_depth);
            st.max_depth = max_depth_from_mitsuba(max_depth);
            fe_->params_changed(viewer_now());
        }
        ImGui::EndDisabled();
        if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
            ImGui::SetTooltip(caps.max_depth ? "Mitsuba's max_depth: path segments (1: emitters only, 2: direct light);\n"
                                               "-1: unbounded (unbiased, ended by Russian roulette)"
                                             : "not read by this integrator: it has no depth");
        // A finite depth drops every longer path: the image converges to a darker one. Say so
        // where the setting is made (docs/accuracy.md measures the energy lost per depth).
        if (caps.max_depth && st.max_depth >= 0)
            ImGui::TextColored(ImVec4(1.f, 0.75f, 0.3f, 1.f), "biased: paths longer than %d segments are dropped",
                               max_depth_to_mitsuba(st.max_depth));
        ImGui::BeginDisabled(!caps.rr_depth);
        if (ImGui::InputInt("RR depth", &st.rr_depth)) {
            st.rr_depth = std::max(1, st.rr_depth);  // rr_depth_error: >= 1
            fe_->params_changed(viewer_now());
        }
        ImGui::EndDisabled();
        if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
            ImGui::SetTooltip(caps.rr_depth ? "Mitsuba's rr_depth: the path vertex from which Russian roulette may end a path"
                                            : "not read by this integrator: it has no Russian roulette");
        ImGui::Text("accelerator: %s", fe_->scene().accel ? fe_->scene().accel->name().c_str() : "-");
    }

    if (ImGui::CollapsingHeader("Camera & display", ImGuiTreeNodeFlags_DefaultOpen)) {
        float fov = fe_->camera().fov();
        if (ImGui::SliderFloat("fov (deg)", &fov, 5.f, 150.f, "%.1f")) {
            fe_->camera().set_fov(fov);
            fe_->camera_changed(viewer_now());
        }
        if (ImGui::Button("Reset camera")) {
            fe_->reset_camera(viewer_now());
        }
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Left drag: orbit   right/middle drag: pan   wheel: dolly\n"
                              "W A S D Q E: fly (shift: faster)   click: inspect a pixel");
        // Exposure is applied by the display shader: it changes nothing that the film holds.
        ImGui::SliderFloat("exposure", &display_.exposure, -10.f, 10.f, "%.2f stops");
    }

    if (ImGui::CollapsingHeader("Materials", ImGuiTreeNodeFlags_DefaultOpen)) {
        for (size_t i = 0; i < fe_->params().materials.size(); ++i) {
            Material& m = fe_->params().materials[i];
            ImGui::PushID(int(i));
            const bool selected = int(i) == fe_->selected_material;
            if (selected && fe_->reveal_selected) ImGui::SetNextItemOpen(true);
            else if (i == 0) ImGui::SetNextItemOpen(true, ImGuiCond_Once);  // show what editing looks like
            ImGuiTreeNodeFlags flags = ImGuiTreeNodeFlags_OpenOnArrow | (selected ? ImGuiTreeNodeFlags_Selected : 0);
            bool open = ImGui::TreeNodeEx("##m", flags, "%s  (%s)", m.name.empty() ? "(unnamed)" : m.name.c_str(),
                                          bsdf_type_name(m.bsdf));
            if (ImGui::IsItemClicked()) fe_->selected_material = int(i);
            if (selected && fe_->reveal_selected) {
                ImGui::SetScrollHereY();
                fe_->reveal_selected = false;
            }
            if (open) {
                if (edit_material(m)) fe_->params_changed(viewer_now());
                ImGui::TreePop();
            }
            ImGui::PopID();
        }
    }

    if (!fe_->params().media.empty() && ImGui::CollapsingHeader("Media", ImGuiTreeNodeFlags_DefaultOpen)) {
        for (size_t i = 0; i < fe_->params().media.size(); ++i) {
            Medium& m = fe_->params().media[i];
            ImGui::PushID(int(i) + 200000);
            if (ImGui::TreeNodeEx("##md", ImGuiTreeNodeFlags_DefaultOpen, "%s  (%s)", m.name.c_str(),
                                  m.heterogeneous() ? "heterogeneous" : "homogeneous")) {
                if (edit_medium(m)) fe_->params_changed(viewer_now());
                ImGui::TreePop();
            }
            ImGui::PopID();
        }
    }

    const bool any_light = !fe_->params().emitters.empty() || !fe_->params().lights.empty();
    if (any_light && ImGui::CollapsingHeader("Lights", ImGuiTreeNodeFlags_DefaultOpen)) {
        for (size_t i = 0; i < fe_->params().emitters.size(); ++i) {
            ImGui::PushID(int(i) + 100000);
            std::string label = "light " + std::to_string(i);
            for (const Shape& s : fe_->scene().shapes)
                if (s.emitter == int32_t(i)) {
                    label += " (" + s.name + ")";
                    break;
                }
            ImGui::TextUnformatted(label.c_str());
            if (edit_emitter(fe_->params().emitters[i])) fe_->params_changed(viewer_now());
            ImGui::PopID();
        }
        // The emitters not on shapes: an edit goes through with_params, which rebuilds the light set only.
        for (size_t i = 0; i < fe_->params().lights.size(); ++i) {
            ImGui::PushID(int(i) + 200000);
            Light& l = fe_->params().lights[i];
            ImGui::Text("%s (%s)", l.name.c_str(), light_type_name(l.model));
            if (edit_light(l)) fe_->params_changed(viewer_now());
            ImGui::PopID();
        }
    }

    if (ImGui::CollapsingHeader("Pixel", ImGuiTreeNodeFlags_DefaultOpen)) panel_pick();
    ImGui::TextDisabled("Drop an .obj or .xml file here to open it.");
    ImGui::PopItemWidth();
    ImGui::End();
}

void Viewer::panel_pick() {
    if (!fe_->has_pick()) {
        ImGui::TextDisabled("Click the image to inspect a pixel.");
        return;
    }
    const PickResult& pick = fe_->pick_result();
    ImGui::Text("pixel (%d, %d)", fe_->pick_pixel().x, fe_->pick_pixel().y);
    const SessionImage& img = fe_->image();
    if (!img.preview && img.width == fe_->params().settings.width && fe_->pick_pixel().x < img.width && fe_->pick_pixel().y < img.height) {
        size_t k = (size_t(fe_->pick_pixel().y) * size_t(img.width) + size_t(fe_->pick_pixel().x)) * 3;
        ImGui::Text("mean  %.4g %.4g %.4g", img.rgb[k], img.rgb[k + 1], img.rgb[k + 2]);
        ImGui::Text("samples  %d", img.passes * std::max(1, fe_->spp_per_pass()));
    } else {
        ImGui::TextDisabled("mean: waiting for a full pass");
    }
    if (!pick.hit) {
        ImGui::TextDisabled("nothing there (background)");
        for (const Light& l : fe_->params().lights)
            if ((light_flags(l.model) & (kLightInfinite | kLightDeltaDirection)) == kLightInfinite)
                ImGui::Text("background light  %s (%s)", l.name.c_str(), light_type_name(l.model));
        return;
    }
    const Shape& shape = fe_->scene().shapes[pick.shape];
    ImGui::Text("object  %s", shape.name.c_str());
    static const char* const kKinds[] = {"triangle", "sphere", "disk", "cylinder", "curve segment"};
    if (pick.kind == PrimKind::Triangle) ImGui::Text("triangle  %u", pick.triangle);
    else ImGui::Text("%s  uv %.4f %.4f", kKinds[int(pick.kind)], pick.uv.x, pick.uv.y);
    if (pick.instance != ~0u)
        ImGui::Text("instance  %u of group %u", pick.instance, fe_->scene().instances[pick.instance].group);
    if (pick.material < fe_->params().materials.size()) {
        const Material& m = fe_->params().materials[pick.material];
        ImGui::Text("material  %s (%s)", m.name.c_str(), bsdf_type_name(m.bsdf));
    }
    if (pick.emitter >= 0) ImGui::Text("emits light %d", pick.emitter);
    ImGui::Text("position  %.4g %.4g %.4g", pick.position.x, pick.position.y, pick.position.z);
    ImGui::Text("normal  %.3f %.3f %.3f", pick.normal.x, pick.normal.y, pick.normal.z);
    ImGui::Text("distance  %.4g", pick.distance);
}


}  // namespace candela
