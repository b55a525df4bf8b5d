#include "evcorner/harris.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace evcorner {

namespace {

HarrisParams validated(HarrisParams p) {
    // The window and k are checked by HarrisScorer; nl depends on the window.
    if (p.window >= HarrisScorer::kMinWindow && p.window <= HarrisScorer::kMaxWindow &&
        (p.nl < 1 || p.nl > p.window * p.window))
        throw std::invalid_argument("Harris nl must be within 1.." + std::to_string(p.window * p.window) +
                                    " (window^2) (got " + std::to_string(p.nl) + ")");
    if (!std::isfinite(p.threshold)) throw std::invalid_argument("Harris threshold must be a finite number");
    return p;
}

}  // namespace

Harris::Harris(SensorSize size, HarrisParams params)
    : params_(validated(params)),
      scorer_(params_.window, params_.k),
      sae_(size, params_.window / 2),
      radius_(params_.window / 2) {}

bool Harris::process(const Event& e) noexcept {
    sae_.update(e);
    score_ = kNoScore;
    const SensorSize s = sae_.size();
    // The reference's border rule: '>' on the far side, so the window of an event at
    // x = width - r reaches one column past the sensor (read as never fired).
    if (e.x < radius_ || e.x > s.width - radius_ || e.y < radius_ || e.y > s.height - radius_)
        return false;

    const int w = params_.window;
    const std::uint64_t* row = sae_.plane(e.p != 0) + sae_.index(e.x - radius_, e.y - radius_);
    // Key = sequence number above the (row, column) of the pixel; sequence numbers are
    // unique, so the keys order the fired pixels by arrival.
    std::uint64_t keys[HarrisScorer::kMaxWindow * HarrisScorer::kMaxWindow];
    int m = 0;
    for (int r = 0; r < w; ++r, row += sae_.stride())
        for (int c = 0; c < w; ++c) {
            const std::uint64_t seq = row[c];
            keys[m] = seq << 8 | static_cast<std::uint64_t>(r << 4 | c);
            m += seq != 0;
        }
    const int nl = params_.nl;
    if (m < nl) return false;
    std::uint64_t* newest = keys + (m - nl);
    if (m > nl) std::nth_element(keys, newest, keys + m);

    std::uint16_t rows[HarrisScorer::kMaxWindow] = {};
    for (int i = 0; i < nl; ++i) rows[newest[i] >> 4 & 15] |= static_cast<std::uint16_t>(1u << (newest[i] & 15));
    score_ = scorer_.score(rows);
    return score_ > params_.threshold;
}

}  // namespace evcorner
