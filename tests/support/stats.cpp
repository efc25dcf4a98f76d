// Statistical test helpers (chi-square, z/t-tests, image block tests); see stats.h.
#include "support/stats.h"

#include <gtest/gtest.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include "film/film.h"
#include "film/image_io.h"

namespace candela::stats {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kEps = 1e-15;      // relative accuracy of the series and continued fractions
constexpr double kTiny = 1e-300;    // keeps Lentz's method away from division by zero
constexpr int kMaxIterations = 100000;

// P(a, x) by its power series: x^a e^-x / Gamma(a+1) * sum_n x^n / ((a+1)...(a+n)).
// Converges quickly for x < a + 1.
double gamma_p_series(double a, double x) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < kMaxIterations; ++n) {
        term *= x / (a + n);
        sum += term;
        if (std::abs(term) < std::abs(sum) * kEps) break;
    }
    return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) by its continued fraction (Legendre), evaluated with the modified Lentz method.
// Converges quickly for x > a + 1, where the series would need many terms.
double gamma_q_fraction(double a, double x) {
    double b = x + 1.0 - a;
    double c = 1.0 / kTiny, d = 1.0 / b, h = d;
    for (int i = 1; i < kMaxIterations; ++i) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::abs(d) < kTiny) d = kTiny;
        c = b + an / c;
        if (std::abs(c) < kTiny) c = kTiny;
        d = 1.0 / d;
        double delta = d * c;
        h *= delta;
        if (std::abs(delta - 1.0) < kEps) break;
    }
    return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// The continued fraction of the incomplete beta function (converges for x < (a+1)/(a+b+2)).
double beta_fraction(double a, double b, double x) {
    double qab = a + b, qap = a + 1.0, qam = a - 1.0;
    double c = 1.0, d = 1.0 - qab * x / qap;
    if (std::abs(d) < kTiny) d = kTiny;
    d = 1.0 / d;
    double h = d;
    for (int m = 1; m < kMaxIterations; ++m) {
        int m2 = 2 * m;
        // Even step.
        double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if (std::abs(d) < kTiny) d = kTiny;
        c = 1.0 + aa / c;
        if (std::abs(c) < kTiny) c = kTiny;
        d = 1.0 / d;
        h *= d * c;
        // Odd step.
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if (std::abs(d) < kTiny) d = kTiny;
        c = 1.0 + aa / c;
        if (std::abs(c) < kTiny) c = kTiny;
        d = 1.0 / d;
        double delta = d * c;
        h *= delta;
        if (std::abs(delta - 1.0) < kEps) break;
    }
    return h;
}

std::string fmt(double v) {
    std::ostringstream s;
    s.precision(6);
    s << v;
    return s.str();
}
}  // namespace

double gamma_p(double a, double x) {
    if (!(a > 0.0) || std::isnan(x)) return std::numeric_limits<double>::quiet_NaN();
    if (x <= 0.0) return 0.0;
    if (std::isinf(x)) return 1.0;
    return x < a + 1.0 ? gamma_p_series(a, x) : 1.0 - gamma_q_fraction(a, x);
}

double gamma_q(double a, double x) {
    if (!(a > 0.0) || std::isnan(x)) return std::numeric_limits<double>::quiet_NaN();
    if (x <= 0.0) return 1.0;
    if (std::isinf(x)) return 0.0;
    // Each branch computes the small side directly, so tiny p-values keep their relative accuracy.
    return x < a + 1.0 ? 1.0 - gamma_p_series(a, x) : gamma_q_fraction(a, x);
}

double beta_inc(double a, double b, double x) {
    if (x <= 0.0) return 0.0;
    if (x >= 1.0) return 1.0;
    double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) +
                            b * std::log1p(-x));
    // Use the fraction where it converges; otherwise the symmetry I_x(a,b) = 1 - I_{1-x}(b,a).
    if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_fraction(a, b, x) / a;
    return 1.0 - front * beta_fraction(b, a, 1.0 - x) / b;
}

double chi_square_sf(double stat, double dof) {
    if (!(dof > 0)) return std::numeric_limits<double>::quiet_NaN();  // no distribution: no p
    return gamma_q(0.5 * dof, 0.5 * stat);
}

