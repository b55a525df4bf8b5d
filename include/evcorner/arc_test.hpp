#pragma once
// The eFAST arc test on one circle of SAE timestamps.
//
// A circle of N timestamps T[0..N) (cyclic) *fires* when some contiguous arc of length
// L, Lmin <= L <= Lmax, has its oldest timestamp strictly newer than every timestamp on
// the rest of the circle (Mueggler et al., BMVC 2017, Sec. 2.2; docs/algorithms.md).
//
// arc_fires() is the linear-time form: a firing arc holds the circle's newest pixel and
// is exactly the set of the L newest pixels. Grow an arc from the newest pixel, always
// taking the newer of its two neighbours; at each length L in range the arc fires iff
// exactly L pixels of the circle are at least as new as the arc's oldest. Any arc that
// fires is found this way, because while the grown arc is a proper part of the firing
// set, one of its neighbours is in that set and newer than everything outside it.
// Before growing, an exact cheap test rejects most circles (see arc_fires_from()).
// arc_fires_naive() is the definition written plainly; tests hold the two together.

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

namespace evcorner {

namespace detail {
// #values in t[0..N) that are >= v, unrolled.
template <std::size_t... K>
inline int count_at_least(const std::int64_t* t, std::int64_t v, std::index_sequence<K...>) noexcept {
    return (static_cast<int>(t[K] >= v) + ...);
}
template <int N>
inline int count_at_least(const std::int64_t* t, std::int64_t v) noexcept {
    return count_at_least(t, v, std::make_index_sequence<N>{});
}

// Branch-free select: the per-event paths must not mispredict on data.
inline int select(bool c, int a, int b) noexcept {
    const int m = -static_cast<int>(c);
    return (a & m) | (b & ~m);
}
}  // namespace detail

/// The arc test given the circle twice (t[k] == t[k + N], so that no index along an
/// arc needs a modulo) and the index of one of its newest pixels.
template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_fires_from(const std::int64_t* t, int newest) noexcept {
    static_assert(2 <= Lmin && Lmin <= Lmax && 2 * Lmax - 2 < N);
    // Centre the work on a copy of the newest pixel whose +-(Lmax-1) neighbourhood
    // and opposite side all lie inside [0, 2N).
    const int c = newest + N * static_cast<int>(newest < Lmax);

    // Cheap rejection, exact: a firing arc holds the newest pixel and at least Lmin
    // pixels, so its oldest is at most `bound`, the best oldest of the Lmin-windows
    // through c; and it spans at most Lmax pixels, so the pixels Lmax or more steps
    // from c lie outside it and must all be older than its oldest.
    std::int64_t bound = INT64_MIN;
    for (int s = 0; s < Lmin; ++s) {
        std::int64_t w = t[c - s];
        for (int k = 1; k < Lmin; ++k) w = t[c - s + k] < w ? t[c - s + k] : w;
        bound = w > bound ? w : bound;
    }
    std::int64_t opposite = t[c + Lmax];
    for (int k = c + Lmax + 1; k <= c + N - Lmax; ++k) opposite = t[k] > opposite ? t[k] : opposite;
    if (opposite >= bound) return false;

    // Grow the arc [lo, hi] from c, taking the newer neighbour each time; at each
    // length in range it fires iff exactly `len` pixels are at least as new as its
    // oldest. Branch-free: the outcome is data, and data mispredicts.
    int lo = c;
    int hi = c;
    std::int64_t oldest = t[c];
    bool fires = false;
#pragma GCC unroll 8
    for (int len = 2; len <= Lmax; ++len) {
        const std::int64_t left = t[lo - 1];
        const std::int64_t right = t[hi + 1];
        const bool go_left = left > right;
        const std::int64_t taken = go_left ? left : right;
        lo -= go_left;
        hi += !go_left;
        oldest = taken < oldest ? taken : oldest;
        if (len >= Lmin) fires |= detail::count_at_least<N>(t, oldest) == len;
    }
    return fires;
}

/// Gathers the circle around `centre` (pixel k at centre[offset(k)]) and runs the test.
template <int N, int Lmin, int Lmax, class Offset>
[[nodiscard]] inline bool circle_fires(const std::int64_t* centre, Offset offset) noexcept {
    std::int64_t t[2 * N];
    int newest = 0;
    std::int64_t top = centre[offset(0)];
    t[0] = t[N] = top;
#pragma GCC unroll 32
    for (int k = 1; k < N; ++k) {
        const std::int64_t v = centre[offset(k)];
        t[k] = t[k + N] = v;
        const bool newer = v > top;
        newest = detail::select(newer, k, newest);
        top = v > top ? v : top;
    }
    return arc_fires_from<N, Lmin, Lmax>(t, newest);
}

/// The arc test on N values.
template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_fires(const std::array<std::int64_t, N>& t) noexcept {
    return circle_fires<N, Lmin, Lmax>(t.data(), [](int k) { return k; });
}

template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_fires_naive(const std::array<std::int64_t, N>& t) noexcept {
    for (int start = 0; start < N; ++start) {
        for (int len = Lmin; len <= Lmax; ++len) {
            bool inside_newer = true;
            for (int i = 0; i < len && inside_newer; ++i) {
                for (int j = len; j < N && inside_newer; ++j) {
                    if (t[(start + i) % N] <= t[(start + j) % N]) inside_newer = false;
                }
            }
            if (inside_newer) return true;
        }
    }
    return false;
}

}  // namespace evcorner
