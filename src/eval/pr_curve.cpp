#include "evcorner/eval/pr_curve.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace evcorner::eval {

namespace {
double key(double s) { return std::isnan(s) ? -std::numeric_limits<double>::infinity() : s; }
}  // namespace

PrCurve pr_curve(std::span<const double> scores, std::span<const std::uint8_t> is_true,
                 std::span<const double> recalled_best, std::uint64_t truth_samples) {
    if (scores.size() != is_true.size())
        throw std::invalid_argument("pr_curve: " + std::to_string(scores.size()) + " scores for " +
                                    std::to_string(is_true.size()) + " corner events");
    if (recalled_best.size() > truth_samples)
        throw std::invalid_argument("pr_curve: more recalled samples than truth samples");
    std::vector<std::size_t> order(scores.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(scores[a]) > key(scores[b]); });
    std::vector<double> best(recalled_best.size());
    std::transform(recalled_best.begin(), recalled_best.end(), best.begin(), key);
    std::sort(best.begin(), best.end(), std::greater<>());
    PrCurve c;
    std::size_t i = 0, j = 0;
    std::uint64_t tp = 0;
    double prev_recall = 0;
    while (i < order.size()) {
        const double th = key(scores[order[i]]);
        for (; i < order.size() && key(scores[order[i]]) == th; ++i) tp += is_true[order[i]] != 0;
        for (; j < best.size() && best[j] >= th; ++j) {
        }
        const double p = static_cast<double>(tp) / static_cast<double>(i);
        const double r = truth_samples ? static_cast<double>(j) / static_cast<double>(truth_samples) : 0.0;
        c.average_precision += (r - prev_recall) * p;
        prev_recall = r;
        c.points.push_back({th, 100.0 * p, 100.0 * r});
    }
    return c;
}

std::vector<PrPoint> thin(const std::vector<PrPoint>& points, std::size_t n) {
    n = std::max<std::size_t>(n, 2);
    if (points.size() <= n) return points;
    std::vector<PrPoint> out;
    for (std::size_t k = 0; k < n; ++k) out.push_back(points[k * (points.size() - 1) / (n - 1)]);
    return out;
}

std::vector<double> precision_at_recall(const std::vector<PrPoint>& points, std::span<const double> levels) {
    std::vector<double> out;
    for (const double level : levels) {
        double best = std::nan("");
        for (const PrPoint& p : points)
            if (p.recall >= level && !(p.precision <= best)) best = p.precision;
        out.push_back(best);
    }
    return out;
}

}  // namespace evcorner::eval
