#include "evcorner/harris.hpp"

#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

namespace evcorner {

namespace {

constexpr int kBuckets = 65;  // bit width of an age: 0..64
// A boundary bucket of more cells than this is split once more before ranking.
constexpr int kRankDirectly = 12;

HarrisParams validated(HarrisParams p) {
    // The window and k are checked by HarrisScorer; nl depends on the window.
    if (p.window >= HarrisScorer::kMinWindow && p.window <= HarrisScorer::kMaxWindow &&
        (p.nl < 1 || p.nl > p.window * p.window))
        throw std::invalid_argument("Harris nl must be within 1.." + std::to_string(p.window * p.window) +
                                    " (window^2) (got " + std::to_string(p.nl) + ")");
    if (!std::isfinite(p.threshold)) throw std::invalid_argument("Harris threshold must be a finite number");
    return p;
}

}  // namespace

Harris::Harris(SensorSize size, HarrisParams params, int planes)
    : params_(validated(params)),
      scorer_(params_.window, params_.k),
      sae_(checked_sensor_size(size, "Harris"), params_.window / 2, planes),
      radius_(params_.window / 2) {}

// One body for both callers, inlined into each (process_unchecked() stays one call).
[[gnu::always_inline]] inline double Harris::score_window(const Event& e) const noexcept {
    const SensorSize s = sae_.size();
    // The reference's border rule: '>' on the far side, so the window of an event at
    // x = width - r reaches one column past the sensor (read as never fired).
    if (e.x < radius_ || e.x > s.width - radius_ || e.y < radius_ || e.y > s.height - radius_)
        return kNoScore;

    // Select the nl newest fired pixels of the window without sorting: bucket every
    // cell by the bit width of its age in arrivals (octaves, monotone in age; a cell that
    // never fired has age `now`, the oldest), find the bucket where the count of newer
    // cells reaches nl, light every cell of the newer buckets and rank the few cells of
    // that boundary bucket exactly. Branch-free loops; four interleaved histograms so that
    // runs of one bucket do not chain their increments.
    const int w = params_.window;
    const int nl = params_.nl;
    const std::uint64_t now = sae_.last();
    const std::uint64_t* const first = sae_.plane(e.p != 0) + sae_.index(e.x - radius_, e.y - radius_);
    std::uint8_t bucket[HarrisScorer::kMaxWindow * HarrisScorer::kMaxWindow];
    std::uint8_t histogram[4][kBuckets] = {};
    int fired = 0;
    const std::uint64_t* row = first;
    for (int r = 0, i = 0; r < w; ++r, row += sae_.stride())
        for (int c = 0; c < w; ++c, ++i) {
            const std::uint64_t seq = row[c];
            const auto b = static_cast<std::uint8_t>(std::bit_width(now - seq));
            bucket[i] = b;
            ++histogram[i & 3][b];
            fired += seq != 0;
        }
    if (fired < nl) return kNoScore;  // fewer than nl pixels ever fired in the window

    int boundary = 0, newer = 0;  // newer: cells in buckets below `boundary`
    for (;;) {
        const int here = histogram[0][boundary] + histogram[1][boundary] + histogram[2][boundary] +
                         histogram[3][boundary];
        if (newer + here >= nl) break;
        newer += here;
        ++boundary;
    }

    std::uint16_t rows[HarrisScorer::kMaxWindow];
    // The boundary bucket's keys: sequence number above the patch position, unique.
    std::uint64_t keys[HarrisScorer::kMaxWindow * HarrisScorer::kMaxWindow];
    int m = 0;
    row = first;
    for (int r = 0, i = 0; r < w; ++r, row += sae_.stride()) {
        unsigned lit = 0;
        for (int c = 0; c < w; ++c, ++i) {
            lit |= static_cast<unsigned>(bucket[i] < boundary) << c;
            keys[m] = row[c] << 8 | static_cast<std::uint64_t>(r << 4 | c);
            m += bucket[i] == boundary;
        }
        rows[r] = static_cast<std::uint16_t>(lit);
    }
    // The `take` newest keys of the boundary bucket are those with fewer than `take` newer
    // keys there. (Cells that never fired have key < 2^8, below every fired cell's, and
    // fired >= nl guarantees they are never taken.)
    int take = nl - newer;  // 1..m
    // A crowded boundary bucket (ranking it directly costs m^2 compares; with an active
    // window m often passes 30, and an edge's burst puts them close in age): split it by
    // the next four bits of the age below its leading bit (16 sub-buckets, monotone in
    // age), light the newer sub-buckets, keep the boundary one's cells, and again with the
    // next four bits, until few cells are left. Cells kept share every age bit above
    // `shift`, so (age >> shift) & 15 stays monotone in age among them. Only cells that
    // never fired share an age; they are ranked by key below.
    int shift = boundary > 5 ? boundary - 5 : 0;
    while (m > kRankDirectly) {
        std::uint8_t sub[HarrisScorer::kMaxWindow * HarrisScorer::kMaxWindow];
        std::uint8_t sub_histogram[16] = {};
        for (int j = 0; j < m; ++j) {
            const std::uint64_t age = now - (keys[j] >> 8);
            sub[j] = static_cast<std::uint8_t>((age >> shift) & 15);
            ++sub_histogram[sub[j]];
        }
        int sub_boundary = 0;
        while (sub_histogram[sub_boundary] < take) take -= sub_histogram[sub_boundary++];
        int kept = 0;
        for (int j = 0; j < m; ++j) {
            const std::uint64_t key = keys[j];
            rows[key >> 4 & 15] |= static_cast<std::uint16_t>(static_cast<unsigned>(sub[j] < sub_boundary) << (key & 15));
            keys[kept] = key;
            kept += sub[j] == sub_boundary;
        }
        m = kept;
        if (shift == 0) break;
        shift = shift > 4 ? shift - 4 : 0;
    }
    for (int j = 0; j < m; ++j) {
        int rank = 0;
        for (int k = 0; k < m; ++k) rank += keys[k] > keys[j];
        const std::uint64_t key = keys[j];
        rows[key >> 4 & 15] |= static_cast<std::uint16_t>(static_cast<unsigned>(rank < take) << (key & 15));
    }
    return scorer_.score(rows);
}

bool Harris::process_unchecked(const Event& e) noexcept {
    sae_.update_unchecked(e);
    score_ = score_window(e);
    return score_ > params_.threshold;  // false for kNoScore (NaN)
}

double Harris::score_latest(const Event& e) const noexcept { return score_window(e); }

}  // namespace evcorner
