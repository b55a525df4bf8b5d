#include "evcorner/harris_select.hpp"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define EVCORNER_HARRIS_X86 1
#define EVCORNER_HARRIS_AVX512_TARGET "avx512f,avx512cd,avx512vl,avx512bw,avx512dq,popcnt"
#define EVCORNER_HARRIS_AVX2_TARGET "avx2,popcnt"
#endif

namespace evcorner {

namespace {

constexpr int kMaxWindow = 15;
constexpr int kMaxCells = kMaxWindow * kMaxWindow;
constexpr int kBuckets = 65;  // bit width of an age: 0..64
// A boundary bucket of more cells than this is split once more before ranking.
constexpr int kRankDirectly = 12;

// ------------------------------------------------------------------ exact, any window
// Bucket every cell by the bit width of its age in arrivals (octaves, monotone in age; a
// cell that never fired has age `now`, the oldest), find the bucket where the count of
// newer cells reaches nl, light every cell of the newer buckets and rank the few cells of
// that boundary bucket exactly. Branch-free loops; four interleaved histograms so that
// runs of one bucket do not chain their increments. 64-bit ages; the boundary cells are
// ranked by keys `sequence number << 8 | position`, exact while sequence numbers stay below
// 2^56 (streams of fewer than 7e16 events: two years at 1 G events/s).
bool select_buckets(const std::uint64_t* first, std::size_t stride, int w, std::uint64_t now, int nl,
                    std::uint16_t* rows) noexcept {
    std::uint8_t bucket[kMaxCells];
    std::uint8_t histogram[4][kBuckets] = {};
    int fired = 0;
    const std::uint64_t* row = first;
    for (int r = 0, i = 0; r < w; ++r, row += stride)
        for (int c = 0; c < w; ++c, ++i) {
            const std::uint64_t seq = row[c];
            const auto b = static_cast<std::uint8_t>(std::bit_width(now - seq));
            bucket[i] = b;
            ++histogram[i & 3][b];
            fired += seq != 0;
        }
    if (fired < nl) return false;  // fewer than nl pixels ever fired in the window

    int boundary = 0, newer = 0;  // newer: cells in buckets below `boundary`
    for (;;) {
        const int here = histogram[0][boundary] + histogram[1][boundary] + histogram[2][boundary] +
                         histogram[3][boundary];
        if (newer + here >= nl) break;
        newer += here;
        ++boundary;
    }

    // The boundary bucket's keys: sequence number above the patch position, unique.
    std::uint64_t keys[kMaxCells];
    int m = 0;
    row = first;
    for (int r = 0, i = 0; r < w; ++r, row += stride) {
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
        std::uint8_t sub[kMaxCells];
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
    return true;
}

// ------------------------------------------------------------------ 9x9, threshold age
// The nl newest cells are exactly the cells whose age (now - sequence number) is at most
// some C: any C from the nl-th smallest age up to just below the (nl+1)-th (fired cells'
// ages are unique). C is found by a search on counts (how many cells are at most C old),
// which ends as soon as a count equals nl -- usually long before C is pinned down, since
// the window's nl-th and (nl+1)-th newest cells are typically many arrivals apart.
// Ages are held in 31 bits (int32, so that vector compares are plain signed ones): exact
// while now < 2^31 - 1; beyond that ages are capped at 2^31 - 1, and a window whose nl-th
// newest cell is that old cannot be decided here (the caller takes the exact code).
constexpr std::int32_t kAgeCap = 0x7FFF'FFFF;
constexpr int kLanes9 = 88;  // 81 cells and 7 padding lanes of age kAgeCap (never counted)

// The search for C, the same in every code: `count(C)` = how many cells are at most C old.
// Invariant: lo <= T <= hi, T the nl-th smallest age, and n = count(hi) >= nl. While
// n > nl, T <= hi - 1, and a probe in [lo, hi - 1] whose count is >= nl lowers hi, else
// raises lo. It ends with count(hi) == nl, at the latest at hi == T. Probes: the octave
// boundary halfway in bit width while lo and hi - 1 lie in different octaves (ages spread
// over many octaves), then the middle. (Probing where the nl-th age would lie were the ages
// evenly spread, alone or in turn with the middle, took 1-3 % more instructions.)
struct ThresholdSearch {
    std::int32_t lo, hi;
    int n, nl;

    [[nodiscard]] bool done() const noexcept { return n == nl; }
    [[nodiscard]] std::int32_t probe() const noexcept {
        const std::int32_t top = hi - 1;
        const int l = std::bit_width(static_cast<std::uint32_t>(lo));
        const int h = std::bit_width(static_cast<std::uint32_t>(top));
        if (l < h) return static_cast<std::int32_t>((std::uint32_t{1} << ((l + h) / 2)) - 1);
        return lo + (top - lo) / 2;
    }
    void take(std::int32_t at, int count) noexcept {
        if (count >= nl) {
            hi = at;
            n = count;
        } else {
            lo = at + 1;
        }
    }
};

inline int count_at_most(const std::int32_t* age, std::int32_t c) noexcept {
    int n = 0;
    for (int i = 0; i < kLanes9; ++i) n += age[i] <= c;  // vectorised by the compiler
    return n;
}

// 1: rows written; 0: fewer than nl cells fired; -1: undecidable on capped ages.
template <bool Capped>
int select9_threshold(const std::uint64_t* first, std::size_t stride, std::uint64_t now, int nl,
                      std::uint16_t* rows) noexcept {
    alignas(64) std::int32_t age[kLanes9];
    for (int r = 0; r < 9; ++r)
        for (int c = 0; c < 9; ++c) {
            const std::uint64_t a = now - first[static_cast<std::size_t>(r) * stride + c];
            age[r * 9 + c] = static_cast<std::int32_t>(Capped ? std::min<std::uint64_t>(a, kAgeCap) : a);
        }
    for (int i = 81; i < kLanes9; ++i) age[i] = kAgeCap;
    // A cell that never fired is `now` old (capped: kAgeCap), older than every fired cell.
    const std::int32_t oldest = (Capped ? kAgeCap : static_cast<std::int32_t>(now)) - 1;
    ThresholdSearch search{0, oldest, count_at_most(age, oldest), nl};  // the fired cells
    if (search.n < nl) return Capped ? -1 : 0;  // (capped: those younger than kAgeCap)
    while (!search.done()) {
        const std::int32_t probe = search.probe();
        search.take(probe, count_at_most(age, probe));
    }
    const std::int32_t hi = search.hi;
    for (int r = 0; r < 9; ++r) {
        unsigned bits = 0;
        for (int c = 0; c < 9; ++c) bits |= static_cast<unsigned>(age[r * 9 + c] <= hi) << c;
        rows[r] = static_cast<std::uint16_t>(bits);
    }
    return 1;
}

#ifdef EVCORNER_HARRIS_X86
// The threshold search with AVX2: rows 0..8 (columns 0..7) as 8-lane vectors of ages,
// column 8 (rows 0..7) gathered into a tenth, cell (8, 8) in the first lane of an eleventh
// (the other lanes kAgeCap). Only for now < kAgeCap (ages exact).
[[gnu::target(EVCORNER_HARRIS_AVX2_TARGET), gnu::always_inline]] inline __m256i narrow_ages(__m256i a, __m256i b) noexcept {
    // Low halves of 4 + 4 64-bit ages, in order: shuffle gives a0 a1 b0 b1 | a2 a3 b2 b3.
    const __m256 s = _mm256_shuffle_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), 0x88);
    return _mm256_permute4x64_epi64(_mm256_castps_si256(s), 0xD8);
}

// How many of the 88 lanes are older than c.
[[gnu::target(EVCORNER_HARRIS_AVX2_TARGET), gnu::always_inline]] inline int count_older(const __m256i* v, __m256i c) noexcept {
    __m256i s0 = _mm256_add_epi32(_mm256_cmpgt_epi32(v[0], c), _mm256_cmpgt_epi32(v[1], c));
    __m256i s1 = _mm256_add_epi32(_mm256_cmpgt_epi32(v[2], c), _mm256_cmpgt_epi32(v[3], c));
    __m256i s2 = _mm256_add_epi32(_mm256_cmpgt_epi32(v[4], c), _mm256_cmpgt_epi32(v[5], c));
    __m256i s3 = _mm256_add_epi32(_mm256_cmpgt_epi32(v[6], c), _mm256_cmpgt_epi32(v[7], c));
    __m256i s4 = _mm256_add_epi32(_mm256_cmpgt_epi32(v[8], c), _mm256_cmpgt_epi32(v[9], c));
    s0 = _mm256_add_epi32(_mm256_add_epi32(s0, s1), _mm256_add_epi32(s2, s3));
    s0 = _mm256_add_epi32(s0, _mm256_add_epi32(s4, _mm256_cmpgt_epi32(v[10], c)));
    __m128i x = _mm_add_epi32(_mm256_castsi256_si128(s0), _mm256_extracti128_si256(s0, 1));
    x = _mm_add_epi32(x, _mm_shuffle_epi32(x, 0x4E));
    x = _mm_add_epi32(x, _mm_shuffle_epi32(x, 0xB1));
    return -_mm_cvtsi128_si32(x);  // each older lane added -1
}

// Bit i: lane i is at most c old.
[[gnu::target(EVCORNER_HARRIS_AVX2_TARGET), gnu::always_inline]] inline unsigned at_most(__m256i v, __m256i c) noexcept {
    return ~static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(v, c)))) & 0xFFu;
}

