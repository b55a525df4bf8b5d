// The batch loop of eFAST, compiled three times: portable, for AVX2 and for AVX-512
// (chosen once at run time from the CPU's features). All produce identical flags; tests
// hold each one this CPU runs to the oracle and the goldens.

#include "evcorner/efast.hpp"

#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "evcorner/cpu_paths.hpp"

namespace evcorner {

namespace {

std::size_t detect_portable(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                            const TimeSpan& span) noexcept {
    return det.run_unchecked<ScalarSearch>(events, is_corner, span);
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
// flatten: every call inside is inlined, so the whole per-event path is compiled for
// AVX2 here and nowhere else (no AVX2 copy of a shared inline function can leak).
[[gnu::target("avx2"), gnu::flatten]] std::size_t detect_avx2(EFast& det, std::span<const Event> events,
                                                               std::span<std::uint8_t> is_corner,
                                                               const TimeSpan& span) noexcept {
    return det.run_unchecked<Avx2Search>(events, is_corner, span);
}
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::flatten]] std::size_t detect_avx512(
    EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner, const TimeSpan& span) noexcept {
    return det.run_unchecked<Avx512Search>(events, is_corner, span);
}
#endif

// `span`: the batch's time span, or TimeSpan::unknown() (EFast::run_unchecked()).
using Loop = std::size_t (*)(EFast&, std::span<const Event>, std::span<std::uint8_t>, const TimeSpan&) noexcept;

// The scored loops (detect with scores), one per path, beside the binary ones.
using ScoredLoop = std::size_t (*)(EFast&, std::span<const Event>, std::span<std::uint8_t>, std::span<double>,
                                  const TimeSpan&) noexcept;
std::size_t scored_portable(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                            std::span<double> score, const TimeSpan& span) noexcept {
    return det.run_scored_unchecked<ScalarSearch>(events, is_corner, score, span);
}
#ifdef EVCORNER_HAVE_AVX2_SEARCH
[[gnu::target("avx2"), gnu::flatten]] std::size_t scored_avx2(EFast& det, std::span<const Event> events,
                                                               std::span<std::uint8_t> is_corner,
                                                               std::span<double> score, const TimeSpan& span) noexcept {
    return det.run_scored_unchecked<Avx2Search>(events, is_corner, score, span);
}
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::flatten]] std::size_t scored_avx512(
    EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner, std::span<double> score,
    const TimeSpan& span) noexcept {
    return det.run_scored_unchecked<Avx512Search>(events, is_corner, score, span);
}
#endif
ScoredLoop scored_loop_of(Loop loop) noexcept {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    if (loop == detect_avx512) return scored_avx512;
    if (loop == detect_avx2) return scored_avx2;
#endif
    (void)loop;
    return scored_portable;
}

using Path = CodePath<Loop>;

// The paths this CPU runs, fastest first.
std::vector<Path> available() {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    return runnable_paths<Loop>(detect_avx512, detect_avx2, detect_portable);
#else
    return runnable_paths<Loop>(nullptr, nullptr, detect_portable);
#endif
}

const std::vector<Path>& paths() {
    static const std::vector<Path> p = available();
    return p;
}

const Path& choice() noexcept {
    // EVCORNER_EFAST_PATH=portable (or avx2, avx512) forces a path this CPU runs.
    static const Path& c = forced_or_fastest(paths(), "EVCORNER_EFAST_PATH");
    return c;
}

}  // namespace

std::size_t detect(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) {
    detail::check_flags(events.size(), is_corner.size(), "detect");
    // One pass over the batch, before the first event; it also finds the batch's span.
    const TimeSpan span = check_events_span(events, det.limits());
    return choice().fn(det, events, is_corner, span);
}

std::size_t detect_unchecked(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return choice().fn(det, events, is_corner, TimeSpan::unknown());
}

std::size_t detect_unchecked(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             const TimeSpan& span) noexcept {
    return choice().fn(det, events, is_corner, span);
}

std::size_t detect(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                   std::span<double> score) {
    detail::check_flags(events.size(), is_corner.size(), "detect");
    detail::check_flags(events.size(), score.size(), "detect (scores)");
    const TimeSpan span = check_events_span(events, det.limits());
    return scored_loop_of(choice().fn)(det, events, is_corner, score, span);
}

std::size_t detect_unchecked(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept {
    return scored_loop_of(choice().fn)(det, events, is_corner, score, TimeSpan::unknown());
}

const char* efast_code_path() noexcept { return choice().name; }

std::vector<std::string> efast_code_paths() {
    std::vector<std::string> names;
    for (const Path& p : paths()) names.emplace_back(p.name);
    return names;
}

std::size_t detect_on_path(std::string_view path, EFast& det, std::span<const Event> events,
                           std::span<std::uint8_t> is_corner) {
    for (const Path& p : paths())
        if (path == p.name) {
            detail::check_flags(events.size(), is_corner.size(), "detect_on_path");
            const TimeSpan span = check_events_span(events, det.limits());
            return p.fn(det, events, is_corner, span);
        }
    throw std::invalid_argument("eFAST code path '" + std::string(path) + "' does not run on this CPU");
}

}  // namespace evcorner