double normal_two_sided_p(double z) {
    if (std::isnan(z)) return 0.0;  // an undefined statistic is never evidence of agreement
    return std::erfc(std::abs(z) / std::sqrt(2.0));
}

double student_t_two_sided_p(double t, double dof) {
    if (std::isnan(t)) return 0.0;
    if (std::isinf(t)) return 0.0;
    return beta_inc(0.5 * dof, 0.5, dof / (dof + t * t));
}

double sidak_level(double alpha, int m) {
    // -expm1(log1p(-alpha) / m) == 1 - (1-alpha)^(1/m) without cancellation for small alpha.
    return -std::expm1(std::log1p(-alpha) / double(std::max(m, 1)));
}

double sidak_adjust(double p_min, int m) {
    return -std::expm1(double(std::max(m, 1)) * std::log1p(-std::min(std::max(p_min, 0.0), 1.0)));
}

// ---- one-sample tests ---------------------------------------------------------------------------

void RunningStats::add(double x) {
    ++n_;
    double d = x - mean_;
    mean_ += d / double(n_);
    m2_ += d * (x - mean_);
}

void RunningStats::merge(const RunningStats& o) {
    if (o.n_ == 0) return;
    if (n_ == 0) {
        *this = o;
        return;
    }
    // Chan et al.'s pairwise combination.
    double n = double(n_ + o.n_), d = o.mean_ - mean_;
    mean_ += d * double(o.n_) / n;
    m2_ += o.m2_ + d * d * double(n_) * double(o.n_) / n;
    n_ += o.n_;
}

double RunningStats::std_error() const { return n_ > 1 ? std::sqrt(variance() / double(n_)) : 0.0; }

std::string MeanTest::describe() const {
    return "mean " + fmt(mean) + " vs expected " + fmt(expected) + " (std error " + fmt(std_error) +
           ", relative " + fmt(expected != 0 ? std_error / std::abs(expected) : std_error) + "), statistic " +
           fmt(statistic) + ", p = " + fmt(p_value);
}

MeanTest z_test(double mean, double std_error, double expected, double std_error_floor) {
    MeanTest r;
    r.mean = mean;
    r.expected = expected;
    r.std_error = std::sqrt(std_error * std_error + std_error_floor * std_error_floor);
    double diff = mean - expected;
    if (r.std_error > 0) r.statistic = diff / r.std_error;
    else r.statistic = diff == 0 ? 0.0 : std::copysign(std::numeric_limits<double>::infinity(), diff);
    r.p_value = normal_two_sided_p(r.statistic);
    return r;
}

MeanTest z_test(const RunningStats& s, double expected, double std_error_floor) {
    return z_test(s.mean(), s.std_error(), expected, std_error_floor);
}

MeanTest t_test(const RunningStats& s, double expected, double std_error_floor) {
    MeanTest r = z_test(s, expected, std_error_floor);
    r.p_value = s.count() > 1 ? (std::isinf(r.statistic) ? 0.0 : student_t_two_sided_p(r.statistic, double(s.count() - 1)))
                              : 1.0;
    return r;
}

// ---- chi-square -----------------------------------------------------------------------------------

