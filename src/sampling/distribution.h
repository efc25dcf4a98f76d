#pragma once
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

    // Index i with cdf[i] <= u < cdf[i+1]; entries of zero weight are never returned.
    size_t sample(float u, float* pmf_out = nullptr, float* u_remapped = nullptr) const {
        auto it = std::upper_bound(cdf_f_.begin(), cdf_f_.end(), u);
        size_t i = size_t(std::max<std::ptrdiff_t>(it - cdf_f_.begin() - 1, 0));
        i = std::min(i, pmf_.size() - 1);
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

}  // namespace candela
