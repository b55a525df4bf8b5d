#pragma once
// The event-based Harris detectors written plainly from their definitions, as oracles
// for the fast paths (docs/harris.md; Mueggler et al., BMVC 2017, Sec. 3.2;
// Vasco et al., IROS 2016):
// - HarrisNaive: keeps every event of the stream; per event, fully sorts the fired
//   pixels of the window by arrival and lights the newest nl of them;
// - HarrisGlobalNaive: per event, walks the whole history of its polarity backwards to
//   find the newest n distinct pixels of the sensor;
// both then score the patch by plain double convolution loops. Slow on purpose.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::naive {

/// The Harris score of a w x w binary patch (patch[y][x], 0 or 1), by definition.
inline double harris_score_naive(const std::vector<std::vector<int>>& patch, double k) {
    const int w = static_cast<int>(patch.size());
    const int g = w - 4;
    const double sm[5] = {1, 4, 6, 4, 1};
    const double de[5] = {1, 2, 0, -2, -1};
    double gx[5][5], gy[5][5];
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) {
            gx[i][j] = sm[i] * de[j] / 12.0;  // row i (y), column j (x)
            gy[j][i] = gx[i][j];
        }
    std::vector<std::vector<double>> ix(g, std::vector<double>(g)), iy = ix, h = ix;
    for (int r = 0; r < g; ++r)
        for (int c = 0; c < g; ++c) {
            double sx = 0, sy = 0;
            for (int i = 0; i < 5; ++i)
                for (int j = 0; j < 5; ++j) {
                    sx += gx[i][j] * patch[r + i][c + j];
                    sy += gy[i][j] * patch[r + i][c + j];
                }
            ix[r][c] = sx;
            iy[r][c] = sy;
        }
    double sum = 0;
    const double mid = (g - 1) / 2.0;
    for (int r = 0; r < g; ++r)
        for (int c = 0; c < g; ++c) {
            h[r][c] = std::exp(-((r - mid) * (r - mid) + (c - mid) * (c - mid)) / 2.0);
            sum += h[r][c];
        }
    double a = 0, b = 0, cc = 0;
    for (int r = 0; r < g; ++r)
        for (int c = 0; c < g; ++c) {
            const double hw = h[r][c] / sum;
            a += hw * ix[r][c] * ix[r][c];
            b += hw * ix[r][c] * iy[r][c];
            cc += hw * iy[r][c] * iy[r][c];
        }
    return a * cc - b * b - k * (a + cc) * (a + cc);
}

class HarrisNaive {
public:
    HarrisNaive(SensorSize size, int window = 9, int nl = 25, double k = 0.04, double threshold = 8)
        : size_(size), w_(window), nl_(nl), k_(k), threshold_(threshold),
          last_(2, std::vector<std::int64_t>(static_cast<std::size_t>(size.pixels()), -1)) {}

    bool process(const Event& e) {
        const int p = e.p != 0;
        last_[p][static_cast<std::size_t>(e.y) * size_.width + e.x] = arrivals_++;
        score_ = std::numeric_limits<double>::quiet_NaN();
        const int r = w_ / 2;
        if (e.x < r || e.x > size_.width - r || e.y < r || e.y > size_.height - r) return false;
        struct Fired { std::int64_t arrival; int dx, dy; };
        std::vector<Fired> fired;
        for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
                const int x = e.x + dx, y = e.y + dy;
                if (!size_.contains(x, y)) continue;
                const std::int64_t a = last_[p][static_cast<std::size_t>(y) * size_.width + x];
                if (a >= 0) fired.push_back({a, dx, dy});
            }
        if (static_cast<int>(fired.size()) < nl_) return false;
        std::sort(fired.begin(), fired.end(), [](const Fired& u, const Fired& v) { return u.arrival > v.arrival; });
        std::vector<std::vector<int>> patch(w_, std::vector<int>(w_, 0));
        for (int i = 0; i < nl_; ++i) patch[fired[i].dy + r][fired[i].dx + r] = 1;
        score_ = harris_score_naive(patch, k_);
        return score_ > threshold_;
    }
    double last_score() const { return score_; }

private:
    SensorSize size_;
    int w_, nl_;
    double k_, threshold_;
    std::vector<std::vector<std::int64_t>> last_;  // arrival index of each pixel's latest event
    std::int64_t arrivals_ = 0;
    double score_ = std::numeric_limits<double>::quiet_NaN();
};

class HarrisGlobalNaive {
public:
    HarrisGlobalNaive(SensorSize size, int n = 1000, int window = 9, double k = 0.04, double threshold = 8)
        : size_(size), n_(n), w_(window), k_(k), threshold_(threshold) {}

    /// The pixels (y * width + x) lit on polarity p: the newest n distinct ones.
    std::vector<int> lit_pixels(int p) const {
        std::vector<char> seen(static_cast<std::size_t>(size_.pixels()), 0);
        std::vector<int> lit;
        for (auto it = history_[p].rbegin(); it != history_[p].rend() && static_cast<int>(lit.size()) < n_; ++it)
            if (!seen[*it]) {
                seen[*it] = 1;
                lit.push_back(*it);
            }
        return lit;
    }

    bool process(const Event& e) {
        const int p = e.p != 0;
        history_[p].push_back(e.y * size_.width + e.x);
        score_ = std::numeric_limits<double>::quiet_NaN();
        const int r = w_ / 2;
        if (e.x < r || e.x > size_.width - r || e.y < r || e.y > size_.height - r) return false;
        std::vector<std::vector<int>> patch(w_, std::vector<int>(w_, 0));
        for (int id : lit_pixels(p)) {
            const int dx = id % size_.width - e.x, dy = id / size_.width - e.y;
            if (dx >= -r && dx <= r && dy >= -r && dy <= r) patch[dy + r][dx + r] = 1;
        }
        score_ = harris_score_naive(patch, k_);
        return score_ > threshold_;
    }
    double last_score() const { return score_; }

private:
    SensorSize size_;
    int n_, w_;
    double k_, threshold_;
    std::vector<int> history_[2];
    double score_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace evcorner::naive