Domain sphere_domain() {
    Domain d;
    d.name = "sphere";
    d.to_point = [](dvec2 g) {
        double z = 1.0 - 2.0 * g.x, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * kPi * g.y;
        return dvec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    d.to_grid = [](const dvec3& p, dvec2& g) {
        double len = glm::length(p);
        if (!(std::abs(len - 1.0) < 1e-4)) return false;  // a direction sampler must return unit vectors
        dvec3 v = p / len;
        double phi = std::atan2(v.y, v.x);
        if (phi < 0) phi += 2.0 * kPi;
        g = dvec2((1.0 - v.z) * 0.5, phi / (2.0 * kPi));
        return true;
    };
    d.jacobian = [](dvec2) { return 4.0 * kPi; };
    return d;
}

Domain hemisphere_domain() {
    Domain d = sphere_domain();
    d.name = "hemisphere";
    d.to_point = [](dvec2 g) {
        double z = 1.0 - g.x, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * kPi * g.y;
        return dvec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    Domain sphere = sphere_domain();
    d.to_grid = [to_sphere = sphere.to_grid](const dvec3& p, dvec2& g) {
        if (!to_sphere(p, g) || p.z < 0.0) return false;
        g.x *= 2.0;
        return true;
    };
    d.jacobian = [](dvec2) { return 2.0 * kPi; };
    return d;
}

Domain disk_domain() {
    Domain d;
    d.name = "disk";
    d.to_point = [](dvec2 g) {
        double r = std::sqrt(g.x), phi = 2.0 * kPi * g.y;
        return dvec3(r * std::cos(phi), r * std::sin(phi), 0.0);
    };
    d.to_grid = [](const dvec3& p, dvec2& g) {
        double r2 = p.x * p.x + p.y * p.y;
        if (p.z != 0.0 || !(r2 <= 1.0 + 1e-6)) return false;
        double phi = std::atan2(p.y, p.x);
        if (phi < 0) phi += 2.0 * kPi;
        g = dvec2(std::min(r2, 1.0), phi / (2.0 * kPi));
        return true;
    };
    d.jacobian = [](dvec2) { return kPi; };
    return d;
}

Domain square_domain() {
    Domain d;
    d.name = "square";
    d.to_point = [](dvec2 g) { return dvec3(g, 0.0); };
    d.to_grid = [](const dvec3& p, dvec2& g) {
        if (p.z != 0.0 || !(p.x >= 0.0 && p.x <= 1.0 && p.y >= 0.0 && p.y <= 1.0)) return false;
        g = dvec2(p);
        return true;
    };
    d.jacobian = [](dvec2) { return 1.0; };
    return d;
}

Domain triangle_domain(dvec2 p0, dvec2 p1, dvec2 p2) {
    Domain d;
    d.name = "triangle";
    dvec2 e1 = p1 - p0, e2 = p2 - p0;
    double det = e1.x * e2.y - e1.y * e2.x;  // twice the signed area
    double area = 0.5 * std::abs(det);
    d.to_point = [=](dvec2 g) {
        double s = std::sqrt(g.x), t = g.y;
        return dvec3(p0 + s * (p1 - p0) + s * t * (p2 - p1), 0.0);
    };
    d.to_grid = [=](const dvec3& p, dvec2& g) {
        if (p.z != 0.0) return false;
        dvec2 q = dvec2(p) - p0;
        double b1 = (q.x * e2.y - q.y * e2.x) / det, b2 = (e1.x * q.y - e1.y * q.x) / det;
        double b0 = 1.0 - b1 - b2;
        // Float samplers land a rounding error outside; anything more is a sampler bug.
        const double tol = 1e-6;
        if (b0 < -tol || b1 < -tol || b2 < -tol) return false;
        double s = std::clamp(1.0 - b0, 0.0, 1.0);
        double t = s > 0.0 ? std::clamp(b2 / s, 0.0, 1.0) : 0.0;
        g = dvec2(s * s, t);
        return true;
    };
    d.jacobian = [=](dvec2) { return area; };
    return d;
}

namespace {
// Gauss-Legendre nodes and weights on [0, 1] (Newton's method on P_n from the Chebyshev guess).
// Gauss rather than Simpson: no node lies on a cell boundary, and densities with a jump exactly
// there (the horizon of a hemisphere, the rim of the disk) are integrated without the boundary
// being evaluated on the wrong side by float rounding.
struct GaussRule {
    std::vector<double> x, w;
    explicit GaussRule(int n) : x(size_t(n)), w(size_t(n)) {
        for (int i = 0; i < n; ++i) {
            double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1;
            for (int it = 0; it < 100; ++it) {
                double p0 = 1, p1 = 0;
                for (int k = 1; k <= n; ++k) {  // recurrence k P_k = (2k-1) z P_{k-1} - (k-1) P_{k-2}
                    double p2 = p1;
                    p1 = p0;
                    p0 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p2) / k;
                }
                dp = n * (z * p0 - p1) / (z * z - 1.0);
                double dz = p0 / dp;
                z -= dz;
                if (std::abs(dz) < 1e-15) break;
            }
            x[size_t(i)] = 0.5 * (1.0 - z);
            w[size_t(i)] = 1.0 / ((1.0 - z * z) * dp * dp);  // 2 / ((1-z^2) P'^2), halved for [0,1]
        }
    }
};

// Integral of f * jacobian over cell (ix, iy) with an n x n Gauss-Legendre rule.
double integrate_cell(const Domain& d, const std::function<double(const dvec3&)>& f, int ix, int iy, int res_x,
                      int res_y, int n) {
    static thread_local std::vector<std::unique_ptr<GaussRule>> rules;
    n = std::clamp(n, 1, 64);
    if (rules.size() <= size_t(n)) rules.resize(size_t(n) + 1);
    if (!rules[size_t(n)]) rules[size_t(n)] = std::make_unique<GaussRule>(n);
    const GaussRule& q = *rules[size_t(n)];
    double x0 = double(ix) / res_x, y0 = double(iy) / res_y, hx = 1.0 / res_x, hy = 1.0 / res_y;
    double sum = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            dvec2 g(x0 + q.x[size_t(i)] * hx, y0 + q.x[size_t(j)] * hy);
            double v = f(d.to_point(g)) * d.jacobian(g);
            if (std::isfinite(v)) sum += q.w[size_t(i)] * q.w[size_t(j)] * v;
        }
    return sum * hx * hy;
}

// The chi-square statistic with pooling. `may_be_zero` marks cells whose expected count may
// legitimately round to 0 (the "failed" outcome, whose probability comes from 1 - integral).
ChiSquareResult pooled_chi_square(const std::vector<double>& obs, const std::vector<double>& expct,
                                  const std::vector<bool>& may_be_zero, double min_expected, int constraints) {
    ChiSquareResult r;
    struct Cell {
        double o, e;
    };
    std::vector<Cell> cells;
    for (size_t i = 0; i < obs.size(); ++i) {
        if (expct[i] <= 0.0 && obs[i] > 0.0 && !may_be_zero[i]) {
            r.p_value = 0.0;
            r.statistic = std::numeric_limits<double>::infinity();
            r.message = "cell " + std::to_string(i) + " holds " + fmt(obs[i]) + " samples where the pdf is 0";
            return r;
        }
        if (expct[i] > 0.0 || obs[i] > 0.0) cells.push_back({obs[i], std::max(expct[i], 0.0)});
    }
    std::sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.e < b.e; });
    std::vector<Cell> kept;
    Cell pool{0, 0};
    int pooled = 0;
    for (const Cell& c : cells) {
        if (c.e >= min_expected) {
            kept.push_back(c);
        } else {
            pool.o += c.o;
            pool.e += c.e;
            ++pooled;
            if (pool.e >= min_expected) {
                kept.push_back(pool);
                pool = {0, 0};
            }
        }
    }
    if (pool.o > 0 || pool.e > 0) {
        // A remainder too small to stand alone joins the smallest kept cell.
        if (kept.empty()) kept.push_back(pool);
        else {
            auto smallest = std::min_element(kept.begin(), kept.end(), [](const Cell& a, const Cell& b) { return a.e < b.e; });
            smallest->o += pool.o;
            smallest->e += pool.e;
        }
    }
    r.cells = int(cells.size());
    r.pooled_cells = pooled;
    r.dof = int(kept.size()) - 1 - constraints;
    for (const Cell& c : kept) {
        if (c.e > 0) r.statistic += (c.o - c.e) * (c.o - c.e) / c.e;
        else if (c.o > 0) r.statistic = std::numeric_limits<double>::infinity();
    }
    if (r.dof <= 0) {
        // A test without degrees of freedom tests nothing: it fails the calling test, and its p
        // is NaN, so that neither "p >= level" nor a control's "p < level" can hold.
        r.p_value = std::numeric_limits<double>::quiet_NaN();
        r.message = "too few cells for a chi-square test (" + std::to_string(kept.size()) + " after pooling, " +
                    std::to_string(constraints) + " constraints): choose a finer binning or more samples";
        ADD_FAILURE() << "chi-square test with " << r.dof << " degrees of freedom: " << r.message;
    } else {
        r.p_value = chi_square_sf(r.statistic, r.dof);
    }
    return r;
}
}  // namespace

