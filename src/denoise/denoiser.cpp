#include "denoise/denoiser.h"
#include <algorithm>
#include <cstdlib>

#if CANDELA_HAS_OIDN
#include <dlfcn.h>
#include "denoise/oidn_api.h"
#endif

namespace candela {

bool parse_denoise_quality(const std::string& s, DenoiseQuality& out) {
    if (s == "fast") out = DenoiseQuality::Fast;
    else if (s == "balanced") out = DenoiseQuality::Balanced;
    else if (s == "high") out = DenoiseQuality::High;
    else return false;
    return true;
}

const char* denoise_quality_name(DenoiseQuality q) {
    switch (q) {
        case DenoiseQuality::Fast: return "fast";
        case DenoiseQuality::Balanced: return "balanced";
        case DenoiseQuality::High: return "high";
    }
    return "?";
}

DenoiseImages denoise_inputs(const Film& film, const std::vector<AovSpec>& aovs) {
    DenoiseImages in;
    in.width = film.width();
    in.height = film.height();
    film.resolve_into(in.color);
    const size_t n = size_t(in.width) * size_t(in.height);
    int offset = 0;
    for (const AovSpec& a : aovs) {
        std::vector<float>* dst = a.type == AovType::DenoiseAlbedo   ? &in.albedo
                                  : a.type == AovType::DenoiseNormal ? &in.normal
                                                                     : nullptr;
        if (dst && offset + 3 <= film.aov_channels()) {
            dst->resize(3 * n);
            for (int y = 0; y < in.height; ++y)
                for (int x = 0; x < in.width; ++x) {
                    const size_t i = size_t(y) * size_t(in.width) + size_t(x);
                    for (int k = 0; k < 3; ++k) (*dst)[3 * i + size_t(k)] = film.aov(x, y, offset + k);
                }
        }
        offset += aov_channel_count(a.type);
    }
    // OIDN takes both auxiliaries or the albedo alone; a normal without an albedo is dropped.
    if (in.albedo.empty()) in.normal.clear();
    return in;
}

#if CANDELA_HAS_OIDN

namespace {

struct Library {
    oidn::Api api{};
    std::string error;  // empty: loaded
};

template <class F>
bool find(void* h, const char* name, F& fn, std::string& error) {
    fn = reinterpret_cast<F>(dlsym(h, name));
    if (!fn && error.empty()) error = std::string("the Open Image Denoise library has no ") + name + " (not version 2.x?)";
    return fn != nullptr;
}

Library load_library() {
    Library lib;
    std::vector<std::string> candidates;
    if (const char* e = std::getenv("CANDELA_OIDN_LIBRARY")) {
        candidates.push_back(e);
    } else {
        std::string cache;
        if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) cache = x;
        else if (const char* home = std::getenv("HOME"); home && *home) cache = std::string(home) + "/.cache";
        if (!cache.empty()) candidates.push_back(cache + "/candela/oidn-2.5.1/lib/libOpenImageDenoise.so.2");
        candidates.push_back("libOpenImageDenoise.so.2");
    }
    void* h = nullptr;
    std::string why;
    for (const std::string& c : candidates) {
        h = dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (h) break;
        if (why.empty()) {  // the first candidate's reason: the installed copy, or the one asked for
            const char* e = dlerror();
            why = e ? e : c + ": cannot load";
        }
    }
    if (!h) {
        lib.error = "Open Image Denoise is not installed (" + why + "); bash scripts/setup.sh installs it";
        return lib;
    }
    oidn::Api& a = lib.api;
    std::string& err = lib.error;
    find(h, "oidnNewDevice", a.NewDevice, err);
    find(h, "oidnCommitDevice", a.CommitDevice, err);
    find(h, "oidnReleaseDevice", a.ReleaseDevice, err);
    find(h, "oidnSetDeviceInt", a.SetDeviceInt, err);
    find(h, "oidnGetDeviceError", a.GetDeviceError, err);
    find(h, "oidnNewFilter", a.NewFilter, err);
    find(h, "oidnSetSharedFilterImage", a.SetSharedFilterImage, err);
    find(h, "oidnSetFilterBool", a.SetFilterBool, err);
    find(h, "oidnSetFilterInt", a.SetFilterInt, err);
    find(h, "oidnCommitFilter", a.CommitFilter, err);
    find(h, "oidnExecuteFilter", a.ExecuteFilter, err);
    find(h, "oidnReleaseFilter", a.ReleaseFilter, err);
    return lib;  // the handle stays open for the life of the process
}

const Library& library() {
    static const Library lib = load_library();  // thread-safe, once
    return lib;
}

int oidn_quality(DenoiseQuality q) {
    switch (q) {
        case DenoiseQuality::Fast: return oidn::kQualityFast;
        case DenoiseQuality::Balanced: return oidn::kQualityBalanced;
        case DenoiseQuality::High: return oidn::kQualityHigh;
    }
    return oidn::kQualityHigh;
}

}  // namespace

std::string denoiser_unavailable_reason() { return library().error; }

struct Denoiser::State {
    const oidn::Api& api;
    oidn::Device device = nullptr;
    oidn::Filter beauty = nullptr, albedo_filter = nullptr, normal_filter = nullptr;
    // What the filters were committed for.
    int width = 0, height = 0;
    bool aux = false, normal = false;
    int quality = -1;
    // The images the filters read and write (shared with OIDN: their addresses must not change
    // while the filters are committed, so they are resized only when the filters are rebuilt).
    std::vector<float> color, albedo, normal_img, output;

