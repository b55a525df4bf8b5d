// luvHarris (docs/luvharris.md). Determinism: the table is integer arithmetic up to one
// fixed conversion to double; the adaptive statistics are double arithmetic whose
// operations must not be fused (an FMA rounds once where a multiply and an add round
// twice, and a build for a CPU with FMA could otherwise differ from one without).
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

#include "evcorner/luvharris.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

namespace evcorner {

namespace {

__extension__ typedef __int128 Int128;

[[noreturn]] void bad(const std::string& what) { throw std::invalid_argument("luvHarris " + what); }

LuvHarrisParams validated(const LuvHarrisParams& p) {
    if (p.tos_size < 3 || p.tos_size > 31 || p.tos_size % 2 == 0)
        bad("tos_size must be odd and within 3..31 (got " + std::to_string(p.tos_size) + ")");
    if (p.tos_threshold < 0 || p.tos_size * p.tos_threshold > 254)
        bad("tos_threshold must be within 0.." + std::to_string(254 / p.tos_size) + " (254 / tos_size) (got " +
            std::to_string(p.tos_threshold) + ")");
    if (p.gradient != 3 && p.gradient != 5) bad("gradient must be 3 or 5 (got " + std::to_string(p.gradient) + ")");
    const int max_block = p.gaussian_block ? 9 : 15;
    const int min_block = p.gaussian_block ? 3 : 1;
    if (p.block < min_block || p.block > max_block || p.block % 2 == 0)
        bad(std::string("block must be odd and within ") + std::to_string(min_block) + ".." + std::to_string(max_block) +
            (p.gaussian_block ? " (gaussian)" : " (box)") + " (got " + std::to_string(p.block) + ")");
    if (!(p.k >= 0.0 && p.k <= 0.25)) bad("k must be within 0..0.25");
    if (p.refresh_us < 0 || p.refresh_us > LuvHarris::kMaxRefreshUs)
        bad("refresh_us must be within 0.." + std::to_string(LuvHarris::kMaxRefreshUs) + " (got " +
            std::to_string(p.refresh_us) + ")");
    if (p.refresh_events < 0) bad("refresh_events must be >= 0 (got " + std::to_string(p.refresh_events) + ")");
    if (p.refresh_us == 0 && p.refresh_events == 0)
        bad("refresh_us and refresh_events cannot both be 0 (the table would never be computed)");
    if (!std::isfinite(p.sigmas)) bad("sigmas must be a finite number");
    if (!(p.alpha > 0.0 && p.alpha <= 1.0)) bad("alpha must be within (0, 1]");
    if (!std::isfinite(p.threshold)) bad("threshold must be a finite number");
    return p;
}

std::vector<std::int32_t> block_weights(const LuvHarrisParams& p) {
    std::vector<std::int32_t> w(static_cast<std::size_t>(p.block), 1);
    if (p.gaussian_block) {  // binomial: row block-1 of Pascal's triangle
        for (int n = 1; n < p.block; ++n)
            for (int j = n - 1; j >= 1; --j) w[static_cast<std::size_t>(j)] += w[static_cast<std::size_t>(j - 1)];
    }
    return w;
}

struct Geometry {
    std::size_t w, h, hg, hb, pad, stride, gw, gh;
};
Geometry geometry(SensorSize s, const LuvHarrisParams& p) {
    Geometry g{};
    g.w = static_cast<std::size_t>(s.width);
    g.h = static_cast<std::size_t>(s.height);
    g.hg = static_cast<std::size_t>(p.gradient / 2);
    g.hb = static_cast<std::size_t>(p.block / 2);
    g.pad = g.hg + g.hb;
    g.stride = g.w + 2 * g.pad;
    g.gw = g.w + 2 * g.hb;  // gradient columns: the sensor and the block's reach
    g.gh = g.h + 2 * g.hb;
    return g;
}

// The ring buffers' sizes: gradient rows x gw for the two horizontal passes, three
// product rows of gw, block rows x width for the three horizontal block sums.
struct BufferSizes {
    std::size_t tos, table, h_ring, products, b_ring, tiles;
};

constexpr int kTileShift = 3;  // 8x8 tiles of dirty and stale marks
constexpr int kTile = 1 << kTileShift;
// A refresh after more than pixels / kLazyFactor events computes the whole table at once
// (measured: about 14 ns a pixel) rather than value by value when read (each event reads at
// most one; about 45 ns a value with its share of the refresh's copying and marking).
constexpr std::uint64_t kLazyFactor = 3;
BufferSizes buffer_sizes(SensorSize s, const LuvHarrisParams& p) {
    const Geometry g = geometry(s, p);
    // The TOS with 16 bytes of slack for update_tos(); the block ring and one accumulator row.
    const std::size_t tiles = ((g.w + kTile - 1) >> kTileShift) * ((g.h + kTile - 1) >> kTileShift);
    return {g.stride * (g.h + 2 * g.pad) + 16, g.w * g.h, static_cast<std::size_t>(p.gradient) * g.gw, 3 * g.gw,
            3 * (static_cast<std::size_t>(p.block) + 1) * g.w, tiles};
}

}  // namespace

double luv_harris_response(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t k_q, double scale) noexcept {
    const Int128 det = static_cast<Int128>(a) * c - static_cast<Int128>(b) * b;
    const std::int64_t tr = a + c;  // < 2^46 for every allowed parameter set
    const Int128 r = det * 65536 - static_cast<Int128>(tr) * tr * k_q;  // |r| < 2^106 for every allowed parameter set
    // To double: the high part (exact up to its own rounding) times 2^48 (exact), plus the
    // low 48 bits (exact), rounded once; then the scale. The same on every IEEE machine.
    const auto hi = static_cast<std::int64_t>(r >> 48);
    const auto lo = static_cast<std::int64_t>(r & ((Int128{1} << 48) - 1));
    const double value = static_cast<double>(hi) * 281474976710656.0 + static_cast<double>(lo);
    return value * scale;
}

LuvHarris::LuvHarris(SensorSize size, const Params& params, int /*planes*/)
    : params_(validated(params)),
      size_(checked_sensor_size(size, "luvHarris")),
      pad_(params_.gradient / 2 + params_.block / 2),
      stride_(static_cast<std::size_t>(size_.width) + 2 * static_cast<std::size_t>(pad_)),
      tos_drop_(255 - params_.tos_size * params_.tos_threshold),
      k_q_(std::llround(params_.k * 65536.0)),
      block_weights_(block_weights(params_)) {
    // Gradients in TOS levels per pixel: the integer kernels give 128 (5x5) or 8 (3x3)
    // times the slope of a ramp; the block sums weights adding up to ws per axis.
    const double gn = params_.gradient == 5 ? 128.0 : 8.0;
    double ws = 0;
    for (const std::int32_t w : block_weights_) ws += w;
    const double d = gn * gn * ws * ws;  // exact
    scale_ = 1.0 / (d * d) / 65536.0;
    const BufferSizes b = buffer_sizes(size_, params_);
    tos_ = ZeroedArray<std::uint8_t>(b.tos);
    snap_ = ZeroedArray<std::uint8_t>(b.tos);
    table_ = ZeroedArray<double>(b.table);
    stamp_ = ZeroedArray<std::uint32_t>(b.table);
    tiles_w_ = (static_cast<std::size_t>(size_.width) + kTile - 1) >> kTileShift;
    stale_since_.assign(b.tiles, 1);  // every value is stale at the first refresh (epoch 1)
    dirty_.assign(b.tiles, 0);
    dirty_list_ = ZeroedArray<std::uint32_t>(b.tiles);
    hs_ = ZeroedArray<std::int16_t>(b.h_ring);
    hd_ = ZeroedArray<std::int16_t>(b.h_ring);
    xx_ = ZeroedArray<std::int32_t>(b.products);
    bxx_ = ZeroedArray<std::int64_t>(b.b_ring);
    until_count_refresh_ = params_.refresh_events;
}

std::uint64_t LuvHarris::state_bytes(SensorSize size, const Params& params, int /*planes*/) noexcept {
    const BufferSizes b = buffer_sizes(size, params);
    return 2 * b.tos + b.table * (sizeof(double) + sizeof(std::uint32_t)) + 2 * b.h_ring * sizeof(std::int16_t) +
           b.products * sizeof(std::int32_t) + b.b_ring * sizeof(std::int64_t) +
           b.tiles * (2 * sizeof(std::uint32_t) + 1);
}

std::size_t LuvHarris::memory_bytes() const noexcept {
    return tos_.size() + snap_.size() + table_.size() * sizeof(double) + stamp_.size() * sizeof(std::uint32_t) +
           (hs_.size() + hd_.size()) * sizeof(std::int16_t) + xx_.size() * sizeof(std::int32_t) +
           bxx_.size() * sizeof(std::int64_t) +
           stale_since_.size() * sizeof(std::uint32_t) + dirty_list_.size() * sizeof(std::uint32_t) + dirty_.size();
}

void LuvHarris::mark_dirty(int x, int y) noexcept {
    // The tiles of the TOS update's footprint (the tos_size square clipped to the sensor).
    const int r = params_.tos_size / 2;
    const int tx0 = std::max(x - r, 0) >> kTileShift, tx1 = std::min(x + r, size_.width - 1) >> kTileShift;
    const int ty0 = std::max(y - r, 0) >> kTileShift, ty1 = std::min(y + r, size_.height - 1) >> kTileShift;
    for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) {
            const std::size_t t = static_cast<std::size_t>(ty) * tiles_w_ + static_cast<std::size_t>(tx);
            if (dirty_[t]) continue;
            dirty_[t] = 1;
            dirty_list_[dirty_count_++] = static_cast<std::uint32_t>(t);
        }
}

