#pragma once
#include <algorithm>
#include <cmath>
#include <vector>
#include "core/math.h"

namespace candela {

// A discrete distribution proportional to non-negative weights. sample() returns an index with
// probability pmf(index) and rescales u so that the same number can be reused.
class DiscreteDistribution {
public:
    DiscreteDistribution() = default;
    explicit DiscreteDistribution(const std::vector<float>& weights) { build(weights); }

    void build(const std::vector<float>& weights) {
        cdf_.assign(weights.size() + 1, 0.0);
        for (size_t i = 0; i < weights.size(); ++i) cdf_[i + 1] = cdf_[i] + double(std::max(weights[i], 0.f));
        total_ = cdf_.back();
        pmf_.resize(weights.size());
        for (size_t i = 0; i < weights.size(); ++i)
            pmf_[i] = total_ > 0 ? float(double(std::max(weights[i], 0.f)) / total_) : 0.f;
        cdf_f_.resize(cdf_.size());
        for (size_t i = 0; i < cdf_.size(); ++i) cdf_f_[i] = total_ > 0 ? float(cdf_[i] / total_) : 0.f;
        cdf_f_.back() = 1.f;
    }

    size_t size() const { return pmf_.size(); }
    bool empty() const { return pmf_.empty() || total_ <= 0; }
    double total() const { return total_; }
    float pmf(size_t i) const { return pmf_[i]; }
    // The float CDF (size() + 1 entries, from 0) and the pmfs, for vector copies of sample().
    const float* cdf_data() const { return cdf_f_.data(); }
    const float* pmf_data() const { return pmf_.data(); }

    // Index i with cdf[i] <= u < cdf[i+1]; entries of zero weight are never returned.
    size_t sample(float u, float* pmf_out = nullptr, float* u_remapped = nullptr) const {
        // upper_bound - 1 (clamped to 0) as a branchless binary search: the last entry that u is
        // not below (cdf_f_[0] = 0 is never compared). Its steps depend on u, which a branch
        // predictor cannot follow.
        const float* base = cdf_f_.data();
        for (size_t n = cdf_f_.size(); n > 1;) {
            const size_t half = n / 2;
            base = u < base[half] ? base : base + half;
            n -= half;
        }
        size_t i = std::min(size_t(base - cdf_f_.data()), pmf_.size() - 1);
        while (pmf_[i] == 0.f && i > 0) --i;  // u landed on a zero-width bin: step back
        while (pmf_[i] == 0.f && i + 1 < pmf_.size()) ++i;
        if (pmf_out) *pmf_out = pmf_[i];
        if (u_remapped) {
            float w = cdf_f_[i + 1] - cdf_f_[i];
            *u_remapped = w > 0 ? std::min((u - cdf_f_[i]) / w, 0x1.fffffep-1f) : 0.f;
        }
        return i;
    }

    size_t memory_bytes() const {
        return cdf_.capacity() * sizeof(double) + (cdf_f_.capacity() + pmf_.capacity()) * sizeof(float);
    }

private:
    std::vector<double> cdf_;
    std::vector<float> cdf_f_;
    std::vector<float> pmf_;
    double total_ = 0;
};


// A piecewise-constant density on [0,1]^2 from a grid of nu x nv non-negative cell weights
// (row-major, f[j * nu + i] for column i, row j; u runs along a row, v across rows): the marginal
// over rows, then the conditional within the chosen row, both inverted continuously (pbrt's
// PiecewiseConstant2D). The density w.r.t. area in (u, v) is f(cell) / mean(f): sample() and
// pdf() agree on it, and a cell of zero weight is never sampled. Two floats per cell.
class Distribution2D {
public:
    Distribution2D() = default;
    Distribution2D(const std::vector<float>& f, int nu, int nv) { build(f, nu, nv); }