    explicit State(const oidn::Api& a) : api(a) {}
    ~State() {
        release_filters();
        if (device) api.ReleaseDevice(device);
    }
    void release_filters() {
        for (oidn::Filter* f : {&beauty, &albedo_filter, &normal_filter})
            if (*f) {
                api.ReleaseFilter(*f);
                *f = nullptr;
            }
    }
    void check(const char* what) {
        const char* msg = nullptr;
        const int code = api.GetDeviceError(device, &msg);
        if (code == oidn::kErrorNone) return;
        std::string m = msg && *msg ? msg : "error " + std::to_string(code);
        std::replace(m.begin(), m.end(), '\n', ' ');
        throw DenoiseError(std::string("Open Image Denoise failed ") + what + ": " + m);
    }
    void image(oidn::Filter f, const char* name, std::vector<float>& v) {
        api.SetSharedFilterImage(f, name, v.data(), oidn::kFormatFloat3, size_t(width), size_t(height), 0, 0, 0);
    }
    // A filter that denoises one auxiliary image in place of its noisy self (the prefilter).
    oidn::Filter aux_filter(const char* name, std::vector<float>& v) {
        oidn::Filter f = api.NewFilter(device, "RT");
        image(f, name, v);
        image(f, "output", v);  // in place: OIDN allows output = input
        api.SetFilterInt(f, "quality", quality);
        api.CommitFilter(f);
        return f;
    }
    void configure(int w, int h, bool with_aux, bool with_normal, int q) {
        if (w == width && h == height && with_aux == aux && with_normal == normal && q == quality && beauty) return;
        release_filters();
        width = w, height = h, aux = with_aux, normal = with_normal, quality = q;
        const size_t n = 3 * size_t(w) * size_t(h);
        color.assign(n, 0.f);
        output.assign(n, 0.f);
        albedo.assign(aux ? n : 0, 0.f);
        normal_img.assign(normal ? n : 0, 0.f);
        beauty = api.NewFilter(device, "RT");
        image(beauty, "color", color);
        if (aux) image(beauty, "albedo", albedo);
        if (normal) image(beauty, "normal", normal_img);
        image(beauty, "output", output);
        api.SetFilterBool(beauty, "hdr", true);
        api.SetFilterBool(beauty, "cleanAux", aux);
        api.SetFilterInt(beauty, "quality", quality);
        api.CommitFilter(beauty);
        if (aux) albedo_filter = aux_filter("albedo", albedo);
        if (normal) normal_filter = aux_filter("normal", normal_img);
        check("to set up its filters");
    }
};

Denoiser::Denoiser(DenoiseQuality q) : quality_(q) {}
Denoiser::~Denoiser() = default;

void Denoiser::set_quality(DenoiseQuality q) { quality_ = q; }

void Denoiser::denoise(const DenoiseImages& in, std::vector<float>& out) {
    const Library& lib = library();
    if (!lib.error.empty()) throw DenoiseError(lib.error);
    const size_t n = 3 * size_t(std::max(0, in.width)) * size_t(std::max(0, in.height));
    if (n == 0 || in.color.size() != n || (!in.albedo.empty() && in.albedo.size() != n) ||
        (!in.normal.empty() && (in.normal.size() != n || in.albedo.empty())))
        throw DenoiseError("denoise: the images do not have the same size");
    if (!state_) {
        auto s = std::make_unique<State>(lib.api);
        s->device = lib.api.NewDevice(oidn::kDeviceCpu);
        if (!s->device) s->check("to create its CPU device");  // GetDeviceError(null) says why
        if (!s->device) throw DenoiseError("Open Image Denoise failed to create its CPU device");
        lib.api.CommitDevice(s->device);
        s->check("to start its CPU device");
        state_ = std::move(s);
    }
    State& s = *state_;
    s.configure(in.width, in.height, !in.albedo.empty(), !in.normal.empty(), oidn_quality(quality_));
    std::copy(in.color.begin(), in.color.end(), s.color.begin());
    if (s.aux) std::copy(in.albedo.begin(), in.albedo.end(), s.albedo.begin());
    if (s.normal) std::copy(in.normal.begin(), in.normal.end(), s.normal_img.begin());
    if (s.albedo_filter) lib.api.ExecuteFilter(s.albedo_filter);
    if (s.normal_filter) lib.api.ExecuteFilter(s.normal_filter);
    lib.api.ExecuteFilter(s.beauty);
    s.check("to denoise");
    out = s.output;
}

#else  // built with CANDELA_OIDN=OFF

std::string denoiser_unavailable_reason() {
    return "this candela was built without Open Image Denoise (CANDELA_OIDN=OFF)";
}

struct Denoiser::State {};
Denoiser::Denoiser(DenoiseQuality q) : quality_(q) {}
Denoiser::~Denoiser() = default;
void Denoiser::set_quality(DenoiseQuality q) { quality_ = q; }
void Denoiser::denoise(const DenoiseImages&, std::vector<float>&) { throw DenoiseError(denoiser_unavailable_reason()); }

#endif

}  // namespace candela
