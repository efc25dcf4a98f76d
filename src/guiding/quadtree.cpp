#include "guiding/quadtree.h"
#include <queue>
#include "sampling/warp.h"

namespace candela::guiding {

using glm::dvec2;

namespace {

constexpr double kOneBelow = 0x1.fffffffffffffp-1;

// The probabilities of a node's halves as sample_square draws them: first the column (x below or
// above the middle), then the quadrant within the column. sample_square and pdf_square both use
// these, so that the density pdf reports is the one sampling realises, rounding included.
struct Split {
    double px;  // P(x < half)
    double py;  // P(y < half | the chosen column)
};
Split split_of(const Quadtree::Node& n, int column) {
    const double left = n.sum[0] + n.sum[2];
    const double t = left + n.sum[1] + n.sum[3];
    const double a = n.sum[column], b = n.sum[column + 2];
    return {left / t, a + b > 0 ? a / (a + b) : 0.5};
}
double quadrant_probability(const Split& s, int q) {
    return ((q & 1) ? 1.0 - s.px : s.px) * ((q & 2) ? 1.0 - s.py : s.py);
}
double node_total(const Quadtree::Node& n) { return n.sum[0] + n.sum[1] + n.sum[2] + n.sum[3]; }

}  // namespace

double Quadtree::total() const { return node_total(nodes_[0]); }

int Quadtree::depth() const {
    int deepest = 1;
    std::vector<std::pair<uint32_t, int>> stack{{0u, 1}};
    while (!stack.empty()) {
        auto [n, d] = stack.back();
        stack.pop_back();
        deepest = std::max(deepest, d);
        for (uint32_t c : nodes_[n].child)
            if (c) stack.push_back({c, d + 1});
    }
    return deepest;
}

int Quadtree::depth_at(vec2 p) const {
    uint32_t n = 0;
    dvec2 o(0.0), x(p);
    double size = 1.0;
    for (int d = 1;; ++d) {
        const double half = 0.5 * size;
        const int q = int(x.x >= o.x + half) + 2 * int(x.y >= o.y + half);
        if (!nodes_[n].child[q]) return d;
        o += half * dvec2(q & 1, q >> 1);
        size = half;
        n = nodes_[n].child[q];
    }
}

void Quadtree::record(vec2 p, double value, DirectionalFilter filter) {
    if (!(value > 0) || !std::isfinite(value)) return;
    if (filter == DirectionalFilter::Nearest) {
        uint32_t n = 0;
        dvec2 o(0.0);
        double size = 1.0;
        for (;;) {
            const double half = 0.5 * size;
            const int q = int(p.x >= o.x + half) + 2 * int(p.y >= o.y + half);
            nodes_[n].sum[q] += value;
            if (!nodes_[n].child[q]) return;
            o += half * dvec2(q & 1, q >> 1);
            size = half;
            n = nodes_[n].child[q];
        }
    }
    // Box: the landing cell's size, clipped in x (the poles), wrapped in y (phi is periodic).
    const double s = std::ldexp(1.0, -depth_at(p));
    dvec2 lo = dvec2(p) - 0.5 * s, hi = dvec2(p) + 0.5 * s;
    lo.x = std::max(lo.x, 0.0);
    hi.x = std::min(hi.x, 1.0);
    const double density = value / ((hi.x - lo.x) * s);
    if (lo.y < 0.0) {
        add_box(0, dvec2(0.0), 1.0, dvec2(lo.x, lo.y + 1.0), dvec2(hi.x, 1.0), density);
        add_box(0, dvec2(0.0), 1.0, dvec2(lo.x, 0.0), hi, density);
    } else if (hi.y > 1.0) {
        add_box(0, dvec2(0.0), 1.0, lo, dvec2(hi.x, 1.0), density);
        add_box(0, dvec2(0.0), 1.0, dvec2(lo.x, 0.0), dvec2(hi.x, hi.y - 1.0), density);
    } else {
        add_box(0, dvec2(0.0), 1.0, lo, hi, density);
    }
}

void Quadtree::add_box(uint32_t node, dvec2 origin, double size, dvec2 lo, dvec2 hi, double density) {
    const double half = 0.5 * size;
    for (int q = 0; q < 4; ++q) {
        const dvec2 co = origin + half * dvec2(q & 1, q >> 1);
        const dvec2 overlap = glm::max(glm::min(hi, co + half) - glm::max(lo, co), dvec2(0.0));
        const double area = overlap.x * overlap.y;
        if (!(area > 0)) continue;
        nodes_[node].sum[q] += density * area;
        if (nodes_[node].child[q]) add_box(nodes_[node].child[q], co, half, lo, hi, density);
    }
}

void Quadtree::record_direction(vec3 dir, double value, DirectionalFilter filter) {
    record(uniform_sphere_to_square(dir), value, filter);
}

vec2 Quadtree::sample_square(vec2 u_in, double* pdf_square) const {
    dvec2 u(u_in), o(0.0);
    double size = 1.0, density = 1.0;
    uint32_t n = 0;
    for (;;) {
        const Node& node = nodes_[n];
        if (!(node_total(node) > 0)) break;  // nothing recorded below: uniform over the node
        const double px = split_of(node, 0).px;
        const int column = u.x < px ? 0 : 1;
        u.x = column == 0 ? u.x / px : (u.x - px) / (1.0 - px);
        const Split s = split_of(node, column);
        const int row = u.y < s.py ? 0 : 1;
        u.y = row == 0 ? u.y / s.py : (u.y - s.py) / (1.0 - s.py);
        u = glm::clamp(u, dvec2(0.0), dvec2(kOneBelow));
        const int q = column + 2 * row;
        density *= 4.0 * quadrant_probability(s, q);
        size *= 0.5;
        o += size * dvec2(q & 1, q >> 1);
        if (!node.child[q]) break;
        n = node.child[q];
    }
    if (pdf_square) *pdf_square = density;
    const dvec2 p = glm::min(o + size * u, dvec2(kOneBelow));
    return vec2(p);
}

double Quadtree::pdf_square(vec2 p) const {
    dvec2 o(0.0);
    double size = 1.0, density = 1.0;
    uint32_t n = 0;
    for (;;) {
        const Node& node = nodes_[n];
        if (!(node_total(node) > 0)) return density;
        const double half = 0.5 * size;
        const int column = int(p.x >= o.x + half), row = int(p.y >= o.y + half);
        const int q = column + 2 * row;
        const double prob = quadrant_probability(split_of(node, column), q);
        if (!(prob > 0)) return 0.0;
        density *= 4.0 * prob;
        size = half;
        o += half * dvec2(column, row);
        if (!node.child[q]) return density;
        n = node.child[q];
    }
}

vec3 Quadtree::sample(vec2 u, float* pdf_out) const {
    double density = 0;
    const vec2 p = sample_square(u, &density);
    if (pdf_out) *pdf_out = float(density) * kInv4Pi;
    return square_to_uniform_sphere(p);
}

float Quadtree::pdf(vec3 dir) const { return float(pdf_square(uniform_sphere_to_square(dir))) * kInv4Pi; }

Quadtree Quadtree::refined(const Quadtree& stats, double rho, int max_depth, size_t max_nodes) {
    const double total = stats.total();
    // A quadrant that may be split: its share of the energy, where the statistics of its children
    // are (src: stats' node for it, 0 when stats did not split it and its share is spread evenly).
    struct Candidate {
        double share;
        uint64_t order;  // tie-break: first found, first split
        uint32_t node;
        int q, depth;
        uint32_t src;
        bool operator<(const Candidate& o) const { return share != o.share ? share < o.share : order > o.order; }
    };
    std::priority_queue<Candidate> heap;
    uint64_t order = 0;
    for (int q = 0; q < 4; ++q)
        heap.push({total > 0 ? stats.nodes_[0].sum[q] / total : 0.25, order++, 0u, q, 1, stats.nodes_[0].child[q]});
    Quadtree out;
    while (!heap.empty()) {
        const Candidate c = heap.top();
        heap.pop();
        if (!(c.share > rho) || out.nodes_.size() + 1 > max_nodes) break;  // the rest hold less
        if (c.depth >= max_depth) continue;
        const uint32_t m = uint32_t(out.nodes_.size());
        out.nodes_.emplace_back();
        out.nodes_[c.node].child[c.q] = m;
        for (int i = 0; i < 4; ++i) {
            const double share = c.src && total > 0 ? stats.nodes_[c.src].sum[i] / total : 0.25 * c.share;
            heap.push({share, order++, m, i, c.depth + 1, c.src ? stats.nodes_[c.src].child[i] : 0u});
        }
    }
    return out;
}

void Quadtree::scale(double factor) {
    for (Node& n : nodes_)
        for (double& s : n.sum) s *= factor;
}

bool Quadtree::operator==(const Quadtree& o) const {
    if (nodes_.size() != o.nodes_.size()) return false;
    for (size_t i = 0; i < nodes_.size(); ++i)
        if (nodes_[i].sum != o.nodes_[i].sum || nodes_[i].child != o.nodes_[i].child) return false;
    return true;
}

}  // namespace candela::guiding
