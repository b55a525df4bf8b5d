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
// arc_fires_naive() is the definition written plainly; tests hold the two together.

#include <array>
#include <cstdint>

namespace evcorner {

namespace detail {
// #values in t[0..N) that are >= v. Kept scalar on purpose: without SSE4.2 the
// auto-vectorised 64-bit compare costs several times more instructions.
template <int N>
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-vectorize")))
#endif
inline int count_at_least(const std::int64_t* t, std::int64_t v) noexcept {
    int n = 0;
    for (int k = 0; k < N; ++k) n += t[k] >= v;
    return n;
}
}  // namespace detail

/// `t` holds the circle twice: t[k] == t[k + N] for 0 <= k < N, so that no index
/// along an arc needs a modulo.
template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_fires(const std::int64_t* t) noexcept {
    static_assert(2 <= Lmin && Lmin <= Lmax && 2 * Lmax - 2 < N);
    int newest = 0;
    std::int64_t top = t[0];
    for (int k = 1; k < N; ++k) {
        const bool newer = t[k] > top;
        newest = newer ? k : newest;
        top = newer ? t[k] : top;
    }
    // Centre the work on a copy of the newest pixel whose +-(Lmax-1) neighbourhood
    // and opposite side all lie inside [0, 2N).
    const int c = newest < Lmax ? newest + N : newest;

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
    for (int k = c + Lmax; k <= c + N - Lmax; ++k)
        if (t[k] >= bound) return false;

    // Grow the arc [lo, hi] from c, taking the newer neighbour each time.
    int lo = c;
    int hi = c;
    std::int64_t oldest = top;
    int at_least_oldest = -1;  // #pixels with t >= oldest; -1 = stale
    for (int len = 2; len <= Lmax; ++len) {
        const std::int64_t left = t[lo - 1];
        const std::int64_t right = t[hi + 1];
        const bool go_left = left > right;
        const std::int64_t taken = go_left ? left : right;
        lo -= go_left;
        hi += !go_left;
        if (taken < oldest) {
            oldest = taken;
            at_least_oldest = -1;
        }
        if (len < Lmin) continue;
        if (at_least_oldest < 0) {
            at_least_oldest = detail::count_at_least<N>(t, oldest);
            // The count only grows as the arc grows; past Lmax nothing can fire.
            if (at_least_oldest > Lmax) return false;
        }
        if (at_least_oldest == len) return true;
    }
    return false;
}

/// The same test on N values, doubling them first.
template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_fires(const std::array<std::int64_t, N>& t) noexcept {
    std::array<std::int64_t, 2 * N> twice;
    for (int k = 0; k < N; ++k) twice[k] = twice[k + N] = t[k];
    return arc_fires<N, Lmin, Lmax>(twice.data());
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