void LuvHarris::update_tos(int x, int y) noexcept {
    const int r = params_.tos_size / 2;
    const int x0 = std::max(x - r, 0), x1 = std::min(x + r, size_.width - 1);
    const int y0 = std::max(y - r, 0), y1 = std::min(y + r, size_.height - 1);
    const int drop = tos_drop_;
#ifdef __SSE2__
    // 16 bytes at a time: v >= drop (unsigned max(v, drop) == v) keeps v - 1, else 0;
    // lanes outside x0..x1 are written back unchanged (the buffer has 16 bytes of slack).
    const __m128i dropv = _mm_set1_epi8(static_cast<char>(drop));
    const __m128i one = _mm_set1_epi8(1);
    const __m128i lane = _mm_setr_epi8(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    for (int xs = x0; xs <= x1; xs += 16) {
        const int n = std::min(16, x1 - xs + 1);
        const __m128i inside = _mm_cmplt_epi8(lane, _mm_set1_epi8(static_cast<char>(n)));
        for (int yy = y0; yy <= y1; ++yy) {
            auto* const at = reinterpret_cast<__m128i*>(tos_.data() + index(xs, yy));
            const __m128i v = _mm_loadu_si128(at);
            const __m128i keep = _mm_cmpeq_epi8(_mm_max_epu8(v, dropv), v);
            const __m128i next = _mm_and_si128(_mm_sub_epi8(v, one), keep);
            _mm_storeu_si128(at, _mm_or_si128(_mm_and_si128(inside, next), _mm_andnot_si128(inside, v)));
        }
    }
#else
    for (int yy = y0; yy <= y1; ++yy) {
        std::uint8_t* row = tos_.data() + index(0, yy);
        for (int xx = x0; xx <= x1; ++xx) {
            const int v = row[xx];
            row[xx] = static_cast<std::uint8_t>(v < drop ? 0 : v - 1);
        }
    }
#endif
    tos_[index(x, y)] = 255;
}

void LuvHarris::fill_border() noexcept {  // of the copy the table reads
    const std::size_t p = static_cast<std::size_t>(pad_), w = static_cast<std::size_t>(size_.width),
                      h = static_cast<std::size_t>(size_.height);
    std::uint8_t* t = snap_.data();
    for (std::size_t y = p; y < p + h; ++y) {
        std::uint8_t* row = t + y * stride_;
        std::fill(row, row + p, row[p]);
        std::fill(row + p + w, row + stride_, row[p + w - 1]);
    }
    for (std::size_t y = 0; y < p; ++y) {
        std::copy(t + p * stride_, t + (p + 1) * stride_, t + y * stride_);
        std::copy(t + (p + h - 1) * stride_, t + (p + h) * stride_, t + (p + h + y) * stride_);
    }
}

namespace {

// The table from the TOS, row by row through ring buffers (all in cache): for product
// row q (rows -hb..h+hb of the sensor), the horizontal passes of TOS row q+g-1, the
// vertical pass giving Ix, Iy and their products over gw columns, the horizontal block
// sums into the block ring; then, once b rows are there, the vertical block sums and the
// response of sensor row q-b+1. Every inner loop runs along a row with compile-time taps
// or a tap outside it, so that the compiler vectorises it.
template <int G>
struct Taps;
template <>
struct Taps<5> {
    static constexpr int smooth[5] = {1, 4, 6, 4, 1};
    static constexpr int deriv[5] = {1, 2, 0, -2, -1};
};
template <>
struct Taps<3> {
    static constexpr int smooth[3] = {1, 2, 1};
    static constexpr int deriv[3] = {1, 0, -1};
};

struct RefreshBuffers {
    std::int16_t* hs;     // G rows x gw
    std::int16_t* hd;     // G rows x gw
    std::int32_t* prod;   // 3 x gw
    std::int64_t* bring;  // b rows x 3 x w
    std::int64_t* acc;    // 3 x w
};

// Box: every block weight is 1 (adds only: a 64-bit multiply has no SSE2 instruction).
template <int G, bool Box>
void refresh_table(const Geometry& g, const std::uint8_t* tos, const RefreshBuffers& buf,
                   const std::vector<std::int32_t>& wts, std::int64_t k_q, double scale, double* table) noexcept {
    constexpr const int* smooth = Taps<G>::smooth;
    constexpr const int* deriv = Taps<G>::deriv;
    const std::size_t gw = g.gw, w = g.w, b = wts.size();

    auto horizontal = [&](std::size_t r) {  // TOS row r (padded coordinates) -> ring slot r % G
        const std::uint8_t* in = tos + r * g.stride;
        std::int16_t* s = buf.hs + (r % G) * gw;
        std::int16_t* d = buf.hd + (r % G) * gw;
        for (std::size_t c = 0; c < gw; ++c) {
            int sv = 0, dv = 0;
            for (int j = 0; j < G; ++j) {
                sv += smooth[j] * in[c + static_cast<std::size_t>(j)];
                dv += deriv[j] * in[c + static_cast<std::size_t>(j)];
            }
            s[c] = static_cast<std::int16_t>(sv);
            d[c] = static_cast<std::int16_t>(dv);
        }
    };
    for (std::size_t r = 0; r + 1 < G; ++r) horizontal(r);

    std::int32_t* const pxx = buf.prod;
    std::int32_t* const pxy = buf.prod + gw;
    std::int32_t* const pyy = buf.prod + 2 * gw;
    std::int64_t* const axx = buf.acc;
    std::int64_t* const axy = buf.acc + w;
    std::int64_t* const ayy = buf.acc + 2 * w;
    for (std::size_t q = 0; q < g.gh; ++q) {
        horizontal(q + G - 1);
        const std::int16_t* sr[G];
        const std::int16_t* dr[G];
        for (int i = 0; i < G; ++i) {
            sr[i] = buf.hs + ((q + static_cast<std::size_t>(i)) % G) * gw;
            dr[i] = buf.hd + ((q + static_cast<std::size_t>(i)) % G) * gw;
        }
        for (std::size_t c = 0; c < gw; ++c) {
            int ix = 0, iy = 0;
            for (int i = 0; i < G; ++i) {
                ix += smooth[i] * dr[i][c];
                iy += deriv[i] * sr[i][c];
            }
            pxx[c] = ix * ix;
            pxy[c] = ix * iy;
            pyy[c] = iy * iy;
        }
        std::int64_t* const bxx = buf.bring + (q % b) * 3 * w;
        std::int64_t* const bxy = bxx + w;
        std::int64_t* const byy = bxy + w;
        std::fill(bxx, bxx + 3 * w, std::int64_t{0});
        for (std::size_t j = 0; j < b; ++j) {
            const std::int64_t wt = wts[j];
            for (std::size_t x = 0; x < w; ++x) {
                if constexpr (Box) {
                    bxx[x] += pxx[x + j];
                    bxy[x] += pxy[x + j];
                    byy[x] += pyy[x + j];
                } else {
                    bxx[x] += wt * pxx[x + j];
                    bxy[x] += wt * pxy[x + j];
                    byy[x] += wt * pyy[x + j];
                }
            }
        }
        if (q + 1 < b) continue;
        const std::size_t y = q + 1 - b;  // sensor row: block rows y..y+b-1 of the ring
        std::fill(axx, axx + 3 * w, std::int64_t{0});
        for (std::size_t i = 0; i < b; ++i) {
            const std::int64_t wt = wts[i];
            const std::int64_t* const row = buf.bring + ((y + i) % b) * 3 * w;
            if constexpr (Box)
                for (std::size_t x = 0; x < 3 * w; ++x) axx[x] += row[x];
            else
                for (std::size_t x = 0; x < 3 * w; ++x) axx[x] += wt * row[x];
        }
        double* const out = table + y * w;
        for (std::size_t x = 0; x < w; ++x) out[x] = luv_harris_response(axx[x], axy[x], ayy[x], k_q, scale);
    }
}

// One table value: the sums refresh_table forms for sensor pixel (x, y), whose window of
// the framed TOS starts at row y, column x (integers, exact in any order: the same value).
// B: the block side at compile time (0: b at run time, at most 15).
template <int G, int B, bool Box>
double pixel_value(const std::uint8_t* tos, std::size_t stride, std::size_t x, std::size_t y, const std::int32_t* wts,
                   int b_run, std::int64_t k_q, double scale) noexcept {
    constexpr const int* smooth = Taps<G>::smooth;
    constexpr const int* deriv = Taps<G>::deriv;
    constexpr int kMaxB = B > 0 ? B : 15;
    const int b = B > 0 ? B : b_run;
    std::int32_t hs[kMaxB + G - 1][kMaxB], hd[kMaxB + G - 1][kMaxB];
    for (int r = 0; r < b + G - 1; ++r) {
        const std::uint8_t* in = tos + (y + static_cast<std::size_t>(r)) * stride + x;
        for (int c = 0; c < b; ++c) {
            int sv = 0, dv = 0;
            for (int j = 0; j < G; ++j) {
                sv += smooth[j] * in[c + j];
                dv += deriv[j] * in[c + j];
            }
            hs[r][c] = sv;
            hd[r][c] = dv;
        }
    }
    std::int64_t a = 0, m = 0, c2 = 0;
    for (int q = 0; q < b; ++q) {
        std::int64_t rxx = 0, rxy = 0, ryy = 0;
        for (int c = 0; c < b; ++c) {
            int ix = 0, iy = 0;
            for (int i = 0; i < G; ++i) {
                ix += smooth[i] * hd[q + i][c];
                iy += deriv[i] * hs[q + i][c];
            }
            const std::int64_t wc = Box ? 1 : wts[c];
            rxx += wc * (ix * ix);
            rxy += wc * (ix * iy);
            ryy += wc * (iy * iy);
        }
        const std::int64_t wq = Box ? 1 : wts[q];
        a += wq * rxx;
        m += wq * rxy;
        c2 += wq * ryy;
    }
    return luv_harris_response(a, m, c2, k_q, scale);
}

#ifdef __SSE2__
// pixel_value for a box block of B <= 7 columns, 8 lanes of 16 bits across the block's
// columns: the horizontal passes of each window row (|values| <= 4080), the vertical pass
// (|Ix|, |Iy| <= 24480), the products summed in pairs (_mm_madd_epi16, <= 2 x 24480^2 <
// 2^31) and widened to 64 bits before the sum over the block.
template <int G, int B>
double pixel_value_box_sse2(const std::uint8_t* tos, std::size_t stride, std::size_t x, std::size_t y,
                            std::int64_t k_q, double scale) noexcept {
    static_assert(B >= 1 && B <= 7 && (G == 3 || G == 5));
    constexpr int R = B + G - 1;
    const __m128i zero = _mm_setzero_si128();
    __m128i hs[R], hd[R];
    for (int r = 0; r < R; ++r) {
        const std::uint8_t* in = tos + (y + static_cast<std::size_t>(r)) * stride + x;
        __m128i v[G];
        for (int j = 0; j < G; ++j)
            v[j] = _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(in + j)), zero);
        if constexpr (G == 5) {  // smooth 1 4 6 4 1, derivative 1 2 0 -2 -1
            const __m128i v13 = _mm_add_epi16(v[1], v[3]);
            hs[r] = _mm_add_epi16(_mm_add_epi16(_mm_add_epi16(v[0], v[4]), _mm_slli_epi16(v13, 2)),
                                  _mm_add_epi16(_mm_slli_epi16(v[2], 2), _mm_slli_epi16(v[2], 1)));
            hd[r] = _mm_add_epi16(_mm_sub_epi16(v[0], v[4]), _mm_slli_epi16(_mm_sub_epi16(v[1], v[3]), 1));
        } else {  // smooth 1 2 1, derivative 1 0 -1
            hs[r] = _mm_add_epi16(_mm_add_epi16(v[0], v[2]), _mm_slli_epi16(v[1], 1));
            hd[r] = _mm_sub_epi16(v[0], v[2]);
        }
    }
    const __m128i keep = _mm_cmplt_epi16(_mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7), _mm_set1_epi16(B));
    __m128i axx = zero, axy = zero, ayy = zero;  // 2 lanes of 64 bits each
    for (int q = 0; q < B; ++q) {
        __m128i ix, iy;
        const __m128i* d = hd + q;
        const __m128i* sm = hs + q;
        if constexpr (G == 5) {
            const __m128i d13 = _mm_add_epi16(d[1], d[3]);
            ix = _mm_add_epi16(_mm_add_epi16(_mm_add_epi16(d[0], d[4]), _mm_slli_epi16(d13, 2)),
                               _mm_add_epi16(_mm_slli_epi16(d[2], 2), _mm_slli_epi16(d[2], 1)));
            iy = _mm_add_epi16(_mm_sub_epi16(sm[0], sm[4]), _mm_slli_epi16(_mm_sub_epi16(sm[1], sm[3]), 1));
        } else {
            ix = _mm_add_epi16(_mm_add_epi16(d[0], d[2]), _mm_slli_epi16(d[1], 1));
            iy = _mm_sub_epi16(sm[0], sm[2]);
        }
        ix = _mm_and_si128(ix, keep);
        iy = _mm_and_si128(iy, keep);
        const __m128i pxx = _mm_madd_epi16(ix, ix), pyy = _mm_madd_epi16(iy, iy), pxy = _mm_madd_epi16(ix, iy);
        axx = _mm_add_epi64(axx, _mm_add_epi64(_mm_unpacklo_epi32(pxx, zero), _mm_unpackhi_epi32(pxx, zero)));
        ayy = _mm_add_epi64(ayy, _mm_add_epi64(_mm_unpacklo_epi32(pyy, zero), _mm_unpackhi_epi32(pyy, zero)));
        const __m128i sign = _mm_srai_epi32(pxy, 31);
        axy = _mm_add_epi64(axy, _mm_add_epi64(_mm_unpacklo_epi32(pxy, sign), _mm_unpackhi_epi32(pxy, sign)));
    }
    auto sum = [](__m128i v) {
        alignas(16) std::int64_t l[2];
        _mm_store_si128(reinterpret_cast<__m128i*>(l), v);
        return l[0] + l[1];
    };
    return luv_harris_response(sum(axx), sum(axy), sum(ayy), k_q, scale);
}
#endif

}  // namespace

