#pragma once
// FA-Harris written plainly from its definition (docs/fa_harris.md), as an oracle for the
// fast path: the Arc* oracle's filter and arc test (arcstar_naive.hpp), an arrival number
// per filtered write, and the window's filtered pixels fully sorted by (time, arrival),
// the newest nl lit and scored by the plain Harris of harris_naive.hpp.

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "evcorner/fa_harris.hpp"
#include "evcorner/naive/arcstar_naive.hpp"
#include "evcorner/naive/harris_naive.hpp"

namespace evcorner::naive {

class FaHarrisNaive {
public:
    explicit FaHarrisNaive(SensorSize size, const FaHarrisParams& p = {})
        : p_(p), s_(size, ArcStarParams{p.filter, p.filter_us, p.minority_only, p.zero_init}) {
        for (auto& a : arrival_) a.assign(static_cast<std::size_t>(size.pixels()), 0);
    }

    bool process(const Event& e) {
        score_ = std::numeric_limits<double>::quiet_NaN();
        const SensorSize z = s_.size();
        if (e.x < 4 || e.x >= z.width - 4 || e.y < 4 || e.y >= z.height - 4) return false;  // no state change
        if (!s_.filter(e)) return false;
        s_.write_filtered(e);
        arrival_[e.p][static_cast<std::size_t>(e.y) * z.width + e.x] = ++arrivals_;
        if (!s_.arc_test(e.p, e.x, e.y)) return false;
        struct Cell {
            std::int64_t t;
            std::int64_t arrival;
            int dx, dy;
        };
        std::vector<Cell> fired;
        const int r = p_.window / 2;
        for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
                const int x = e.x + dx, y = e.y + dy;
                if (!z.contains(x, y)) continue;
                const std::int64_t t = s_.filtered(e.p, x, y);
                if (t == kNeverNaive) continue;
                fired.push_back({t, arrival_[e.p][static_cast<std::size_t>(y) * z.width + x], dx, dy});
            }
        if (static_cast<int>(fired.size()) < p_.nl) return false;
        std::sort(fired.begin(), fired.end(), [](const Cell& a, const Cell& b) {
            return a.t != b.t ? a.t > b.t : a.arrival > b.arrival;
        });
        std::vector<std::vector<int>> patch(p_.window, std::vector<int>(p_.window, 0));
        for (int i = 0; i < p_.nl; ++i) patch[fired[i].dy + r][fired[i].dx + r] = 1;
        score_ = harris_score_naive(patch, p_.k);
        return score_ > p_.threshold;
    }
    double last_score() const { return score_; }

private:
    FaHarrisParams p_;
    ArcStarStateNaive s_;
    std::vector<std::int64_t> arrival_[2];
    std::int64_t arrivals_ = 0;
    double score_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace evcorner::naive