[[gnu::target(EVCORNER_HARRIS_AVX2_TARGET)]] bool select9_avx2(const std::uint64_t* first, std::size_t stride,
                                                               std::uint64_t now, int nl,
                                                               std::uint16_t* rows) noexcept {
    const __m256i nowv = _mm256_set1_epi64x(static_cast<long long>(now));
    __m256i v[11];
    for (int r = 0; r < 9; ++r) {
        const std::uint64_t* row = first + static_cast<std::size_t>(r) * stride;
        v[r] = narrow_ages(_mm256_sub_epi64(nowv, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row))),
                           _mm256_sub_epi64(nowv, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + 4))));
    }
    const auto s = static_cast<long long>(stride);
    const __m256i rows03 = _mm256_setr_epi64x(0, s, 2 * s, 3 * s);
    const auto* col8 = reinterpret_cast<const long long*>(first + 8);
    v[9] = narrow_ages(_mm256_sub_epi64(nowv, _mm256_i64gather_epi64(col8, rows03, 8)),
                       _mm256_sub_epi64(nowv, _mm256_i64gather_epi64(col8 + 4 * stride, rows03, 8)));
    v[10] = _mm256_setr_epi32(static_cast<std::int32_t>(now - first[8 * stride + 8]), kAgeCap, kAgeCap, kAgeCap,
                              kAgeCap, kAgeCap, kAgeCap, kAgeCap);

    const std::int32_t oldest = static_cast<std::int32_t>(now) - 1;  // never fired: `now` old
    ThresholdSearch search{0, oldest, kLanes9 - count_older(v, _mm256_set1_epi32(oldest)), nl};
    if (search.n < nl) return false;
    while (!search.done()) {
        const std::int32_t probe = search.probe();
        search.take(probe, kLanes9 - count_older(v, _mm256_set1_epi32(probe)));
    }
    const __m256i c = _mm256_set1_epi32(search.hi);
    const unsigned col = at_most(v[9], c);  // bit r: cell (r, 8)
    for (int r = 0; r < 8; ++r) rows[r] = static_cast<std::uint16_t>(at_most(v[r], c) | (col >> r & 1u) << 8);
    rows[8] = static_cast<std::uint16_t>(at_most(v[8], c) | (at_most(v[10], c) & 1u) << 8);
    return true;
}

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
    for (int r = 0; r < 9; ++r) rows[r] = 0;
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