double LuvHarris::table(int x, int y) const noexcept {
    const std::size_t w = static_cast<std::size_t>(size_.width);
    const std::size_t i = static_cast<std::size_t>(y) * w + static_cast<std::size_t>(x);
    if (!refreshed_) return table_[i];
    const std::size_t t = static_cast<std::size_t>(y >> kTileShift) * tiles_w_ + static_cast<std::size_t>(x >> kTileShift);
    if (std::max(stamp_[i], full_epoch_) >= stale_since_[t]) return table_[i];
    const std::uint8_t* s = snap_.data();
    const std::size_t xs = static_cast<std::size_t>(x), ys = static_cast<std::size_t>(y);
    const std::int32_t* wts = block_weights_.data();
    const int b = params_.block;
    double v;
#ifdef __SSE2__
    if (!params_.gaussian_block && b <= 7) {
        auto* const fn = params_.gradient == 5
                             ? (b == 1 ? pixel_value_box_sse2<5, 1> : b == 3 ? pixel_value_box_sse2<5, 3>
                                : b == 5 ? pixel_value_box_sse2<5, 5> : pixel_value_box_sse2<5, 7>)
                             : (b == 1 ? pixel_value_box_sse2<3, 1> : b == 3 ? pixel_value_box_sse2<3, 3>
                                : b == 5 ? pixel_value_box_sse2<3, 5> : pixel_value_box_sse2<3, 7>);
        v = fn(s, stride_, xs, ys, k_q_, scale_);
    } else
#endif
    if (params_.gradient == 5) {
        if (params_.gaussian_block)
            v = pixel_value<5, 0, false>(s, stride_, xs, ys, wts, b, k_q_, scale_);
        else
            v = pixel_value<5, 0, true>(s, stride_, xs, ys, wts, b, k_q_, scale_);
    } else {
        if (params_.gaussian_block)
            v = pixel_value<3, 0, false>(s, stride_, xs, ys, wts, b, k_q_, scale_);
        else
            v = pixel_value<3, 0, true>(s, stride_, xs, ys, wts, b, k_q_, scale_);
    }
    table_[i] = v;
    stamp_[i] = epoch_;
    ++computed_;
    return v;
}

