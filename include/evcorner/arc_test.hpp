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

template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_fires(const std::int64_t* t) noexcept {
    static_assert(1 <= Lmin && Lmin <= Lmax && Lmax < N);
    int newest = 0;
    for (int k = 1; k < N; ++k)
        if (t[k] > t[newest]) newest = k;

    // Indices lo..hi (inclusive) of the arc, taken modulo N; start in the middle of
    // [0, 3N) so neither end needs a wrap check.
    int lo = newest + N;
    int hi = newest + N;
    auto at = [t](int i) { return t[i >= 2 * N ? i - 2 * N : (i >= N ? i - N : i)]; };
    std::int64_t oldest = t[newest];
    int at_least_oldest = -1;  // #pixels with t >= oldest; -1 = stale
    for (int len = 2; len <= Lmax; ++len) {
        const std::int64_t left = at(lo - 1);
        const std::int64_t right = at(hi + 1);
        std::int64_t taken;
        if (left > right) {
            taken = left;
            --lo;
        } else {
            taken = right;
            ++hi;
        }
        if (taken < oldest) {
            oldest = taken;
            at_least_oldest = -1;
        }
        if (len < Lmin) continue;
        if (at_least_oldest < 0) {
            at_least_oldest = 0;
            for (int k = 0; k < N; ++k) at_least_oldest += t[k] >= oldest;
            // The count only grows as the arc grows; past Lmax nothing can fire.
            if (at_least_oldest > Lmax) return false;
        }
        if (at_least_oldest == len) return true;
    }
    return false;
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