double integrate_over_domain(const Domain& d, const std::function<double(const dvec3&)>& f, int res_x, int res_y,
                             int points) {
    double sum = 0;
    for (int iy = 0; iy < res_y; ++iy)
        for (int ix = 0; ix < res_x; ++ix) sum += integrate_cell(d, f, ix, iy, res_x, res_y, points);
    return sum;
}

ChiSquareResult chi_square_counts(const std::vector<double>& observed, const std::vector<double>& expected,
                                  double min_expected, int constraints) {
    if (observed.size() != expected.size()) throw std::invalid_argument("chi_square_counts: size mismatch");
    ChiSquareResult r =
        pooled_chi_square(observed, expected, std::vector<bool>(observed.size(), false), min_expected, constraints);
    r.observed = observed;
    r.expected = expected;
    return r;
}

ChiSquareResult chi_square_2d(const ChiSquareSetup& s) {
    const int nx = s.res_x, ny = s.res_y;
    const size_t n_grid = size_t(nx) * size_t(ny), n_disc = s.discrete_probabilities.size();
    const double N = double(s.samples);

    // Histogram of the samples.
    std::vector<double> obs(n_grid + n_disc + 1, 0.0);  // grid cells, discrete components, failed
    uint64_t outside = 0, failed = 0, smooth = 0;
    PCG32 rng(s.seed, 0x9e3779b97f4a7c15ULL);
    for (uint64_t i = 0; i < s.samples; ++i) {
        DomainSample ds = s.sample(rng);
        if (ds.kind == DomainSample::Failed) {
            ++failed;
        } else if (ds.kind == DomainSample::Discrete) {
            if (ds.component < 0 || size_t(ds.component) >= n_disc) ++outside;
            else obs[n_grid + size_t(ds.component)] += 1;
        } else {
            dvec2 g;
            if (!s.domain.to_grid(ds.p, g) || !std::isfinite(g.x) || !std::isfinite(g.y)) {
                ++outside;
                continue;
            }
            int ix = std::clamp(int(g.x * nx), 0, nx - 1), iy = std::clamp(int(g.y * ny), 0, ny - 1);
            obs[size_t(iy) * size_t(nx) + size_t(ix)] += 1;
            ++smooth;
        }
    }
    obs.back() = double(failed);

    // Expected counts.
    std::vector<double> exp(obs.size(), 0.0);
    double integral = 0;
    for (int iy = 0; iy < ny; ++iy)
        for (int ix = 0; ix < nx; ++ix) {
            double v = integrate_cell(s.domain, s.pdf, ix, iy, nx, ny, s.integration_points);
            integral += v;
            exp[size_t(iy) * size_t(nx) + size_t(ix)] = N * v;
        }
    double disc_total = 0;
    for (size_t k = 0; k < n_disc; ++k) {
        exp[n_grid + k] = N * s.discrete_probabilities[k];
        disc_total += s.discrete_probabilities[k];
    }
    exp.back() = std::max(0.0, N * (1.0 - integral - disc_total));

    std::vector<bool> may_be_zero(obs.size(), false);
    may_be_zero.back() = true;
    ChiSquareResult r;
    if (outside > 0) {
        r.p_value = 0.0;
        r.statistic = std::numeric_limits<double>::infinity();
        r.message = std::to_string(outside) + " samples outside the " + s.domain.name + " domain";
    } else {
        r = pooled_chi_square(obs, exp, may_be_zero, s.min_expected, 0);
    }
    r.pdf_integral = integral;
    r.smooth_count = smooth;
    r.failed_count = failed;
    r.outside_count = outside;
    r.failed_expected = exp.back();
    for (size_t k = 0; k < n_disc; ++k) {
        r.discrete_count.push_back(uint64_t(obs[n_grid + k]));
        r.discrete_expected.push_back(exp[n_grid + k]);
    }
    r.observed.assign(obs.begin(), obs.begin() + std::ptrdiff_t(n_grid));
    r.expected.assign(exp.begin(), exp.begin() + std::ptrdiff_t(n_grid));
    return r;
}

