#include "evcorner/event_check.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/cpu_paths.hpp"

namespace evcorner {

namespace {

std::string describe(const Event& e, const EventLimits& l, std::size_t index) {
    std::string s = "event";
    if (index != InvalidEvent::kNoIndex) {
        s += ' ';
        s += std::to_string(index);
    }
    s.append(" (t=").append(std::to_string(e.t)).append(" x=").append(std::to_string(e.x));
    s.append(" y=").append(std::to_string(e.y)).append(" p=").append(std::to_string(e.p)).append(")");
    const std::string sensor = std::to_string(l.size.width) + "x" + std::to_string(l.size.height) + " sensor";
    if (e.x >= l.size.width || e.y >= l.size.height) {
        s += " is off the " + sensor + " (x must be < " + std::to_string(l.size.width) + ", y < " +
             std::to_string(l.size.height) + ")";
    } else if (e.p > 1) {
        s += " has polarity " + std::to_string(e.p) + " (0 or 1 expected) on the " + sensor;
    } else {
        s += " has a time outside " + std::to_string(l.t_min) + ".." + std::to_string(l.t_max) +
             " us, which the detector cannot hold (" + sensor + ")";
    }
    return s;
}

}  // namespace

namespace {

// Whether all of ev[0, n) are accepted: maxima and minima over the block (branch-free
// reductions that the compiler vectorises; the 64-bit time ones only where the target
// has 64-bit vector compares, AVX2, and only when the limits restrict the time).
// `span`, when given, is widened by the block's times.
inline bool all_accepted(const Event* ev, std::size_t n, const EventLimits& l, TimeSpan* span) noexcept {
    std::uint16_t max_x = 0, max_y = 0;
    std::uint8_t max_p = 0;
    if (span == nullptr && l.t_min == std::numeric_limits<std::int64_t>::min() &&
        l.t_max == std::numeric_limits<std::int64_t>::max()) {
        for (std::size_t i = 0; i < n; ++i) {
            max_x = ev[i].x > max_x ? ev[i].x : max_x;
            max_y = ev[i].y > max_y ? ev[i].y : max_y;
            max_p = ev[i].p > max_p ? ev[i].p : max_p;
        }
        return n == 0 || l.accepts(Event{0, max_x, max_y, max_p});
    }
    std::int64_t min_t = std::numeric_limits<std::int64_t>::max(), max_t = std::numeric_limits<std::int64_t>::min();
    for (std::size_t i = 0; i < n; ++i) {
        max_x = ev[i].x > max_x ? ev[i].x : max_x;
        max_y = ev[i].y > max_y ? ev[i].y : max_y;
        max_p = ev[i].p > max_p ? ev[i].p : max_p;
        min_t = ev[i].t < min_t ? ev[i].t : min_t;
        max_t = ev[i].t > max_t ? ev[i].t : max_t;
    }
    if (span != nullptr) *span = span->with({min_t, max_t});
    return n == 0 || (l.accepts(Event{min_t, max_x, max_y, max_p}) && l.accepts(Event{max_t, max_x, max_y, max_p}));
}

// Blocks of events, each tested by Accepted (all_accepted() or all_accepted_avx512());
// in the first block that fails, the first failing event.
template <bool (*Accepted)(const Event*, std::size_t, const EventLimits&, TimeSpan*) noexcept>
std::size_t first_invalid(std::span<const Event> events, const EventLimits& limits, TimeSpan* span) noexcept {
    constexpr std::size_t kBlock = 1024;
    const std::size_t n = events.size();
    for (std::size_t at = 0; at < n; at += kBlock) {
        const std::size_t m = n - at < kBlock ? n - at : kBlock;
        if (!Accepted(events.data() + at, m, limits, span)) [[unlikely]]
            for (std::size_t i = at; i < at + m; ++i)
                if (!limits.accepts(events[i])) return i;
    }
    return n;
}

using Finder = std::size_t (*)(std::span<const Event>, const EventLimits&, TimeSpan*) noexcept;

#ifdef EVCORNER_HAVE_AVX2_SEARCH
// The AVX-512 pass: four events per 512-bit load (an event is 16 bytes: t in the even
// 64-bit lanes, x, y, p and three padding bytes in the odd ones), folded into running
// extremes by four instructions: the least and the greatest t (masked to the even lanes),
// the greatest 16-bit words (x and y) and the OR of the bytes (p <= 1 iff no bit of p
// above the lowest is set). The padding bytes take part in none of the decisions. What
// GCC's vectoriser makes of all_accepted() takes about 8.5 instructions per event; this
// takes about 1.3, which matters because the check runs before every checked detect().
EVCORNER_AVX512_WARNINGS_OFF
[[gnu::target(EVCORNER_AVX512_TARGET)]] bool all_accepted_avx512(const Event* ev, std::size_t n,
                                                                 const EventLimits& l, TimeSpan* span) noexcept {
    static_assert(sizeof(Event) == 16 && offsetof(Event, t) == 0 && offsetof(Event, x) == 8 &&
                  offsetof(Event, y) == 10 && offsetof(Event, p) == 12);
    constexpr __mmask8 kTimes = 0x55;  // the even 64-bit lanes: t of each event
    __m512i tmin = _mm512_set1_epi64(std::numeric_limits<std::int64_t>::max());
    __m512i tmax = _mm512_set1_epi64(std::numeric_limits<std::int64_t>::min());
    __m512i words = _mm512_setzero_si512(), bits = _mm512_setzero_si512();
    const char* const base = reinterpret_cast<const char*>(ev);
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const __m512i v = _mm512_loadu_si512(base + i * sizeof(Event));
        tmin = _mm512_mask_min_epi64(tmin, kTimes, tmin, v);
        tmax = _mm512_mask_max_epi64(tmax, kTimes, tmax, v);
        words = _mm512_max_epu16(words, v);
        bits = _mm512_or_si512(bits, v);
    }
    if (i < n) {  // the last 1-3 events: a masked load, the missing lanes as zeros
        const __mmask8 lanes = static_cast<__mmask8>((1u << (2 * (n - i))) - 1);
        const __m512i v = _mm512_maskz_loadu_epi64(lanes, base + i * sizeof(Event));
        tmin = _mm512_mask_min_epi64(tmin, lanes & kTimes, tmin, v);
        tmax = _mm512_mask_max_epi64(tmax, lanes & kTimes, tmax, v);
        words = _mm512_max_epu16(words, v);
        bits = _mm512_or_si512(bits, v);
    }
    if (n == 0) return true;
    // Fold the four odd lanes into one: the largest x and y, the OR of p.
    alignas(64) std::uint16_t w[32];
    alignas(64) std::uint8_t b[64];
    _mm512_store_si512(w, words);
    _mm512_store_si512(b, bits);
    std::uint16_t max_x = 0, max_y = 0;
    std::uint8_t or_p = 0;
    for (int e = 0; e < 4; ++e) {
        max_x = std::max(max_x, w[8 * e + 4]);
        max_y = std::max(max_y, w[8 * e + 5]);
        or_p = static_cast<std::uint8_t>(or_p | b[16 * e + 12]);
    }
    const std::int64_t min_t = _mm512_mask_reduce_min_epi64(kTimes, tmin);
    const std::int64_t max_t = _mm512_mask_reduce_max_epi64(kTimes, tmax);
    if (span != nullptr) *span = span->with({min_t, max_t});
    // or_p <= 1 iff every p <= 1.
    return l.accepts(Event{min_t, max_x, max_y, or_p}) && l.accepts(Event{max_t, max_x, max_y, or_p});
}
EVCORNER_AVX512_WARNINGS_ON

// flatten: the whole pass compiled for AVX2 here and nowhere else.
[[gnu::target("avx2"), gnu::flatten]] std::size_t first_invalid_avx2(std::span<const Event> events,
                                                                      const EventLimits& limits,
                                                                      TimeSpan* span) noexcept {
    return first_invalid<all_accepted>(events, limits, span);
}
[[gnu::target(EVCORNER_AVX512_TARGET)]] std::size_t first_invalid_avx512(std::span<const Event> events,
                                                                         const EventLimits& limits,
                                                                         TimeSpan* span) noexcept {
    return first_invalid<all_accepted_avx512>(events, limits, span);
}
#endif

// The passes this CPU runs, fastest first.
std::vector<CodePath<Finder>> finder_paths() {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    return runnable_paths<Finder>(first_invalid_avx512, first_invalid_avx2, first_invalid<all_accepted>);
#else
    return runnable_paths<Finder>(nullptr, nullptr, first_invalid<all_accepted>);
#endif
}

const std::vector<CodePath<Finder>>& finders() {
    static const std::vector<CodePath<Finder>> p = finder_paths();
    return p;
}

const Finder& finder() noexcept {
    static const Finder f = finders().front().fn;
    return f;
}

}  // namespace

std::size_t first_invalid_event(std::span<const Event> events, const EventLimits& limits) noexcept {
    return finder()(events, limits, nullptr);
}

std::size_t first_invalid_event(std::span<const Event> events, const EventLimits& limits, TimeSpan& span) noexcept {
    span = TimeSpan{};
    return finder()(events, limits, &span);
}

std::vector<std::string> event_check_paths() {
    std::vector<std::string> names;
    for (const CodePath<Finder>& p : finders()) names.emplace_back(p.name);
    return names;
}

std::size_t first_invalid_event_on_path(std::string_view path, std::span<const Event> events,
                                        const EventLimits& limits, TimeSpan& span) {
    span = TimeSpan{};
    for (const CodePath<Finder>& p : finders())
        if (path == p.name) return p.fn(events, limits, &span);
    throw std::invalid_argument("event check path '" + std::string(path) + "' does not run on this CPU");
}

InvalidEvent::InvalidEvent(const Event& e, const EventLimits& limits, std::size_t index)
    : std::invalid_argument(describe(e, limits, index)), event_(e), index_(index), sensor_(limits.size) {}

}  // namespace evcorner
