#include "evcorner/harris.hpp"

#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define EVCORNER_HARRIS_AVX512 1
#define EVCORNER_HARRIS_AVX512_TARGET "avx512f,avx512cd,avx512vl,avx512bw,avx512dq,popcnt"
#endif

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

#ifdef EVCORNER_HARRIS_AVX512
// The 9x9 selection with AVX-512 (the same cells lit as the portable code): the 81 cells
// as 9 row vectors (columns 0..7), one gathered column 8 (rows 0..7) and cell (8, 8);
// bit widths of the ages by lzcnt; the boundary bucket by a binary search on counts; the
// newer buckets lit from compare masks; the boundary bucket's cells compressed and
// ranked by vector compares. Returns false (nothing written) when fewer than nl fired.
[[gnu::target(EVCORNER_HARRIS_AVX512_TARGET)]] bool select9_avx512(const std::uint64_t* first, std::size_t stride,
                                                                   std::uint64_t now, int nl,
                                                                   std::uint16_t* rows) noexcept {
    constexpr int kVectors = 11;
    __m512i lz[kVectors], seq[kVectors];
    __mmask8 active[kVectors];
    const __m512i nowv = _mm512_set1_epi64(static_cast<long long>(now));
    for (int r = 0; r < 9; ++r) {
        seq[r] = _mm512_loadu_si512(first + static_cast<std::size_t>(r) * stride);
        active[r] = 0xFF;
    }
    const __m512i col8 = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
    seq[9] = _mm512_mask_i64gather_epi64(_mm512_setzero_si512(), 0xFF,
                                         _mm512_mullo_epi64(col8, _mm512_set1_epi64(static_cast<long long>(stride))),
                                         first + 8, 8);
    active[9] = 0xFF;
    seq[10] = _mm512_maskz_loadu_epi64(0x01, first + 8 * stride + 8);
    active[10] = 0x01;
    int fired = 0;
    for (int v = 0; v < kVectors; ++v) {
        lz[v] = _mm512_lzcnt_epi64(_mm512_sub_epi64(nowv, seq[v]));  // 64 - bit width of the age
        fired += std::popcount(static_cast<unsigned>(_mm512_mask_test_epi64_mask(active[v], seq[v], seq[v])));
    }
    if (fired < nl) return false;
    // Boundary bucket b: the smallest bit width with count(width <= b) >= nl, i.e. with
    // count(lz >= 64 - b) >= nl (binary search; no lambda: it would not inherit the target).
    int lo = 0, hi = 64;
    while (lo < hi) {
        const int mid = (lo + hi) / 2;
        const __m512i zv = _mm512_set1_epi64(64 - mid);
        int n = 0;
        for (int v = 0; v < kVectors; ++v)
            n += std::popcount(static_cast<unsigned>(_mm512_mask_cmpge_epu64_mask(active[v], lz[v], zv)));
        if (n >= nl)
            hi = mid;
        else
            lo = mid + 1;
    }
    const int boundary = lo;
    const __m512i zb = _mm512_set1_epi64(64 - boundary);
    // Lit: width < boundary (lz > 64 - boundary). Boundary cells: compressed seqs and positions.
    std::uint64_t bseq[88];
    std::uint64_t bpos[88];
    int m = 0, newer = 0;
    const __m512i pos_row = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
    for (int v = 0; v < kVectors; ++v) {
        const __mmask8 lit = _mm512_mask_cmpgt_epu64_mask(active[v], lz[v], zb);
        const __mmask8 edge = _mm512_mask_cmpeq_epu64_mask(active[v], lz[v], zb);
        newer += std::popcount(static_cast<unsigned>(lit));
        __m512i pos;  // r << 4 | c per lane
        if (v < 9) {
            for (int c = 0; c < 8; ++c)
                rows[v] = static_cast<std::uint16_t>(rows[v] | ((lit >> c & 1u) << c));
            pos = _mm512_add_epi64(_mm512_set1_epi64(v << 4), pos_row);
        } else if (v == 9) {
            for (int r = 0; r < 8; ++r) rows[r] = static_cast<std::uint16_t>(rows[r] | ((lit >> r & 1u) << 8));
            pos = _mm512_add_epi64(_mm512_slli_epi64(pos_row, 4), _mm512_set1_epi64(8));
        } else {
            rows[8] = static_cast<std::uint16_t>(rows[8] | ((lit & 1u) << 8));
            pos = _mm512_set1_epi64(8 << 4 | 8);
        }
        _mm512_mask_compressstoreu_epi64(bseq + m, edge, seq[v]);
        _mm512_mask_compressstoreu_epi64(bpos + m, edge, pos);
        m += std::popcount(static_cast<unsigned>(edge));
    }
    const int take = nl - newer;  // 1..m
    for (int j = m; j < ((m + 7) & ~7); ++j) bseq[j] = 0;  // never greater than a cell
    // Seqs of fired cells are unique; cells that never fired (seq 0) rank below every
    // fired one, and enough fired cells are in the bucket, so they are never taken.
    for (int j = 0; j < m; ++j) {
        const __m512i key = _mm512_set1_epi64(static_cast<long long>(bseq[j]));
        int rank = 0;
        for (int k = 0; k < m; k += 8)
            rank += std::popcount(static_cast<unsigned>(_mm512_cmpgt_epu64_mask(_mm512_loadu_si512(bseq + k), key)));
        const std::uint64_t pos = bpos[j];
        rows[pos >> 4] = static_cast<std::uint16_t>(rows[pos >> 4] | (static_cast<unsigned>(rank < take) << (pos & 15)));
    }
    return true;
}

bool cpu_runs_avx512() {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
           __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw") &&
           __builtin_cpu_supports("avx512dq");
}
#endif

// The 9x9 AVX-512 selection is used when the CPU runs it, unless the environment variable
// EVCORNER_HARRIS_PATH=portable asks for the portable code.
bool harris_avx512() {
#ifdef EVCORNER_HARRIS_AVX512
    static const bool use = [] {
        const char* forced = std::getenv("EVCORNER_HARRIS_PATH");
        if (forced != nullptr && std::strcmp(forced, "portable") == 0) return false;
        return cpu_runs_avx512();
    }();
    return use;
#else
    return false;
#endif
}

}  // namespace

const char* harris_code_path() noexcept { return harris_avx512() ? "avx512" : "portable"; }

Harris::Harris(SensorSize size, HarrisParams params, int planes)
    : params_(validated(params)),
      scorer_(params_.window, params_.k),
      sae_(checked_sensor_size(size, "Harris"), params_.window / 2, planes),
      radius_(params_.window / 2),
      avx512_(params_.window == 9 && harris_avx512()) {}

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
#ifdef EVCORNER_HARRIS_AVX512
    if (avx512_) {
        std::uint16_t lit[9] = {};
        if (!select9_avx512(first, sae_.stride(), now, nl, lit)) return kNoScore;
        return scorer_.score(lit);
    }
#endif
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