    void build(const std::vector<float>& f, int nu, int nv) {
        nu_ = nu;
        nv_ = nv;
        func_.resize(size_t(nu) * size_t(nv));
        cdf_.assign(size_t(nu + 1) * size_t(nv), 0.f);
        std::vector<float> row_sums(size_t(nv), 0.f);
        row_sum_.assign(size_t(nv), 0.0);
        for (int j = 0; j < nv; ++j) {
            double acc = 0;
            std::vector<double> c(size_t(nu) + 1, 0.0);
            for (int i = 0; i < nu; ++i) {
                float w = f[size_t(j) * size_t(nu) + size_t(i)];
                w = std::isfinite(w) && w > 0.f ? w : 0.f;
                func_[size_t(j) * size_t(nu) + size_t(i)] = w;
                acc += double(w);
                c[size_t(i) + 1] = acc;
            }
            float* row = &cdf_[size_t(j) * size_t(nu + 1)];
            for (int i = 0; i <= nu; ++i) row[i] = acc > 0 ? float(c[size_t(i)] / acc) : float(i) / float(nu);
            row[nu] = 1.f;
            row_sums[size_t(j)] = float(acc);
            row_sum_[size_t(j)] = acc;
        }
        marginal_.build(row_sums);
    }

    bool empty() const { return marginal_.empty(); }
    int nu() const { return nu_; }
    int nv() const { return nv_; }

    // A point of [0,1)^2 with density *pdf (w.r.t. area in uv); false when every weight is 0.
    bool sample(vec2 u, vec2& uv, float& pdf) const {
        if (empty()) return false;
        float pmf_row, ur;
        const size_t j = marginal_.sample(u.y, &pmf_row, &ur);
        const float* row = &cdf_[j * size_t(nu_ + 1)];
        const float* it = std::upper_bound(row, row + nu_ + 1, u.x);
        size_t i = size_t(std::max<std::ptrdiff_t>(it - row - 1, 0));
        i = std::min(i, size_t(nu_ - 1));
        const float* fr = &func_[j * size_t(nu_)];
        while (fr[i] == 0.f && i > 0) --i;  // u landed on a zero-width bin: step back
        while (fr[i] == 0.f && i + 1 < size_t(nu_)) ++i;
        const float w = row[i + 1] - row[i];
        const float uc = w > 0 ? glm::clamp((u.x - row[i]) / w, 0.f, 0x1.fffffep-1f) : 0.5f;
        uv = vec2((float(i) + uc) / float(nu_), (float(j) + ur) / float(nv_));
        uv = glm::min(uv, vec2(0x1.fffffep-1f));
        pdf = cell_pdf(i, j, pmf_row);
        return pdf > 0.f;
    }

    // The density of sample() at uv (cells are half-open; uv outside [0,1]^2 is clamped in).
    float pdf(vec2 uv) const {
        if (empty()) return 0.f;
        const size_t i = size_t(glm::clamp(int(uv.x * float(nu_)), 0, nu_ - 1));
        const size_t j = size_t(glm::clamp(int(uv.y * float(nv_)), 0, nv_ - 1));
        return cell_pdf(i, j, marginal_.pmf(j));
    }

    size_t memory_bytes() const {
        return func_.capacity() * sizeof(float) + cdf_.capacity() * sizeof(float) +
               row_sum_.capacity() * sizeof(double) + marginal_.memory_bytes();
    }

private:
    int nu_ = 0, nv_ = 0;
    std::vector<float> func_;      // the weights, clamped to [0, inf)
    std::vector<float> cdf_;       // per row, nu + 1 entries from 0 to 1
    std::vector<double> row_sum_;  // per row, the sum of its weights
    DiscreteDistribution marginal_;

    // pmf(row) * pmf(cell | row) * nu * nv (the cells have area 1 / (nu nv)).
    float cell_pdf(size_t i, size_t j, float pmf_row) const {
        const double rs = row_sum_[j];
        if (!(rs > 0)) return 0.f;
        return float(double(pmf_row) * double(func_[j * size_t(nu_) + i]) / rs * double(nu_) * double(nv_));
    }
};

}  // namespace candela