// Whether this CPU runs the path's instructions.
bool cpu_runs(HarrisPath path) noexcept {
    __builtin_cpu_init();
    switch (path) {
        case HarrisPath::portable: return true;
        case HarrisPath::avx2: return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt");
        case HarrisPath::avx512:
            return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
                   __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw") &&
                   __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("popcnt");
    }
    return false;
}
#else
bool cpu_runs(HarrisPath path) noexcept { return path == HarrisPath::portable; }
#endif

// Fastest first (measured on an AMD Zen 5: docs/harris.md).
constexpr HarrisPath kPreference[] = {HarrisPath::avx2, HarrisPath::avx512, HarrisPath::portable};

}  // namespace

const char* harris_path_name(HarrisPath path) noexcept {
    switch (path) {
        case HarrisPath::avx2: return "avx2";
        case HarrisPath::avx512: return "avx512";
        default: return "portable";
    }
}

HarrisPath harris_path_named(std::string_view name) {
    for (const HarrisPath p : kPreference)
        if (name == harris_path_name(p)) {
            if (!cpu_runs(p)) throw std::invalid_argument("Harris code path '" + std::string(name) + "' is not run by this CPU");
            return p;
        }
    throw std::invalid_argument("unknown Harris code path '" + std::string(name) +
                                "' (expected portable, avx2 or avx512)");
}

HarrisPath harris_default_path() noexcept {
    static const HarrisPath path = [] {
        if (const char* forced = std::getenv("EVCORNER_HARRIS_PATH"))
            for (const HarrisPath p : kPreference)
                if (std::strcmp(forced, harris_path_name(p)) == 0 && cpu_runs(p)) return p;
        for (const HarrisPath p : kPreference)
            if (cpu_runs(p)) return p;
        return HarrisPath::portable;
    }();
    return path;
}

std::vector<std::string> harris_code_paths() {
    std::vector<std::string> paths{harris_path_name(harris_default_path())};
    for (const HarrisPath p : kPreference)
        if (cpu_runs(p) && p != harris_default_path() && p != HarrisPath::portable) paths.emplace_back(harris_path_name(p));
    if (paths.back() != "portable") paths.emplace_back("portable");
    return paths;
}

bool harris_select_newest(HarrisPath path, const std::uint64_t* first, std::size_t stride, int window,
                          std::uint64_t now, int nl, std::uint16_t* rows) noexcept {
    if (window != 9) return select_buckets(first, stride, window, now, nl, rows);
#ifdef EVCORNER_HARRIS_X86
    if (path == HarrisPath::avx512) return select9_avx512(first, stride, now, nl, rows);
    if (path == HarrisPath::avx2 && now < static_cast<std::uint64_t>(kAgeCap))
        return select9_avx2(first, stride, now, nl, rows);
#else
    (void)path;
#endif
    const int decided = now < static_cast<std::uint64_t>(kAgeCap) ? select9_threshold<false>(first, stride, now, nl, rows)
                                                                  : select9_threshold<true>(first, stride, now, nl, rows);
    if (decided >= 0) return decided == 1;
    return select_buckets(first, stride, 9, now, nl, rows);
}

}  // namespace evcorner