std::string ChiSquareResult::describe() const {
    std::ostringstream o;
    o << "chi2 = " << fmt(statistic) << ", dof = " << dof << ", p = " << fmt(p_value) << " (" << cells << " cells, "
      << pooled_cells << " pooled; pdf integral " << fmt(pdf_integral) << "; " << smooth_count << " smooth, "
      << failed_count << " failed (expected " << fmt(failed_expected) << "), " << outside_count << " outside)";
    for (size_t k = 0; k < discrete_count.size(); ++k)
        o << "; discrete " << k << ": " << discrete_count[k] << " (expected " << fmt(discrete_expected[k]) << ")";
    if (!message.empty()) o << "; " << message;
    return o.str();
}

// ---- image comparison ---------------------------------------------------------------------------

ImageEstimate ImageEstimate::from_moments(int width, int height, const std::vector<dvec3>& sum,
                                          const std::vector<dvec3>& sum_sq, const std::vector<uint32_t>& count) {
    ImageEstimate im;
    im.width = width;
    im.height = height;
    size_t n = size_t(width) * size_t(height);
    im.mean.assign(n, dvec3(0.0));
    im.var_of_mean.assign(n, dvec3(0.0));
    for (size_t i = 0; i < n; ++i) {
        double c = double(count[i]);
        if (c < 1) continue;
        im.mean[i] = sum[i] / c;
        if (c > 1) {
            // Unbiased per-sample variance from the moments, then divided by n for the mean.
            dvec3 var = glm::max((sum_sq[i] - sum[i] * im.mean[i]) / (c - 1.0), dvec3(0.0));
            im.var_of_mean[i] = var / c;
        }
    }
    return im;
}

