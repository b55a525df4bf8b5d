#include "evcorner/fa_harris.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "evcorner/circle.hpp"
#include "evcorner/cpu_paths.hpp"
#include "evcorner/harris_select.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace evcorner {

namespace {


const FaHarrisParams& validated(const FaHarrisParams& p) {
    if (p.filter_us < 0 || p.filter_us > ArcStar::kMaxFilterUs)
        throw std::invalid_argument("FA-Harris filter_us must be within 0.." + std::to_string(ArcStar::kMaxFilterUs) +
                                    " (got " + std::to_string(p.filter_us) + ")");
    // The window and k are checked by HarrisScorer; nl depends on the window.
    if (p.window >= HarrisScorer::kMinWindow && p.window <= HarrisScorer::kMaxWindow && p.window % 2 == 1 &&
        (p.nl < 1 || p.nl > p.window * p.window))
        throw std::invalid_argument("FA-Harris nl must be within 1.." + std::to_string(p.window * p.window) +
                                    " (window^2) (got " + std::to_string(p.nl) + ")");
    if (!std::isfinite(p.threshold)) throw std::invalid_argument("FA-Harris threshold must be a finite number");
    return p;
}

int frame(int window) { return std::max(kCircleMargin, window / 2); }

}  // namespace

FaHarris::FaHarris(SensorSize size, const Params& params, int /*planes*/)
    : params_(validated(params)),
      scorer_(params_.window, params_.k),
      size_(checked_sensor_size(size, "FA-Harris")),
      pad_(frame(params_.window)),
      stride_(static_cast<std::size_t>(size_.width) + 2 * static_cast<std::size_t>(pad_)),
      plane_size_(stride_ * (static_cast<std::size_t>(size_.height) + 2 * static_cast<std::size_t>(pad_))),
      latest_(static_cast<std::size_t>(size_.pixels())),
      sae_(2 * plane_size_),
      arrival_(2 * plane_size_),
      path_(harris_default_path()) {}

std::uint64_t FaHarris::state_bytes(SensorSize size, const Params& params, int) noexcept {
    const auto pad = static_cast<std::uint64_t>(frame(params.window));
    const std::uint64_t framed = (static_cast<std::uint64_t>(size.width) + 2 * pad) *
                                 (static_cast<std::uint64_t>(size.height) + 2 * pad);
    return static_cast<std::uint64_t>(size.pixels()) * sizeof(ArcStarLatest) + 2 * framed * 2 * sizeof(std::int64_t);
}

