#include "evcorner/event_check.hpp"

#include <cstdint>
#include <limits>
#include <string>

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
inline bool all_accepted(const Event* ev, std::size_t n, const EventLimits& l) noexcept {
    std::uint16_t max_x = 0, max_y = 0;
    std::uint8_t max_p = 0;
    if (l.t_min == std::numeric_limits<std::int64_t>::min() && l.t_max == std::numeric_limits<std::int64_t>::max()) {
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
    return n == 0 || (l.accepts(Event{min_t, max_x, max_y, max_p}) && l.accepts(Event{max_t, max_x, max_y, max_p}));
}

template <bool>
std::size_t first_invalid(std::span<const Event> events, const EventLimits& limits) noexcept {
    constexpr std::size_t kBlock = 1024;
    const std::size_t n = events.size();
    for (std::size_t at = 0; at < n; at += kBlock) {
        const std::size_t m = n - at < kBlock ? n - at : kBlock;
        if (!all_accepted(events.data() + at, m, limits)) [[unlikely]]
            for (std::size_t i = at; i < at + m; ++i)
                if (!limits.accepts(events[i])) return i;
    }
    return n;
}

using Finder = std::size_t (*)(std::span<const Event>, const EventLimits&) noexcept;

#ifdef EVCORNER_HAVE_AVX2_SEARCH
// flatten: the whole pass compiled for AVX2 here and nowhere else.
[[gnu::target("avx2"), gnu::flatten]] std::size_t first_invalid_avx2(std::span<const Event> events,
                                                                      const EventLimits& limits) noexcept {
    return first_invalid<true>(events, limits);
}
Finder choose() noexcept {
    return cpu_runs_avx2() ? first_invalid_avx2 : first_invalid<false>;
}
#else
Finder choose() noexcept { return first_invalid<false>; }
#endif

}  // namespace

std::size_t first_invalid_event(std::span<const Event> events, const EventLimits& limits) noexcept {
    static const Finder finder = choose();
    return finder(events, limits);
}

InvalidEvent::InvalidEvent(const Event& e, const EventLimits& limits, std::size_t index)
    : std::invalid_argument(describe(e, limits, index)), event_(e), index_(index), sensor_(limits.size) {}

}  // namespace evcorner