ImageEstimate ImageEstimate::from_batches(const std::vector<const Film*>& batches) {
    if (batches.size() < 2) throw std::invalid_argument("from_batches needs at least two independent films");
    ImageEstimate im;
    im.width = batches[0]->width();
    im.height = batches[0]->height();
    for (const Film* f : batches)
        if (f->width() != im.width || f->height() != im.height)
            throw std::invalid_argument("from_batches: films differ in size");
    size_t n = size_t(im.width) * size_t(im.height);
    const double K = double(batches.size());
    im.mean.assign(n, dvec3(0.0));
    im.var_of_mean.assign(n, dvec3(0.0));
    // A weighted film (tent, gaussian) normalises by its weight sums, a box-filtered one by counts;
    // the batch means are then ratio estimators, whose spread still gives the variance.
    // A film of splats only (the light tracer on a weighted film: no camera weights): every batch
    // weighs the same.
    bool splats_only = true;
    for (const Film* f : batches)
        for (size_t i = 0; i < f->weights().size() && splats_only; ++i) splats_only = f->weights()[i] == 0.0;
    for (const Film* f : batches) splats_only = splats_only && f->weighted() && f->has_splats();
    auto norm = [&](const Film* f, size_t i) {
        return splats_only ? 1.0 : f->weighted() ? f->weights()[i] : double(f->counts()[i]);
    };
    for (size_t i = 0; i < n; ++i) {
        double total = 0;
        dvec3 sum(0.0);
        for (const Film* f : batches) {
            total += norm(f, i);
            sum += f->sums()[i];
        }
        if (total <= 0) continue;
        // Splats (light tracing) are already normalised per film: weighted like the batch means.
        dvec3 m = sum / total;
        for (const Film* f : batches) m += f->splat_value(i) * (norm(f, i) / total);
        im.mean[i] = m;
        // Weighted batch means: var(sum_k w_k m_k) estimated by K/(K-1) sum_k w_k^2 (m_k - m)^2,
        // which is s^2 / K for equal batches.
        dvec3 v(0.0);
        for (const Film* f : batches) {
            double c = norm(f, i);
            if (c <= 0) continue;
            double w = c / total;
            dvec3 d = f->sums()[i] / c + f->splat_value(i) - m;
            v += w * w * d * d;
        }
        im.var_of_mean[i] = v * (K / (K - 1.0));
    }
    return im;
}

ImageEstimate ImageEstimate::from_reference_files(const std::string& prefix) {
    Image mean = read_linear_image(prefix + "_mean.exr");
    Image var = read_linear_image(prefix + "_var.exr");
    if (var.width != mean.width || var.height != mean.height)
        throw std::runtime_error(prefix + ": the mean and variance images differ in size");
    ImageEstimate e;
    e.width = mean.width;
    e.height = mean.height;
    for (size_t i = 0; i + 2 < mean.rgb.size(); i += 3) {
        e.mean.push_back(dvec3(mean.rgb[i], mean.rgb[i + 1], mean.rgb[i + 2]));
        e.var_of_mean.push_back(dvec3(var.rgb[i], var.rgb[i + 1], var.rgb[i + 2]));
    }
    return e;
}

