#include "evcorner/efast_harris.hpp"

#include <algorithm>

namespace evcorner {

EFastHarris::EFastHarris(SensorSize size, const Params& params, int planes)
    : efast_(checked_sensor_size(size, "eFAST -> Harris"), planes), harris_(size, params, planes) {}

// Block by block: eFAST's batch loop (its fastest code path) writes its flags for the
// block, then Harris takes every event of the block in order and scores the events eFAST
// flagged, clearing the flags Harris rejects. Exact: neither stage's decision for an event
// depends on anything but the events up to it. The block keeps the events in cache
// between the two passes.
template <bool WithScores>
std::size_t run_efast_harris(EFastHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept {
    constexpr std::size_t kBlock = 2048;
    const double threshold = det.harris_.params().threshold;
    std::size_t corners = 0;
    double last = det.score_;
    for (std::size_t begin = 0; begin < events.size(); begin += kBlock) {
        const std::size_t n = std::min(kBlock, events.size() - begin);
        const std::span<const Event> block = events.subspan(begin, n);
        std::uint8_t* const flags = is_corner.data() + begin;
        detect_unchecked(det.efast_, block, std::span<std::uint8_t>(flags, n));
        for (std::size_t i = 0; i < n; ++i) {
            const Event& e = block[i];
            det.harris_.update_unchecked(e);
            last = kNoScore;
            if (flags[i]) {
                last = det.harris_.score_latest(e);
                const bool c = last > threshold;
                flags[i] = static_cast<std::uint8_t>(c);
                corners += c;
            }
            if constexpr (WithScores) score[begin + i] = last;
        }
    }
    det.score_ = last;
    return corners;
}

std::size_t detect_unchecked(EFastHarris& det, std::span<const Event> events,
                             std::span<std::uint8_t> is_corner) noexcept {
    return run_efast_harris<false>(det, events, is_corner, {});
}

std::size_t detect(EFastHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) {
    detail::check_flags(events.size(), is_corner.size(), "detect");
    check_events(events, det.limits());
    return run_efast_harris<false>(det, events, is_corner, {});
}

std::size_t detect_unchecked(EFastHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept {
    return run_efast_harris<true>(det, events, is_corner, score);
}

std::size_t detect(EFastHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                   std::span<double> score) {
    detail::check_flags(events.size(), is_corner.size(), "detect");
    detail::check_flags(events.size(), score.size(), "detect (scores)");
    check_events(events, det.limits());
    return run_efast_harris<true>(det, events, is_corner, score);
}

}  // namespace evcorner
