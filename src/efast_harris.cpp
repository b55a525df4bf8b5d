#include "evcorner/efast_harris.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

namespace evcorner {

EFastHarris::EFastHarris(SensorSize size, const Params& params, int planes)
    : efast_(checked_sensor_size(size, "eFAST -> Harris"), planes), harris_(size, params, planes) {}

namespace {

// The index of the first nonzero flag in [i, n), else n; eight flags per step.
std::size_t next_flag(const std::uint8_t* flags, std::size_t i, std::size_t n) noexcept {
    for (; i + 8 <= n; i += 8) {
        std::uint64_t word;
        std::memcpy(&word, flags + i, sizeof word);
        if (word != 0) return i + static_cast<std::size_t>(std::countr_zero(word)) / 8;  // little-endian x86/ARM
    }
    for (; i < n; ++i)
        if (flags[i] != 0) return i;
    return n;
}

}  // namespace

// Block by block: eFAST's batch loop (its fastest code path) writes its flags for the
// block; then, from one flagged event to the next, Harris's state takes the events up to
// and including the flagged one in one tight loop (a store each, the state in
// registers) and scores it, clearing the flag when Harris rejects it. Exact: neither
// stage's decision for an event depends on anything but the events up to it, and each
// candidate is scored with Harris's state exactly as after that event. The block keeps
// the events in cache between the two passes.
template <bool WithScores>
std::size_t run_efast_harris(EFastHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept {
    static_assert(std::endian::native == std::endian::little);
    constexpr std::size_t kBlock = 2048;
    const double threshold = det.harris_.params().threshold;
    std::size_t corners = 0;
    double last = det.score_;
    for (std::size_t begin = 0; begin < events.size(); begin += kBlock) {
        const std::size_t n = std::min(kBlock, events.size() - begin);
        const std::span<const Event> block = events.subspan(begin, n);
        std::uint8_t* const flags = is_corner.data() + begin;
        detect_unchecked(det.efast_, block, std::span<std::uint8_t>(flags, n));
        if constexpr (WithScores) std::fill_n(score.data() + begin, n, kNoScore);
        std::size_t done = 0;  // events [0, done) of the block are in Harris's state
        for (std::size_t i = next_flag(flags, 0, n); i < n; i = next_flag(flags, i + 1, n)) {
            det.harris_.update_unchecked(block.subspan(done, i + 1 - done));
            done = i + 1;
            const double s = det.harris_.score_latest(block[i]);
            const bool c = s > threshold;  // false for kNoScore (NaN)
            flags[i] = static_cast<std::uint8_t>(c);
            corners += c;
            if constexpr (WithScores) score[begin + i] = s;
            last = s;
        }
        det.harris_.update_unchecked(block.subspan(done));
        if (done != n) last = kNoScore;  // the block's last event was not a candidate
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
