#pragma once
// Statistical test helpers shared by the sampling, BSDF, light and integrator tests.
//
// Three tools, each returning a p-value so that a test can apply one significance level with a
// Sidak correction over however many hypotheses it checks:
//   * chi_square_2d: goodness of fit of a 2D sampling routine against its claimed density, on the
//     sphere, hemisphere, disk, square or a triangle (plus any discrete / delta components).
//   * one-sample z and t tests: a Monte Carlo mean against an exact value.
//   * block_z_test: two noisy images (mean + variance of the mean per pixel) compared block by
//     block, for image regression tests against a committed reference.
//
// Every test here must be deterministic (fixed seeds) and must be shown to reject a deliberately
// wrong density or sampler; see tests/test_warp.cpp for the pattern.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>
#include <glm/glm.hpp>
#include "sampling/pcg32.h"

namespace candela {
class Film;
}

namespace candela::stats {

using glm::dvec2;
using glm::dvec3;

// ---- distributions ----------------------------------------------------------------------------

// Regularised lower / upper incomplete gamma functions P(a, x) and Q(a, x) = 1 - P(a, x), a > 0.
double gamma_p(double a, double x);
double gamma_q(double a, double x);
// Regularised incomplete beta function I_x(a, b).
double beta_inc(double a, double b, double x);

// Survival function of the chi-square distribution: P(X >= stat) for `dof` degrees of freedom
// (NaN for dof <= 0).
double chi_square_sf(double stat, double dof);
// Two-sided p-values of a standard normal z and of a Student t with `dof` degrees of freedom.
double normal_two_sided_p(double z);
double student_t_two_sided_p(double t, double dof);

// Sidak correction for m independent tests at family-wise level alpha: each test is run at
// 1 - (1 - alpha)^(1/m), so that P(any false rejection) = alpha exactly under independence (and at
// most about alpha otherwise). sidak_adjust turns the smallest of m p-values into a family-wise one.
double sidak_level(double alpha, int m);
double sidak_adjust(double p_min, int m);

// ---- one-sample tests -------------------------------------------------------------------------

// Mean and variance by Welford's update (stable for millions of samples of similar size).
class RunningStats {
public:
    void add(double x);
    void merge(const RunningStats& o);
    uint64_t count() const { return n_; }
    double mean() const { return mean_; }
    double variance() const { return n_ > 1 ? m2_ / double(n_ - 1) : 0.0; }  // unbiased
    double std_error() const;                                                // of the mean
private:
    uint64_t n_ = 0;
    double mean_ = 0.0, m2_ = 0.0;
};

struct MeanTest {
    double mean = 0, expected = 0, std_error = 0;
    double statistic = 0;  // (mean - expected) / std_error
    double p_value = 1;    // two-sided
    std::string describe() const;
};
// z-test (normal approximation: n large) and t-test (n - 1 degrees of freedom). `std_error_floor`
// is added in quadrature to the standard error: estimators whose samples are all equal up to float
// rounding have a zero sample variance, and the floor (e.g. a few float ulps of the value) stops
// rounding from counting as bias.
MeanTest z_test(const RunningStats& s, double expected, double std_error_floor = 0);
MeanTest z_test(double mean, double std_error, double expected, double std_error_floor = 0);
MeanTest t_test(const RunningStats& s, double expected, double std_error_floor = 0);

// ---- chi-square goodness of fit in 2D ---------------------------------------------------------

// A 2D domain parameterised by grid coordinates g in [0,1]^2: the histogram has res_x x res_y
// equal cells in g. Points are dvec3 (2D domains use z = 0). `jacobian` is d(measure)/d(g) at g,
// with measure = solid angle for the sphere and hemisphere, area otherwise.
struct Domain {
    std::string name;
    std::function<dvec3(dvec2)> to_point;
    std::function<bool(const dvec3&, dvec2&)> to_grid;  // false: the point is not in the domain
    std::function<double(dvec2)> jacobian;
};
// Cells are equal-area: the sphere and hemisphere use (cos theta, phi), the disk (r^2, phi).
Domain sphere_domain();      // g = ((1 - cos theta) / 2, phi / 2pi)
Domain hemisphere_domain();  // z >= 0, g = (1 - cos theta, phi / 2pi)
Domain disk_domain();        // unit disk, g = (r^2, phi / 2pi)
Domain square_domain();      // [0,1]^2, g = p
// A triangle in the plane z = 0 through the Duffy map p = p0 + s (p1 - p0) + s t (p2 - p1),
// g = (s^2, t): the s^2 spacing makes all cells of one row equal in area.
Domain triangle_domain(dvec2 p0, dvec2 p1, dvec2 p2);

// One draw of the routine under test.
struct DomainSample {
    enum Kind { Failed, Smooth, Discrete } kind = Failed;
    dvec3 p{0.0};       // Smooth: the point (direction) drawn
    int component = 0;  // Discrete: index into ChiSquareSetup::discrete_probabilities
};

struct ChiSquareSetup {
    Domain domain;
    int res_x = 20, res_y = 40;
    uint64_t samples = 1000000;
    uint64_t seed = 1;
    // Draws one sample; rng is the only source of randomness (seeded from `seed`).
    std::function<DomainSample(PCG32& rng)> sample;
    // Density of the smooth part w.r.t. the domain's measure (it may integrate to less than 1).
    std::function<double(const dvec3&)> pdf;
    // Probabilities of the discrete (delta) components, e.g. specular reflection and refraction.
    std::vector<double> discrete_probabilities;
    int integration_points = 6;  // Gauss-Legendre points per cell axis
    double min_expected = 5.0;   // cells expected to hold fewer samples are pooled
};

struct ChiSquareResult {
    double statistic = 0, p_value = 1;
    int dof = 0;
    int cells = 0, pooled_cells = 0;  // non-empty cells and how many were pooled
    double pdf_integral = 0;          // integral of the smooth pdf over the domain
    uint64_t smooth_count = 0, failed_count = 0, outside_count = 0;
    double failed_expected = 0;  // N (1 - pdf_integral - sum of discrete probabilities)
    // Discrete components, reported separately (they are also cells of the chi-square above).
    std::vector<uint64_t> discrete_count;
    std::vector<double> discrete_expected;
    std::string message;  // why p is 0 when the test is decided without the statistic
    std::string describe() const;
    // Observed and expected histograms, row per grid row, for diagnosis of a failure.
    std::vector<double> observed, expected;
};

// Both chi-square functions need at least one degree of freedom after pooling: with none (e.g.
// every cell pooled into one) they record a GoogleTest failure in the calling test and return
// p = NaN, which passes no comparison, instead of a p = 1 that would pass any test.
//
// Draws setup.samples samples, bins them on the grid and compares with the expected counts
// N * integral of pdf * jacobian over each cell (Gauss-Legendre rule per cell). Cells with expected
// count < min_expected are pooled, smallest first, into groups that reach it. A sample in a cell
// (or discrete component) whose expected count is 0 decides the test at once: p = 0. The
// "failed" outcomes (no sample drawn) form one more cell with the leftover probability.
ChiSquareResult chi_square_2d(const ChiSquareSetup& setup);

// The pooling and statistic alone, for histograms built elsewhere (e.g. discrete distributions).
// `constraints` is the number of degrees of freedom lost besides the total (usually 0).
ChiSquareResult chi_square_counts(const std::vector<double>& observed, const std::vector<double>& expected,
                                  double min_expected = 5.0, int constraints = 0);

// Integral of pdf * jacobian over the whole domain, by the same rule as the expected counts.
double integrate_over_domain(const Domain& d, const std::function<double(const dvec3&)>& f, int res_x = 20,
                             int res_y = 40, int points = 6);

// ---- image comparison -------------------------------------------------------------------------

// A rendered image as an estimator: per pixel the mean and the variance OF THAT MEAN (i.e. the
// per-sample variance divided by the number of samples), 3 channels.
struct ImageEstimate {
    int width = 0, height = 0;
    std::vector<dvec3> mean;
    std::vector<dvec3> var_of_mean;

