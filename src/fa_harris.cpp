#include "evcorner/fa_harris.hpp"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <cmath>
#include <stdexcept>
#include <string>

#include "evcorner/circle.hpp"

namespace evcorner {

namespace {

constexpr int kBuckets = 65;  // bit width of an age: 0..64

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
      arrival_(2 * plane_size_) {}

std::uint64_t FaHarris::state_bytes(SensorSize size, const Params& params, int) noexcept {
    const auto pad = static_cast<std::uint64_t>(frame(params.window));
    const std::uint64_t framed = (static_cast<std::uint64_t>(size.width) + 2 * pad) *
                                 (static_cast<std::uint64_t>(size.height) + 2 * pad);
    return static_cast<std::uint64_t>(size.pixels()) * sizeof(ArcStarLatest) + 2 * framed * 2 * sizeof(std::int64_t);
}

template <class Search>
bool FaHarris::process_with(const Event& e) noexcept {
    score_ = kNoScore;
    // (1) Border first: such an event changes no state at all.
    if (e.x < kCircleMargin || e.x >= size_.width - kCircleMargin || e.y < kCircleMargin ||
        e.y >= size_.height - kCircleMargin)
        return false;
    // (2) The Arc* filter; a passing event writes the filtered SAE and its arrival number.
    const int p = e.p & 1;
    const std::int64_t st = Sae::stored(e.t);
    ArcStarLatest& l = latest_[static_cast<std::size_t>(e.y) * static_cast<std::size_t>(size_.width) + e.x];
    const bool pass = !params_.filter | arcstar_filter_passes(st, l.t[p], l.t[p ^ 1], params_.filter_us, params_.zero_init);
    l.t[p] = st;
    if (!pass) return false;
    const std::size_t i = plane(p) + index(e.x, e.y);
    std::int64_t* const centre = sae_.data() + i;
    *centre = st;
    arrival_[i] = ++arrivals_;
    newest_ = std::max(newest_, st);
    // (3) The Arc* candidate test (the AVX-512 path reads *centre as the event's time).
    if (!ArcStarCircles(static_cast<std::ptrdiff_t>(stride_))
             .pass<Search, ArcStar::kArc3Min, ArcStar::kArc3Max, ArcStar::kArc4Min, ArcStar::kArc4Max>(
                 centre, params_.minority_only))
        return false;
    // (4) Harris on the nl newest filtered pixels of the window.
    score_ = refine(p, e.x, e.y);
    return score_ > params_.threshold;  // false for NaN
}

// The nl newest filtered pixels of the window, without sorting: bucket every cell by
// the bit width of its age newest_ - t (octaves, monotone in age; a never-fired cell,
// stored 0, lands in the oldest bucket of all), find the bucket where the count of newer
// cells reaches nl, light every cell of the newer buckets and rank the few cells of that
// boundary bucket exactly by (time, arrival).
double FaHarris::refine(int p, int x, int y) const noexcept {
    const int w = params_.window;
    const int nl = params_.nl;
    const int r = w / 2;
    const std::size_t first = plane(p) + index(x - r, y - r);
    const std::int64_t* const times = sae_.data() + first;
    const std::uint64_t* const seqs = arrival_.data() + first;
    std::uint8_t bucket[HarrisScorer::kMaxWindow * HarrisScorer::kMaxWindow];
    std::uint8_t histogram[4][kBuckets] = {};
    int fired = 0;
    for (int row = 0, i = 0; row < w; ++row)
        for (int c = 0; c < w; ++c, ++i) {
            const std::int64_t t = times[static_cast<std::size_t>(row) * stride_ + static_cast<std::size_t>(c)];
            const auto b = static_cast<std::uint8_t>(
                std::bit_width(static_cast<std::uint64_t>(newest_) - static_cast<std::uint64_t>(t)));
            bucket[i] = b;
            ++histogram[i & 3][b];
            fired += t != 0;
        }
    if (fired < nl) return kNoScore;

    int boundary = 0, newer = 0;  // newer: cells in buckets below `boundary`
    for (;;) {
        const int here =
            histogram[0][boundary] + histogram[1][boundary] + histogram[2][boundary] + histogram[3][boundary];
        if (newer + here >= nl) break;
        newer += here;
        ++boundary;
    }
    std::uint16_t rows[HarrisScorer::kMaxWindow];
    // The boundary bucket's cells, by position (row << 4 | column), gathered in the same
    // pass; their (time, arrival) keys are read afterwards for those few cells only.
    std::uint8_t where[HarrisScorer::kMaxWindow * HarrisScorer::kMaxWindow];
    int m = 0;
    for (int row = 0, i = 0; row < w; ++row) {
        unsigned lit = 0;
        for (int c = 0; c < w; ++c, ++i) {
            lit |= static_cast<unsigned>(bucket[i] < boundary) << c;
            where[m] = static_cast<std::uint8_t>(row << 4 | c);
            m += bucket[i] == boundary;
        }
        rows[row] = static_cast<std::uint16_t>(lit);
    }
    struct Key {
        std::int64_t t;
        std::uint64_t q;
        int row, col;
    };
    Key keys[HarrisScorer::kMaxWindow * HarrisScorer::kMaxWindow];
    for (int j = 0; j < m; ++j) {
        const int row = where[j] >> 4, col = where[j] & 15;
        const std::size_t at = static_cast<std::size_t>(row) * stride_ + static_cast<std::size_t>(col);
        keys[j] = {times[at], seqs[at], row, col};
    }
    // Light the `take` newest of the boundary bucket: newer = later time, or the same time
    // and a later arrival (arrival numbers are unique among fired cells; never-fired cells,
    // time 0 and arrival 0, are the oldest, and fired >= nl keeps them out).
    const int take = nl - newer;  // 1..m
    if (take < m) {
        std::nth_element(keys, keys + (take - 1), keys + m, [](const Key& a, const Key& b) {
            return a.t != b.t ? a.t > b.t : a.q > b.q;
        });
    }
    for (int j = 0; j < take; ++j) rows[keys[j].row] |= static_cast<std::uint16_t>(1u << keys[j].col);
    return scorer_.score(rows);
}

bool FaHarris::process_unchecked(const Event& e) noexcept { return process_with<ScalarSearch>(e); }

struct FaHarrisLoops {
    template <class Search>
    static std::size_t run(FaHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
        std::size_t corners = 0;
        for (std::size_t i = 0; i < events.size(); ++i) {
            const bool c = det.process_with<Search>(events[i]);
            is_corner[i] = static_cast<std::uint8_t>(c);
            corners += c;
        }
        return corners;
    }
};

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
// Arc*'s, arcstar.cpp).
Loop loop() noexcept {
    static const Loop l = [] {
        const char* forced = std::getenv("EVCORNER_ARCSTAR_PATH");
        const auto wanted = [forced](const char* name) { return forced == nullptr || std::strcmp(forced, name) == 0; };
#ifdef EVCORNER_HAVE_AVX2_SEARCH
        __builtin_cpu_init();
        if (wanted("avx512") && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
            __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq"))
            return static_cast<Loop>(run_avx512);
        if ((wanted("avx2") || wanted("avx512")) && __builtin_cpu_supports("avx2")) return static_cast<Loop>(run_avx2);
#endif
        return static_cast<Loop>(run_portable);
    }();
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
