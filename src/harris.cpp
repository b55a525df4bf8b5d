#include "evcorner/harris.hpp"

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

const char* harris_code_path() noexcept { return harris_path_name(harris_default_path()); }

Harris::Harris(SensorSize size, HarrisParams params, int planes)
    : params_(validated(params)),
      scorer_(params_.window, params_.k),
      sae_(checked_sensor_size(size, "Harris"), params_.window / 2, planes),
      radius_(params_.window / 2),
      path_(harris_default_path()) {}

// One body for both callers, inlined into each (process_unchecked() stays one call).
[[gnu::always_inline]] inline double Harris::score_window(const Event& e) const noexcept {
    const SensorSize s = sae_.size();
    // The reference's border rule: '>' on the far side, so the window of an event at
    // x = width - r reaches one column past the sensor (read as never fired).
    if (e.x < radius_ || e.x > s.width - radius_ || e.y < radius_ || e.y > s.height - radius_)
        return kNoScore;

    // The nl newest fired pixels of the window (harris_select.hpp), then the score.
    const std::uint64_t* const first = sae_.plane(e.p != 0) + sae_.index(e.x - radius_, e.y - radius_);
    std::uint16_t rows[HarrisScorer::kMaxWindow];
    if (!harris_select_newest(path_, first, sae_.stride(), params_.window, sae_.last(), params_.nl, rows))
        return kNoScore;  // fewer than nl pixels ever fired in the window
    // The AVX2 score with the vector selections (every CPU that runs them runs AVX2).
    return path_ != HarrisPath::portable && params_.window == 9 ? scorer_.score9_avx2(rows) : scorer_.score(rows);
}

bool Harris::process_unchecked(const Event& e) noexcept {
    sae_.update_unchecked(e);
    score_ = score_window(e);
    return score_ > params_.threshold;  // false for kNoScore (NaN)
}

double Harris::score_latest(const Event& e) const noexcept { return score_window(e); }

}  // namespace evcorner