namespace {

// Boundary cells up to this many are ranked by all pairs, more by std::nth_element.
constexpr int kPairwiseMax = 16;

// The 9x9 score in AVX2 (bit-identical to the portable one) with adaptive Harris's vector
// selection paths, as Harris takes it (`path`: harris_default_path(), which honours
// EVCORNER_HARRIS_PATH).
double patch_score(const HarrisScorer& scorer, HarrisPath path, int w, const std::uint16_t* rows) noexcept {
    return path != HarrisPath::portable && w == 9 ? scorer.score9_avx2(rows) : scorer.score(rows);
}

// For streams whose filtered writes went back in time (refine() takes harris_select.hpp's
// selection on arrival numbers while they come in time order):
// the nl newest filtered pixels of the window, without sorting. Every cell gets a byte
// code monotone in its age newest - t: the exponent and the three top mantissa bits of
// the age as a double (eighths of octaves up to 35 minutes, then one code for all older
// cells and the never-fired ones, stored 0, which are older than every fired one;
// rounding keeps the order, and ties within a code are resolved exactly below). The
// boundary code, the first where the count of cells at least as new reaches nl, is found
// by a binary search over the 256 codes, each step one branch-free count over the window
// (vectorised). Every cell of a newer code is lit; of the m cells (a few) of the boundary
// code the `take` newest are lit, ranked exactly by (age, later arrival first) with
// branch-free comparisons of all pairs (a sort's branches mispredicted on every
// candidate); only for many cells of one code (equal times), a partition.
// W: the window side, 0 = the `window` given.
template <int W>
double newest_patch_score(const std::int64_t* times, const std::uint64_t* seqs, std::size_t stride,
                          std::int64_t newest, int window, int nl, const HarrisScorer& scorer,
                          HarrisPath path) noexcept {
    const int w = W != 0 ? W : window;
    constexpr int kSide = W != 0 ? W : HarrisScorer::kMaxWindow;
    constexpr int kCells = (kSide * kSide + 15) / 16 * 16;
    const int n = w * w;
    std::uint64_t age[kCells];
    alignas(16) std::uint8_t code[kCells];
    int fired = 0;
    for (int row = 0, i = 0; row < w; ++row)
        for (int c = 0; c < w; ++c, ++i) {
            const std::int64_t t = times[static_cast<std::size_t>(row) * stride + static_cast<std::size_t>(c)];
            const std::uint64_t a = static_cast<std::uint64_t>(newest) - static_cast<std::uint64_t>(t);
            age[i] = a;
            // Fired cells have ages below 2^63 and never-fired ones `newest` < 2^63, so the
            // signed conversion keeps the order. The double's exponent and three top mantissa
            // bits, (bits >> 49) - 8183, are 1..248 for ages 1..2^31 - 1 us; older ages share
            // 255 with the never-fired cells, age 0 is 0.
            const auto bits = std::bit_cast<std::uint64_t>(static_cast<double>(static_cast<std::int64_t>(a)));
            code[i] = static_cast<std::uint8_t>(std::clamp(static_cast<int>(bits >> 49) - 8183, 0, 255));
            fired += t != 0;
        }
    if (fired < nl) return kNoScore;
    for (int i = n; i < kCells; ++i) code[i] = 255;  // padding: counted as oldest, never lit, never a boundary cell

    const auto at_most = [&](int b) noexcept {  // cells with code <= b (padding included at 255)
        int count = 0;
        for (int i = 0; i < kCells; ++i) count += code[i] <= b;
        return count;
    };
    // The smallest boundary in 0..255 with at_most(boundary) >= nl (at_most(255) >= n >= nl).
    int boundary = 0;
    for (int half = 128; half > 0; half >>= 1) boundary += at_most(boundary + half - 1) < nl ? half : 0;

    // Row masks of the newer codes and the list of the boundary code's cells.
    std::uint16_t rows[HarrisScorer::kMaxWindow];
    std::uint8_t where[kCells];
    int m = 0, newer = 0;
#if defined(__SSE2__)
    // One bit per cell, 16 cells per compare (codes biased to signed bytes).
    std::uint64_t lit_bits[(kCells + 63) / 64] = {}, at_bits[(kCells + 63) / 64] = {};
    const __m128i bias = _mm_set1_epi8(static_cast<char>(0x80));
    const __m128i limit = _mm_set1_epi8(static_cast<char>(boundary ^ 0x80));
    for (int i = 0; i < kCells; i += 16) {
        const __m128i v = _mm_xor_si128(_mm_load_si128(reinterpret_cast<const __m128i*>(code + i)), bias);
        const auto lt = static_cast<std::uint64_t>(_mm_movemask_epi8(_mm_cmplt_epi8(v, limit)));
        const auto eq = static_cast<std::uint64_t>(_mm_movemask_epi8(_mm_cmpeq_epi8(v, limit)));
        lit_bits[i >> 6] |= lt << (i & 63);
        at_bits[i >> 6] |= eq << (i & 63);
    }
    const auto field = [](const std::uint64_t* b, int at, int len) noexcept {  // bits at..at+len-1
        const std::uint64_t lo = b[at >> 6] >> (at & 63);
        const std::uint64_t hi = (at & 63) + len > 64 ? b[(at >> 6) + 1] << (64 - (at & 63)) : 0;
        return static_cast<unsigned>((lo | hi) & ((std::uint64_t{1} << len) - 1));
    };
    for (int row = 0; row < w; ++row) {
        rows[row] = static_cast<std::uint16_t>(field(lit_bits, row * w, w));
        newer += std::popcount(rows[row]);
    }
    for (int k = 0; k < (kCells + 63) / 64; ++k) {
        const int inside = std::clamp(n - 64 * k, 0, 64);  // the padding (code 255) is no cell
        if (inside < 64) at_bits[k] &= (std::uint64_t{1} << inside) - 1;
    }
    for (int k = 0; k < (kCells + 63) / 64; ++k)
        for (std::uint64_t b = at_bits[k]; b != 0; b &= b - 1)
            where[m++] = static_cast<std::uint8_t>(64 * k + std::countr_zero(b));
#else
    for (int row = 0, i = 0; row < w; ++row) {
        unsigned lit = 0;
        for (int c = 0; c < w; ++c, ++i) {
            lit |= static_cast<unsigned>(code[i] < boundary) << c;
            where[m] = static_cast<std::uint8_t>(i);
            m += code[i] == boundary;
        }
        rows[row] = static_cast<std::uint16_t>(lit);
        newer += std::popcount(lit);
    }
#endif
    const int take = nl - newer;  // 1..m
    if (take == m) {
        for (int j = 0; j < m; ++j) rows[where[j] / w] |= static_cast<std::uint16_t>(1u << (where[j] % w));
        return patch_score(scorer, path, w, rows);
    }
    // Newer = a smaller age, or the same age and a later arrival (arrival numbers are unique
    // among fired cells; never-fired cells, all age `newest`, arrival 0, are the oldest, and
    // fired >= nl keeps them unlit). A cell is lit iff fewer than `take` cells are newer.
    std::uint64_t key_age[kCells], key_seq[kCells];
    for (int j = 0; j < m; ++j) {
        const int i = where[j];
        key_age[j] = age[i];
        key_seq[j] = seqs[static_cast<std::size_t>(i / w) * stride + static_cast<std::size_t>(i % w)];
    }
    if (m <= kPairwiseMax) {
        for (int j = 0; j < m; ++j) {
            int ahead = 0;
            for (int k = 0; k < m; ++k)
                ahead += (key_age[k] < key_age[j]) | ((key_age[k] == key_age[j]) & (key_seq[k] > key_seq[j]));
            const int i = where[j];
            rows[i / w] |= static_cast<std::uint16_t>(static_cast<unsigned>(ahead < take) << (i % w));
        }
    } else {
        // Many cells of one code (equal times: a busy recording's microseconds): all pairs
        // would cost m^2, so select the `take` newest by partition instead.
        std::uint8_t order[kCells];
        for (int j = 0; j < m; ++j) order[j] = static_cast<std::uint8_t>(j);
        std::nth_element(order, order + (take - 1), order + m, [&](std::uint8_t a, std::uint8_t b) {
            return key_age[a] != key_age[b] ? key_age[a] < key_age[b] : key_seq[a] > key_seq[b];
        });
        for (int j = 0; j < take; ++j) {
            const int i = where[order[j]];
            rows[i / w] |= static_cast<std::uint16_t>(1u << (i % w));
        }
    }
    return patch_score(scorer, path, w, rows);
}

}  // namespace

