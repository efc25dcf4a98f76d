// <spectrum> conversion to linear sRGB (spectrum.h).
#include "scene/xml/spectrum.h"
#include <algorithm>
#include <cmath>

namespace candela {
namespace xml {

namespace {

constexpr double kCieMin = 360.0, kCieMax = 830.0;
constexpr int kCieSamples = 95;
// 1 / ∫ȳ(λ) dλ over the table (Mitsuba's MI_CIE_Y_NORMALIZATION).
constexpr double kCieYNormalization = 1.0 / 106.7502593994140625;

// CIE 1931 2° standard observer, 5 nm steps from 360 nm (published CIE data, as tabulated in
// Mitsuba 3's src/core/spectrum.cpp).
const float kCie1931[kCieSamples][3] = {
    {0.0001299f, 3.917e-06f, 0.0006061f},  // 360 nm
    {0.0002321f, 6.965e-06f, 0.001086f},  // 365 nm
    {0.0004149f, 1.239e-05f, 0.001946f},  // 370 nm
    {0.0007416f, 2.202e-05f, 0.003486f},  // 375 nm
    {0.001368f, 3.9e-05f, 0.006450001f},  // 380 nm
    {0.002236f, 6.4e-05f, 0.01054999f},  // 385 nm
    {0.004243f, 0.00012f, 0.02005001f},  // 390 nm
    {0.00765f, 0.000217f, 0.03621f},  // 395 nm
    {0.01431f, 0.000396f, 0.06785001f},  // 400 nm
    {0.02319f, 0.00064f, 0.1102f},  // 405 nm
    {0.04351f, 0.00121f, 0.2074f},  // 410 nm
    {0.07763f, 0.00218f, 0.3713f},  // 415 nm
    {0.13438f, 0.004f, 0.6456f},  // 420 nm
    {0.21477f, 0.0073f, 1.03905f},  // 425 nm
    {0.2839f, 0.0116f, 1.3856f},  // 430 nm
    {0.3285f, 0.01684f, 1.62296f},  // 435 nm
    {0.34828f, 0.023f, 1.74706f},  // 440 nm
    {0.34806f, 0.0298f, 1.7826f},  // 445 nm
    {0.3362f, 0.038f, 1.77211f},  // 450 nm
    {0.3187f, 0.048f, 1.7441f},  // 455 nm
    {0.2908f, 0.06f, 1.6692f},  // 460 nm
    {0.2511f, 0.0739f, 1.5281f},  // 465 nm
    {0.19536f, 0.09098f, 1.28764f},  // 470 nm
    {0.1421f, 0.1126f, 1.0419f},  // 475 nm
    {0.09564f, 0.13902f, 0.8129501f},  // 480 nm
    {0.05795001f, 0.1693f, 0.6162f},  // 485 nm
    {0.03201f, 0.20802f, 0.46518f},  // 490 nm
    {0.0147f, 0.2586f, 0.3533f},  // 495 nm
    {0.0049f, 0.323f, 0.272f},  // 500 nm
    {0.0024f, 0.4073f, 0.2123f},  // 505 nm
    {0.0093f, 0.503f, 0.1582f},  // 510 nm
    {0.0291f, 0.6082f, 0.1117f},  // 515 nm
    {0.06327f, 0.71f, 0.07824999f},  // 520 nm
    {0.1096f, 0.7932f, 0.05725001f},  // 525 nm
    {0.1655f, 0.862f, 0.04216f},  // 530 nm
    {0.2257499f, 0.9148501f, 0.02984f},  // 535 nm
    {0.2904f, 0.954f, 0.0203f},  // 540 nm
    {0.3597f, 0.9803f, 0.0134f},  // 545 nm
    {0.4334499f, 0.9949501f, 0.008749999f},  // 550 nm
    {0.5120501f, 1.f, 0.005749999f},  // 555 nm
    {0.5945f, 0.995f, 0.0039f},  // 560 nm
    {0.6784f, 0.9786f, 0.002749999f},  // 565 nm
    {0.7621f, 0.952f, 0.0021f},  // 570 nm
    {0.8425f, 0.9154f, 0.0018f},  // 575 nm
    {0.9163f, 0.87f, 0.001650001f},  // 580 nm
    {0.9786f, 0.8163f, 0.0014f},  // 585 nm
    {1.0263f, 0.757f, 0.0011f},  // 590 nm
    {1.0567f, 0.6949f, 0.001f},  // 595 nm
    {1.0622f, 0.631f, 0.0008f},  // 600 nm
    {1.0456f, 0.5668f, 0.0006f},  // 605 nm
    {1.0026f, 0.503f, 0.00034f},  // 610 nm
    {0.9384f, 0.4412f, 0.00024f},  // 615 nm
    {0.8544499f, 0.381f, 0.00019f},  // 620 nm
    {0.7514f, 0.321f, 0.0001f},  // 625 nm
    {0.6424f, 0.265f, 4.999999e-05f},  // 630 nm
    {0.5419f, 0.217f, 3e-05f},  // 635 nm
    {0.4479f, 0.175f, 2e-05f},  // 640 nm
    {0.3608f, 0.1382f, 1e-05f},  // 645 nm
    {0.2835f, 0.107f, 0.f},  // 650 nm
    {0.2187f, 0.0816f, 0.f},  // 655 nm
    {0.1649f, 0.061f, 0.f},  // 660 nm
    {0.1212f, 0.04458f, 0.f},  // 665 nm
    {0.0874f, 0.032f, 0.f},  // 670 nm
    {0.0636f, 0.0232f, 0.f},  // 675 nm
    {0.04677f, 0.017f, 0.f},  // 680 nm
    {0.0329f, 0.01192f, 0.f},  // 685 nm
    {0.0227f, 0.00821f, 0.f},  // 690 nm
    {0.01584f, 0.005723f, 0.f},  // 695 nm
    {0.01135916f, 0.004102f, 0.f},  // 700 nm
    {0.008110916f, 0.002929f, 0.f},  // 705 nm
    {0.005790346f, 0.002091f, 0.f},  // 710 nm
    {0.004109457f, 0.001484f, 0.f},  // 715 nm
    {0.002899327f, 0.001047f, 0.f},  // 720 nm
    {0.00204919f, 0.00074f, 0.f},  // 725 nm
    {0.001439971f, 0.00052f, 0.f},  // 730 nm
    {0.0009999493f, 0.0003611f, 0.f},  // 735 nm
    {0.0006900786f, 0.0002492f, 0.f},  // 740 nm
    {0.0004760213f, 0.0001719f, 0.f},  // 745 nm
    {0.0003323011f, 0.00012f, 0.f},  // 750 nm
    {0.0002348261f, 8.48e-05f, 0.f},  // 755 nm
    {0.0001661505f, 6e-05f, 0.f},  // 760 nm
    {0.000117413f, 4.24e-05f, 0.f},  // 765 nm
    {8.307527e-05f, 3e-05f, 0.f},  // 770 nm
    {5.870652e-05f, 2.12e-05f, 0.f},  // 775 nm
    {4.150994e-05f, 1.499e-05f, 0.f},  // 780 nm
    {2.935326e-05f, 1.06e-05f, 0.f},  // 785 nm
    {2.067383e-05f, 7.4657e-06f, 0.f},  // 790 nm
    {1.455977e-05f, 5.2578e-06f, 0.f},  // 795 nm
    {1.025398e-05f, 3.7029e-06f, 0.f},  // 800 nm
    {7.221456e-06f, 2.6078e-06f, 0.f},  // 805 nm
    {5.085868e-06f, 1.8366e-06f, 0.f},  // 810 nm
    {3.581652e-06f, 1.2934e-06f, 0.f},  // 815 nm
    {2.522525e-06f, 9.1093e-07f, 0.f},  // 820 nm
    {1.776509e-06f, 6.4153e-07f, 0.f},  // 825 nm
    {1.251141e-06f, 4.5181e-07f, 0.f},  // 830 nm
};

// The CIE standard illuminant D65, 5 nm steps from 360 nm (published CIE data), and Mitsuba's
// scale that makes ∫ D65 ȳ over the table equal ∫ ȳ (MI_CIE_D65_NORMALIZATION).
const float kD65[kCieSamples] = {
    46.6383f, 49.3637f, 52.0891f, 51.0323f, 49.9755f, 52.3118f, 54.6482f, 68.7015f,
    82.7549f, 87.1204f, 91.486f, 92.4589f, 93.4318f, 90.057f, 86.6823f, 95.7736f,
    104.865f, 110.936f, 117.008f, 117.41f, 117.812f, 116.336f, 114.861f, 115.392f,
    115.923f, 112.367f, 108.811f, 109.082f, 109.354f, 108.578f, 107.802f, 106.296f,
    104.79f, 106.239f, 107.689f, 106.047f, 104.405f, 104.225f, 104.046f, 102.023f,
    100.f, 98.1671f, 96.3342f, 96.0611f, 95.788f, 92.2368f, 88.6856f, 89.3459f,
    90.0062f, 89.8026f, 89.5991f, 88.6489f, 87.6987f, 85.4936f, 83.2886f, 83.4939f,
    83.6992f, 81.863f, 80.0268f, 80.1207f, 80.2146f, 81.2462f, 82.2778f, 80.281f,
    78.2842f, 74.0027f, 69.7213f, 70.6652f, 71.6091f, 72.979f, 74.349f, 67.9765f,
    61.604f, 65.7448f, 69.8856f, 72.4863f, 75.087f, 69.3398f, 63.5927f, 55.0054f,
    46.4182f, 56.6118f, 66.8054f, 65.0941f, 63.3828f, 63.8434f, 64.304f, 61.8779f,
    59.4519f, 55.7054f, 51.959f, 54.6998f, 57.4406f, 58.8765f, 60.3125f,
};
constexpr double kD65Normalization = 0.010101273599490354;

}  // namespace

double cie_d65(double lambda) {
    if (!(lambda >= kCieMin && lambda <= kCieMax)) return 0.0;
    double t = (lambda - kCieMin) * ((kCieSamples - 1) / (kCieMax - kCieMin));
    int i0 = std::min(std::max(int(t), 0), kCieSamples - 2);
    float w1 = float(t - i0), w0 = 1.f - w1;
    return double(w0 * kD65[i0] + w1 * kD65[i0 + 1]) * kD65Normalization;
}

vec3 xyz_to_linear_srgb(double x, double y, double z) {
    return vec3(float(3.240479 * x - 1.537150 * y - 0.498535 * z), float(-0.969256 * x + 1.875991 * y + 0.041556 * z),
                float(0.055648 * x - 0.204043 * y + 1.057311 * z));
}

vec3 cie1931_xyz(double lambda) {
    if (!(lambda >= kCieMin && lambda <= kCieMax)) return vec3(0.f);
    double t = (lambda - kCieMin) * ((kCieSamples - 1) / (kCieMax - kCieMin));
    int i0 = std::min(std::max(int(t), 0), kCieSamples - 2);
    float w1 = float(t - i0), w0 = 1.f - w1;
    const float* a = kCie1931[i0];
    const float* b = kCie1931[i0 + 1];
    return vec3(w0 * a[0] + w1 * b[0], w0 * a[1] + w1 * b[1], w0 * a[2] + w1 * b[2]);
}

vec3 spectrum_list_to_srgb(const std::vector<double>& wl, const std::vector<double>& values, bool bounded, bool d65) {
    const int steps = 1000;
    double x = 0, y = 0, z = 0;
    size_t n = wl.size();
    for (int i = 0; i < steps; ++i) {
        double w = kCieMin + (i / double(steps - 1)) * (kCieMax - kCieMin);
        if (w < wl.front() || w > wl.back()) continue;
        // The last interval [wl[k], wl[k+1]] with wl[k] <= w.
        size_t k = size_t(std::upper_bound(wl.begin(), wl.end(), w) - wl.begin());
        k = std::min(std::max(k, size_t(1)) - 1, n - 2);
        double w0 = wl[k], w1 = wl[k + 1];
        double v = ((w - w1) * values[k] + (w0 - w) * values[k + 1]) / (w0 - w1);
        if (d65) v *= cie_d65(w);
        vec3 c = cie1931_xyz(w);
        x += c.x * v;
        y += c.y * v;
        z += c.z * v;
    }
    double scale = (kCieMax - kCieMin) / steps * kCieYNormalization;
    x *= scale;
    y *= scale;
    z *= scale;
    vec3 rgb = xyz_to_linear_srgb(x, y, z);
    for (int c = 0; c < 3; ++c) rgb[c] = bounded ? std::min(std::max(rgb[c], 0.f), 1.f) : std::max(rgb[c], 0.f);
    return rgb;
}

}  // namespace xml
}  // namespace candela
