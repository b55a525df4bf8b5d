#include "evcorner/harris_global.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace evcorner {

namespace {

HarrisGlobalParams validated(HarrisGlobalParams p) {
    // The window and k are checked by HarrisScorer.
    if (p.n < 1)
        throw std::invalid_argument("Harris-global n must be within 1..2147483647 (got " + std::to_string(p.n) + ")");
    if (!std::isfinite(p.threshold))
        throw std::invalid_argument("Harris-global threshold must be a finite number");
    return p;
}

}  // namespace

HarrisGlobal::HarrisGlobal(SensorSize size, HarrisGlobalParams params)
    : params_(validated(params)),
      scorer_(params_.window, params_.k),
      sae_(checked_sensor_size(size, "Harris-global"), params_.window / 2),
      newest_{NewestPixels(static_cast<std::size_t>(params_.n), static_cast<std::size_t>(size.pixels())),
              NewestPixels(static_cast<std::size_t>(params_.n), static_cast<std::size_t>(size.pixels()))},
      radius_(params_.window / 2) {}

bool HarrisGlobal::process_unchecked(const Event& e) noexcept {
    const int p = e.p != 0;
    const std::size_t id = sae_.index(e.x, e.y);
    const std::uint64_t previous = sae_.plane(p)[id];
    const std::uint64_t seq = sae_.update_unchecked(e);
    newest_[p].push(id, seq, previous, sae_.plane(p));
    score_ = kNoScore;
    const SensorSize s = sae_.size();
    if (e.x < radius_ || e.x > s.width - radius_ || e.y < radius_ || e.y > s.height - radius_)
        return false;

    const int w = params_.window;
    const std::uint64_t threshold = newest_[p].threshold();  // >= 1: never-fired cells stay dark
    const std::uint64_t* row = sae_.plane(p) + sae_.index(e.x - radius_, e.y - radius_);
    std::uint16_t rows[HarrisScorer::kMaxWindow];
    for (int r = 0; r < w; ++r, row += sae_.stride()) {
        unsigned bits = 0;
        for (int c = 0; c < w; ++c) bits |= static_cast<unsigned>(row[c] >= threshold) << c;
        rows[r] = static_cast<std::uint16_t>(bits);
    }
    score_ = scorer_.score(rows);
    return score_ > params_.threshold;
}

}  // namespace evcorner
