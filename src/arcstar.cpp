// Arc*: construction and the batch loop, compiled portable, for AVX2 (the newest-pixel
// search of arc_test.hpp) and for AVX-512 (the closed form, ArcStarAvx512), chosen once at
// run time from the CPU's features. All produce identical flags; tests hold each to the
// oracle and the goldens.

#include "evcorner/arcstar.hpp"

#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "evcorner/cpu_paths.hpp"

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
// Both circles by the closed form, all arcs at once (ArcStarAvx512 in arcstar_test.hpp).
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::flatten]] std::size_t detect_avx512(
    ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return det.run_unchecked<Avx512Search>(events, is_corner);
}
#endif

using Loop = std::size_t (*)(ArcStar&, std::span<const Event>, std::span<std::uint8_t>) noexcept;
using Path = CodePath<Loop>;

// The paths this CPU runs, fastest first.
std::vector<Path> available() {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    return runnable_paths<Loop>(detect_avx512, detect_avx2, detect_portable);
#else
    return runnable_paths<Loop>(nullptr, nullptr, detect_portable);
#endif
}

// The fastest path, or the one EVCORNER_ARCSTAR_PATH names if this CPU runs it; chosen
// once per process.
const Path& path() noexcept {
    static const std::vector<Path> paths = available();
    static const Path& p = forced_or_fastest(paths, "EVCORNER_ARCSTAR_PATH");
    return p;
}

Loop loop() noexcept { return path().fn; }

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

namespace {
std::size_t scored_portable(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                            std::span<double> score) noexcept {
    return det.run_scored_unchecked<ScalarSearch>(events, is_corner, score);
}
#ifdef EVCORNER_HAVE_AVX2_SEARCH
[[gnu::target("avx2"), gnu::flatten]] std::size_t scored_avx2(ArcStar& det, std::span<const Event> events,
                                                               std::span<std::uint8_t> is_corner,
                                                               std::span<double> score) noexcept {
    return det.run_scored_unchecked<Avx2Search>(events, is_corner, score);
}
#endif
// The scored loop beside the chosen binary path: AVX2 where the CPU runs it.
std::size_t scored_loop(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                        std::span<double> score) noexcept {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    if (std::strcmp(path().name, "portable") != 0) return scored_avx2(det, events, is_corner, score);
#endif
    return scored_portable(det, events, is_corner, score);
}
}  // namespace

std::size_t detect(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                   std::span<double> score) {
    detail::check_flags(events.size(), is_corner.size(), "detect");
    detail::check_flags(events.size(), score.size(), "detect (scores)");
    check_events(events, det.limits());
    return scored_loop(det, events, is_corner, score);
}

std::size_t detect_unchecked(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept {
    return scored_loop(det, events, is_corner, score);
}

const char* arcstar_code_path() noexcept { return path().name; }

std::size_t detect_unchecked(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return loop()(det, events, is_corner);
}

}  // namespace evcorner