void LuvHarris::refresh() noexcept {
    if (epoch_ == UINT32_MAX) {  // epochs start again: every value stale
        std::fill(stamp_.data(), stamp_.data() + stamp_.size(), 0u);
        std::fill(stale_since_.begin(), stale_since_.end(), 1u);
        full_epoch_ = 0;
        epoch_ = 0;
    }
    ++epoch_;
    // The copy takes the tiles events changed; the table values within the response's
    // reach (pad) of them become stale.
    const std::size_t w = static_cast<std::size_t>(size_.width), h = static_cast<std::size_t>(size_.height);
    const std::size_t tiles_h = (h + kTile - 1) >> kTileShift;
    const std::size_t reach = (static_cast<std::size_t>(pad_) + kTile - 1) >> kTileShift;
    bool border = false;
    const std::uint8_t* const from = tos_.data();
    std::uint8_t* const to = snap_.data();
    const std::size_t stride = stride_;
    std::uint8_t* const dirty = dirty_.data();
    std::uint32_t* const stale = stale_since_.data();
    const std::size_t tiles_w = tiles_w_;
    const std::uint32_t epoch = epoch_;
    for (std::size_t n = 0; n < dirty_count_; ++n) {
        const std::uint32_t t = dirty_list_[n];
        dirty[t] = 0;
        const std::size_t tx = t % tiles_w, ty = t / tiles_w;
        const std::size_t x0 = tx << kTileShift, x1 = std::min(x0 + kTile, w);
        const std::size_t y0 = ty << kTileShift, y1 = std::min(y0 + kTile, h);
        // 8 bytes a row even where the tile is cut by the sensor's right side. The bytes
        // beyond it are frame (zero in the TOS; in the copy zero too, or replicated and then
        // refilled below, the tile being on the border) or, where the frame is narrower, the
        // next row's first pixels, which take their current value: the copy's value at this
        // point anyway. The TOS has 16 bytes of slack after its last row.
        const std::size_t first = index(static_cast<int>(x0), static_cast<int>(y0));
        for (std::size_t at = first; at < first + (y1 - y0) * stride; at += stride) std::memcpy(to + at, from + at, kTile);
        border = border || x0 == 0 || y0 == 0 || x1 == w || y1 == h;
        const std::size_t sy0 = ty >= reach ? ty - reach : 0, sy1 = std::min(ty + reach, tiles_h - 1);
        const std::size_t sx0 = tx >= reach ? tx - reach : 0, sx1 = std::min(tx + reach, tiles_w - 1);
        for (std::size_t sy = sy0; sy <= sy1; ++sy)
            for (std::size_t sx = sx0; sx <= sx1; ++sx) stale[sy * tiles_w + sx] = epoch;
    }
    dirty_count_ = 0;
    if (params_.replicate_border && border) fill_border();
    if (events_since_refresh_ * kLazyFactor > w * h) {
        const Geometry g = geometry(size_, params_);
        const RefreshBuffers buf{hs_.data(), hd_.data(), xx_.data(), bxx_.data(),
                                 bxx_.data() + 3 * g.w * static_cast<std::size_t>(params_.block)};
        const bool box = !params_.gaussian_block;
        auto* const run = params_.gradient == 5 ? (box ? refresh_table<5, true> : refresh_table<5, false>)
                                                : (box ? refresh_table<3, true> : refresh_table<3, false>);
        run(g, snap_.data(), buf, block_weights_, k_q_, scale_, table_.data());
        full_epoch_ = epoch_;
        computed_ += w * h;
        ++full_refreshes_;
    }
    events_since_refresh_ = 0;
    refreshed_ = true;
    ++refreshes_;
}