double whole_image_p(const ImageEstimate& a, const ImageEstimate& b, dvec3* rel) {
    dvec3 ma(0.0), mb(0.0), v(0.0);
    const double n = double(a.mean.size());
    for (size_t i = 0; i < a.mean.size(); ++i) {
        ma += a.mean[i];
        mb += b.mean[i];
        v += a.var_of_mean[i] + b.var_of_mean[i];
    }
    ma /= n;
    mb /= n;
    v /= n * n;
    double p_min = 1;
    for (int c = 0; c < 3; ++c) p_min = std::min(p_min, normal_two_sided_p((ma[c] - mb[c]) / std::sqrt(v[c])));
    if (rel) *rel = (ma - mb) / mb;
    return sidak_adjust(p_min, 3);
}

ImageEstimate ImageEstimate::from_film(const Film& film, const std::vector<dvec3>& var_of_mean) {
    ImageEstimate im;
    im.width = film.width();
    im.height = film.height();
    size_t n = size_t(im.width) * size_t(im.height);
    if (var_of_mean.size() != n) throw std::invalid_argument("from_film: variance image has the wrong size");
    im.mean.resize(n);
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) im.mean[size_t(y) * size_t(im.width) + size_t(x)] = dvec3(film.pixel(x, y));
    im.var_of_mean = var_of_mean;
    return im;
}

BlockTestResult block_z_test(const ImageEstimate& a, const ImageEstimate& b, int block, double alpha,
                             double rel_floor) {
    if (a.width != b.width || a.height != b.height) throw std::invalid_argument("block_z_test: sizes differ");
    block = std::max(block, 1);
    struct Test {
        double p, z;
        int x, y, c;
    };
    std::vector<Test> tests;
    for (int by = 0; by < a.height; by += block)
        for (int bx = 0; bx < a.width; bx += block) {
            dvec3 ma(0.0), mb(0.0), va(0.0), vb(0.0);
            double n = 0;
            for (int y = by; y < std::min(by + block, a.height); ++y)
                for (int x = bx; x < std::min(bx + block, a.width); ++x) {
                    size_t i = size_t(y) * size_t(a.width) + size_t(x);
                    ma += a.mean[i];
                    mb += b.mean[i];
                    va += a.var_of_mean[i];
                    vb += b.var_of_mean[i];
                    n += 1;
                }
            ma /= n;
            mb /= n;
            va /= n * n;
            vb /= n * n;
            for (int c = 0; c < 3; ++c) {
                if (ma[c] == 0 && mb[c] == 0 && va[c] == 0 && vb[c] == 0) continue;
                double floor = rel_floor * std::max(std::abs(ma[c]), std::abs(mb[c]));
                double se = std::sqrt(va[c] + vb[c] + floor * floor);
                double d = ma[c] - mb[c];
                double z = se > 0 ? d / se : (d == 0 ? 0.0 : std::numeric_limits<double>::infinity());
                tests.push_back({normal_two_sided_p(z), z, bx, by, c});
            }
        }
    BlockTestResult r;
    r.tests = int(tests.size());
    int failing = 0;
    for (const Test& t : tests) {
        if (t.p < alpha) ++failing;
        if (std::abs(t.z) > r.max_abs_z || std::isnan(t.z)) r.max_abs_z = std::abs(t.z);
        if (t.p < r.p_min || r.worst_x < 0) {
            r.p_min = t.p;
            r.worst_x = t.x;
            r.worst_y = t.y;
            r.worst_channel = t.c;
        }
    }
    r.failing_fraction = tests.empty() ? 0.0 : double(failing) / double(tests.size());
    r.p_family = tests.empty() ? 1.0 : sidak_adjust(r.p_min, r.tests);
    return r;
}

std::string BlockTestResult::describe() const {
    std::ostringstream o;
    o << tests << " block tests: min p = " << fmt(p_min) << " at block (" << worst_x << ", " << worst_y
      << ") channel " << worst_channel << ", family-wise (Sidak) p = " << fmt(p_family) << ", max |z| = "
      << fmt(max_abs_z) << ", failing fraction " << fmt(failing_fraction);
    return o.str();
}

}  // namespace candela::stats