double FaHarris::refine(int p, int x, int y, std::uint64_t now, std::int64_t newest,
                        bool in_time_order) const noexcept {
    const int r = params_.window / 2;
    const std::size_t first = plane(p) + index(x - r, y - r);
    const std::uint64_t* const seqs = arrival_.data() + first;
    if (in_time_order) {
        // Every filtered write came in time order, so a later arrival number is a later
        // time or the same time and a later arrival: the nl newest are the nl largest
        // arrival numbers (0 = never passed), as adaptive Harris selects them.
        std::uint16_t rows[HarrisScorer::kMaxWindow];
        if (!harris_select_newest(path_, seqs, stride_, params_.window, now, params_.nl, rows))
            return kNoScore;  // fewer than nl filtered pixels in the window
        return patch_score(scorer_, path_, params_.window, rows);
    }
    const std::int64_t* const times = sae_.data() + first;
    if (params_.window == 9)
        return newest_patch_score<9>(times, seqs, stride_, newest, 9, params_.nl, scorer_, path_);
    return newest_patch_score<0>(times, seqs, stride_, newest, params_.window, params_.nl, scorer_, path_);
}

// The per-event work on locals: the state's pointers, sizes and counters are copied out of
// the detector once per call and written back at its end, so that the loop keeps them in
// registers (a member would be reloaded after every store into the planes, which may alias
// it as far as the compiler knows). Published: filter on and never-fired passes (the
// defaults), as compile-time constants.
struct FaHarrisLoops {
    struct Locals {
        ArcStarLatest* latest;
        std::int64_t* sae;       // plane 0 at pixel (0, 0) (past the frame)
        std::uint64_t* arrival;  // likewise
        std::size_t stride, plane_size;
        int width, height;
        std::int64_t filter_us;
        bool filter, zero_init, minority_only;
        double threshold;
        std::uint64_t arrivals;
        std::int64_t newest;
        bool in_time_order;
        double score;

        static Locals of(FaHarris& d) noexcept {
            const std::size_t origin = d.index(0, 0);
            return {d.latest_.data(), d.sae_.data() + origin, d.arrival_.data() + origin, d.stride_, d.plane_size_,
                    d.size_.width, d.size_.height, d.params_.filter_us, d.params_.filter, d.params_.zero_init,
                    d.params_.minority_only, d.params_.threshold, d.arrivals_, d.newest_, d.in_time_order_, d.score_};
        }
        void store(FaHarris& d) const noexcept {
            d.arrivals_ = arrivals;
            d.newest_ = newest;
            d.in_time_order_ = in_time_order;
            d.score_ = score;
        }
    };