    // From per-pixel sums of x and x^2 and sample counts (what a film with second moments holds).
    static ImageEstimate from_moments(int width, int height, const std::vector<dvec3>& sum,
                                      const std::vector<dvec3>& sum_sq, const std::vector<uint32_t>& count);
    // From K >= 2 independent films of the same scene (different seeds or sample ranges): the mean
    // is the sample-count-weighted mean, and the variance of the mean comes from the spread of the
    // K batch means ("batch means"), so no second moment has to be stored while rendering.
    // Weighted films (tent, gaussian filters) are normalised by their weight sums instead of counts.
    static ImageEstimate from_batches(const std::vector<const Film*>& batches);
    // A committed reference: its mean image and a per-pixel variance-of-the-mean image.
    static ImageEstimate from_film(const Film& film, const std::vector<dvec3>& var_of_mean);
    // A committed reference as tests/data/make_reference.py writes it: PREFIX_mean.exr (the mean of
    // K batch renders) and PREFIX_var.exr (the variance of that mean), per pixel and channel.
    static ImageEstimate from_reference_files(const std::string& prefix);
};

// Whole-image z-test per channel: the difference of the two images' means over all pixels, with
// both images' variances (pixels independent); the smallest p, Sidak-adjusted over the channels.
// `rel`, when given, receives (mean_a - mean_b) / mean_b per channel.
double whole_image_p(const ImageEstimate& a, const ImageEstimate& b, dvec3* rel = nullptr);

// Block z-test. Both images are cut into block x block tiles (partial tiles at the edges count).
// Per tile and channel: m = average of the pixel means, v = sum of var_of_mean / n_pixels^2 (pixels
// are independent), z = (m_a - m_b) / sqrt(v_a + v_b + (rel_floor * max(|m_a|, |m_b|))^2), two-sided
// normal p. The family-wise p is the smallest p Sidak-adjusted over all tiles x channels; the
// images agree at level alpha when p_family >= alpha. Tiles where both variances and both means are
// zero (black background) are skipped. Blocks trade resolution for the normal approximation: a
// block of b x b pixels at n spp averages b^2 n samples, which tames the heavy tails of per-pixel
// path-traced estimates.
struct BlockTestResult {
    int tests = 0;                // tiles x channels actually tested
    double p_min = 1, p_family = 1;
    double max_abs_z = 0;
    // Fraction of tests with p < alpha, uncorrected: about alpha when the images agree, much more
    // when they differ everywhere (a global bias), a few tiles when one region is wrong.
    double failing_fraction = 0;
    int worst_x = -1, worst_y = -1, worst_channel = -1;  // tile origin (pixels) of the smallest p
    bool passed(double alpha) const { return p_family >= alpha; }
    std::string describe() const;
};
BlockTestResult block_z_test(const ImageEstimate& a, const ImageEstimate& b, int block, double alpha = 0.01,
                             double rel_floor = 0);

}  // namespace candela::stats
