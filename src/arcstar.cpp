// Arc*: construction and the batch loop, compiled portable and for AVX2 (the newest-pixel
// search of arc_test.hpp), chosen once at run time from the CPU's features. Both produce
// identical flags; tests hold each to the oracle and the goldens.

#include "evcorner/arcstar.hpp"

#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

namespace evcorner {

namespace {

const ArcStarParams& validated(const ArcStarParams& p) {
    if (p.filter_us < 0 || p.filter_us > ArcStar::kMaxFilterUs)
        throw std::invalid_argument("Arc* filter_us must be within 0.." + std::to_string(ArcStar::kMaxFilterUs) +
                                    " (got " + std::to_string(p.filter_us) + ")");
    return p;
}

std::size_t detect_portable(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return det.run_unchecked<ScalarSearch>(events, is_corner);
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
// flatten: the whole per-event path is compiled for AVX2 here and nowhere else.
[[gnu::target("avx2"), gnu::flatten]] std::size_t detect_avx2(ArcStar& det, std::span<const Event> events,
                                                               std::span<std::uint8_t> is_corner) noexcept {
    return det.run_unchecked<Avx2Search>(events, is_corner);
}
#endif

using Loop = std::size_t (*)(ArcStar&, std::span<const Event>, std::span<std::uint8_t>) noexcept;

Loop choose() noexcept {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    __builtin_cpu_init();
    // EVCORNER_ARCSTAR_PATH=portable forces the portable loop on an AVX2 CPU.
    const char* forced = std::getenv("EVCORNER_ARCSTAR_PATH");
    if (__builtin_cpu_supports("avx2") && !(forced != nullptr && std::strcmp(forced, "portable") == 0))
        return detect_avx2;
#endif
    return detect_portable;
}

Loop loop() noexcept {
    static const Loop l = choose();
    return l;
}

}  // namespace

ArcStar::ArcStar(SensorSize size, const Params& params, int /*planes*/)
    : params_(validated(params)),
      sae_(checked_sensor_size(size, "Arc*"), 2),
      latest_(static_cast<std::size_t>(size.pixels())) {}

std::size_t detect(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) {
    detail::check_flags(events.size(), is_corner.size(), "detect");
    check_events(events, det.limits());
    return loop()(det, events, is_corner);
}

std::size_t detect_unchecked(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return loop()(det, events, is_corner);
}

}  // namespace evcorner