bool LuvHarris::process_unchecked(const Event& e) noexcept {
    // 1. A refresh point due before this event: the time rule (t0 + n refresh_us, t0 the
    // first event's time; one refresh however many points passed since the last event)
    // and/or the count rule (before events refresh_events, 2 refresh_events, ...).
    bool due = false;
    if (!started_) {
        started_ = true;
        t0_ = e.t;
        next_t_ = params_.refresh_us > 0 ? e.t + params_.refresh_us : kMaxTime;
    } else if (params_.refresh_us > 0 && e.t >= next_t_) {
        due = true;
        next_t_ = e.t - (e.t - t0_) % params_.refresh_us + params_.refresh_us;
    }
    if (params_.refresh_events > 0) {
        if (until_count_refresh_ == 0) {  // starts at refresh_events: never before event 0
            due = true;
            until_count_refresh_ = params_.refresh_events;
        }
        --until_count_refresh_;
    }
    if (due) refresh();

    // 2. The surface.
    update_tos(e.x, e.y);
    mark_dirty(e.x, e.y);
    ++events_since_refresh_;

    // 3. The look-up and the threshold.
    if (!refreshed_) {
        score_ = kNoScore;
        return false;
    }
    const double v = table(e.x, e.y);
    score_ = v;
    if (!params_.adaptive) return v > params_.threshold;
    // Adaptive: compared with the statistics of the values looked up before (none: no
    // corner), then included: exponentially weighted mean and variance, weight alpha.
    const bool corner = stats_n_ > 0 && v > mean_ + params_.sigmas * std::sqrt(var_);
    if (stats_n_ == 0) {
        mean_ = v;
        var_ = 0.0;
    } else {
        const double diff = v - mean_;
        const double incr = params_.alpha * diff;
        mean_ = mean_ + incr;
        var_ = (1.0 - params_.alpha) * (var_ + diff * incr);
    }
    ++stats_n_;
    return corner;
}

}  // namespace evcorner