    template <class Search, bool Published>
    static bool step(const FaHarris& det, Locals& s, const Event& e) noexcept {
        s.score = kNoScore;
        // (1) Border first: such an event changes no state at all.
        if (e.x < kCircleMargin || e.x >= s.width - kCircleMargin || e.y < kCircleMargin ||
            e.y >= s.height - kCircleMargin)
            return false;
        // (2) The Arc* filter; a passing event writes the filtered SAE and its arrival number.
        const int p = e.p & 1;
        const std::int64_t st = Sae::stored(e.t);
        ArcStarLatest& l = s.latest[static_cast<std::size_t>(e.y) * static_cast<std::size_t>(s.width) + e.x];
        const bool pass = !(Published || s.filter) |
                          arcstar_filter_passes(st, l.t[p], l.t[p ^ 1], s.filter_us, !Published && s.zero_init);
        l.t[p] = st;
        if (!pass) return false;
        const std::size_t i = static_cast<std::size_t>(p) * s.plane_size + static_cast<std::size_t>(e.y) * s.stride + e.x;
        std::int64_t* const centre = s.sae + i;
        *centre = st;
        s.arrival[i] = ++s.arrivals;
        s.in_time_order &= st >= s.newest;
        s.newest = std::max(s.newest, st);
        // (3) The Arc* candidate test (the AVX-512 path reads *centre as the event's time).
        if (!ArcStarCircles(static_cast<std::ptrdiff_t>(s.stride))
                 .pass<Search, ArcStar::kArc3Min, ArcStar::kArc3Max, ArcStar::kArc4Min, ArcStar::kArc4Max>(
                     centre, s.minority_only))
            return false;
        // (4) Harris on the nl newest filtered pixels of the window.
        s.score = det.refine(p, e.x, e.y, s.arrivals, s.newest, s.in_time_order);
        return s.score > s.threshold;  // false for NaN
    }

    template <class Search, bool Published>
    static std::size_t loop(const FaHarris& det, Locals& s, std::span<const Event> events,
                            std::span<std::uint8_t> is_corner) noexcept {
        std::size_t corners = 0;
        for (std::size_t i = 0; i < events.size(); ++i) {
            const bool c = step<Search, Published>(det, s, events[i]);
            is_corner[i] = static_cast<std::uint8_t>(c);
            corners += c;
        }
        return corners;
    }

    template <class Search>
    static std::size_t run(FaHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
        Locals s = Locals::of(det);
        const std::size_t corners = s.filter && !s.zero_init ? loop<Search, true>(det, s, events, is_corner)
                                                             : loop<Search, false>(det, s, events, is_corner);
        s.store(det);
        return corners;
    }
};

bool FaHarris::process_unchecked(const Event& e) noexcept {
    FaHarrisLoops::Locals s = FaHarrisLoops::Locals::of(*this);
    const bool c = FaHarrisLoops::step<ScalarSearch, false>(*this, s, e);
    s.store(*this);
    return c;
}

namespace {

std::size_t run_portable(FaHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return FaHarrisLoops::run<ScalarSearch>(det, events, is_corner);
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
// flatten: the per-event path (refine() aside, a call) compiled for AVX2 here only.
[[gnu::target("avx2"), gnu::flatten]] std::size_t run_avx2(FaHarris& det, std::span<const Event> events,
                                                            std::span<std::uint8_t> is_corner) noexcept {
    return FaHarrisLoops::run<Avx2Search>(det, events, is_corner);
}
// The Arc* stage by its closed form, all arcs at once (ArcStarAvx512, arcstar_test.hpp).
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::flatten]] std::size_t run_avx512(
    FaHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return FaHarrisLoops::run<Avx512Search>(det, events, is_corner);
}
#endif

using Loop = std::size_t (*)(FaHarris&, std::span<const Event>, std::span<std::uint8_t>) noexcept;

// The fastest loop this CPU runs, or the one EVCORNER_ARCSTAR_PATH names if it runs it (as
// Arc*'s, arcstar.cpp); chosen once per process.
Loop loop() noexcept {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    static const std::vector<CodePath<Loop>> paths = runnable_paths<Loop>(run_avx512, run_avx2, run_portable);
#else
    static const std::vector<CodePath<Loop>> paths = runnable_paths<Loop>(nullptr, nullptr, run_portable);
#endif
    static const Loop l = forced_or_fastest(paths, "EVCORNER_ARCSTAR_PATH").fn;
    return l;
}

}  // namespace

std::size_t detect(FaHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) {
    detail::check_flags(events.size(), is_corner.size(), "detect");
    check_events(events, det.limits());
    return loop()(det, events, is_corner);
}

std::size_t detect_unchecked(FaHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return loop()(det, events, is_corner);
}

}  // namespace evcorner
