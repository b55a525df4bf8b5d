#include "evcorner/sim/simulator.hpp"

#include "evcorner/state_memory.hpp"

#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <set>
#include <stdexcept>
#include <string>
#ifdef __SSE2__
#include <emmintrin.h>  // SSE2 (baseline x86-64): the compositing's selects without jumps
#endif

#include "evcorner/sim/coverage.hpp"
#include "evcorner/sim/coverage_walk.hpp"
#include "evcorner/sim/motion.hpp"
#include "evcorner/sim/texture.hpp"

namespace evcorner::sim {

namespace {
// Coverage within this of 0 or 1 is 0 or 1: the running sums of a pixel inside a polygon
// give 1 - 1e-16 now and then, and a steady pixel must not change.
constexpr double kSnap = 1e-12;
// Largest move of any vertex in one step, px (mark_edges needs less than 1).
constexpr double kMaxMove = 0.75;
constexpr std::uint64_t kSaltThresholds = 1, kSaltNoise = 2, kSaltHot = 3;
// A crossing's interpolated time is settled when halving its interval moves it by at most
// this times step_fraction, us.
constexpr double kCrossingTolPerFraction = 50.0;

// How far the crossing of `level` on the line from x0 to x1 (over len_us) moves when the
// value bends from that line by c u (u - 1) (u the crossing's place on it, 0 .. 1).
double bend_shift_us(double c, double x0, double x1, double level, double len_us) noexcept {
    const double u = (level - x0) / (x1 - x0);
    return std::abs(c * u * (u - 1.0) / (x1 - x0)) * len_us;
}

// The next step is shortened when the samples that keep the step fraction exceed this share of
// the pixels a render recomputes (a sample costs several times a rendered pixel).
constexpr double kSplitShare = 0.2;


// Horizontal edges are widened by this much (px) when marking the pixels they touch, so that
// rounding never leaves out a pixel one grazes (an extra pixel costs only time).
constexpr double kMarkMargin = 1e-7;

// Sets bits lo .. hi (inclusive) of a bitmap row.
inline void set_range(std::uint64_t* row, int lo, int hi) noexcept {
    const unsigned wl = static_cast<unsigned>(lo) >> 6, wh = static_cast<unsigned>(hi) >> 6;
    const std::uint64_t ml = ~std::uint64_t{0} << (static_cast<unsigned>(lo) & 63u);
    const std::uint64_t mh = ~std::uint64_t{0} >> (63u - (static_cast<unsigned>(hi) & 63u));
    if (wl == wh) {
        row[wl] |= ml & mh;
        return;
    }
    row[wl] |= ml;
    for (unsigned k = wl + 1; k < wh; ++k) row[k] = ~std::uint64_t{0};
    row[wh] |= mh;
}

// The number of set bits (without the popcnt instruction, which the baseline x86-64 lacks).
inline unsigned count_bits(std::uint64_t m) noexcept {
    m = m - ((m >> 1) & 0x5555555555555555ull);
    m = (m & 0x3333333333333333ull) + ((m >> 2) & 0x3333333333333333ull);
    m = (m + (m >> 4)) & 0x0F0F0F0F0F0F0F0Full;
    return static_cast<unsigned>((m * 0x0101010101010101ull) >> 56);
}

// Writes base + the index of each set bit of m, in order, at out, and returns the end of
// them. Eight at a time without a test per bit (a loop over the bits ends at an
// unpredictable count): up to 7 entries past the end are written (garbage within base ..
// base + 63), so out needs 7 spare entries.
inline std::uint32_t* list_bits(std::uint32_t* out, std::uint32_t base, std::uint64_t m) noexcept {
    std::uint32_t* const end = out + count_bits(m);
    constexpr std::uint64_t kTop = std::uint64_t{1} << 63;  // m | kTop: no zero argument once m runs out
    do {
        for (int i = 0; i < 8; ++i) {
            out[i] = base + static_cast<std::uint32_t>(std::countr_zero(m | kTop));
            m &= m - 1;
        }
        out += 8;
    } while (out < end);
    return end;
}

// A running sum of the compositing (coverage, or a checkerboard's intensity-weighted
// coverage) and the compositing of one pixel: out = b > kSnap ? out (1 - bc) + add : out,
// bc = b >= 1 - kSnap ? 1 : b, add = multi ? s : bc * level. With SSE2 the sums are kept in
// the low lane of a register (the high one is 0 and unused), so that the snap to 1 and the
// choice between the composited and the old value are masks (compare, and, or): GCC makes
// jumps of such selects on doubles, and whether a dirty pixel is covered, and wholly, is
// unpredictable. Every arithmetic operation is the scalar one of the same values, so the
// results are those of the plain code (the fallback without SSE2).
#ifdef __SSE2__
using Sum = __m128d;
inline Sum sum_zero() noexcept { return _mm_setzero_pd(); }
inline Sum sum_add(Sum a, const double* cell) noexcept { return _mm_add_sd(a, _mm_load_sd(cell)); }
inline void composite(double* out, Sum b, Sum s, bool multi, double level) noexcept {
    const __m128d one = _mm_set_sd(1.0);
    const __m128d whole = _mm_cmpge_sd(b, _mm_set_sd(1.0 - kSnap));
    const __m128d bc = _mm_or_pd(_mm_and_pd(whole, one), _mm_andnot_pd(whole, b));
    const __m128d old = _mm_load_sd(out);
    const __m128d v = _mm_add_sd(_mm_mul_sd(old, _mm_sub_sd(one, bc)), multi ? s : _mm_mul_sd(bc, _mm_set_sd(level)));
    const __m128d covered = _mm_cmpgt_sd(b, _mm_set_sd(kSnap));
    _mm_store_sd(out, _mm_or_pd(_mm_and_pd(covered, v), _mm_andnot_pd(covered, old)));
}
#else
struct Sum {
    double v;
};
inline Sum sum_zero() noexcept { return {0.0}; }
inline Sum sum_add(Sum a, const double* cell) noexcept { return {a.v + *cell}; }
inline void composite(double* out, Sum b, Sum s, bool multi, double level) noexcept {
    if (b.v <= kSnap) return;
    const double bc = b.v >= 1.0 - kSnap ? 1.0 : b.v;
    *out = *out * (1.0 - bc) + (multi ? s.v : bc * level);
}
#endif

// The bits of word k of a row that lie within columns lo .. hi.
inline std::uint64_t word_mask(std::size_t k, int lo, int hi) noexcept {
    const long base = static_cast<long>(k) * 64;
    if (hi < base || lo >= base + 64) return 0;
    const unsigned l = lo <= base ? 0u : static_cast<unsigned>(lo - base);
    const unsigned h = hi >= base + 63 ? 63u : static_cast<unsigned>(hi - base);
    return (~std::uint64_t{0} << l) & (~std::uint64_t{0} >> (63u - h));
}
}  // namespace

Simulator::Simulator(Scene scene)
    : scene_(std::move(scene)),
      w_(scene_.sensor.width),
      h_(scene_.sensor.height),
      stride_(static_cast<std::size_t>(w_) + 2),
      words_(static_cast<std::size_t>(w_) / 64 + 1),
      dt_(scene_.simulation.max_step_us),
      end_(static_cast<double>(scene_.duration_us())),
      noise_rng_(scene_.seed, kSaltNoise) {
    const std::size_t n = static_cast<std::size_t>(scene_.sensor.pixels());
    // Pixels, accumulator cells and bitmap bits are indexed with 32 bits.
    if (std::max(stride_, words_ * 64) * static_cast<std::size_t>(h_) > UINT32_MAX)
        throw std::length_error("simulate: a " + std::to_string(w_) + "x" + std::to_string(h_) +
                                " sensor is too large for the simulator (at most about 4.29e9 pixels)");
    // Per pixel: the background, two intensity planes (double) and the marks' bits.
    require_memory_fits("simulate: a " + std::to_string(w_) + "x" + std::to_string(h_) + " sensor",
                        static_cast<std::uint64_t>(stride_) * static_cast<std::uint64_t>(h_) * (3 * sizeof(double) + 1),
                        " (a smaller sensor in the scene)");
    bg_ = background_image(scene_.background, scene_.sensor, scene_.seed);
    cur_.assign(n, 0.0);
    next_.assign(n, 0.0);
    const std::size_t bitmap_words = words_ * static_cast<std::size_t>(h_);
    cur_marks_.assign(bitmap_words, 0);
    prev_marks_.assign(bitmap_words, 0);
    dirty_.assign(bitmap_words, 0);
    zero_row_.assign(words_, 0);
    dirty_list_.resize(n + 8);  // list_bits() writes up to 7 past the end
    polys_.resize(scene_.objects.size());
    for (std::size_t o = 0; o < scene_.objects.size(); ++o) polys_[o].resize(scene_.objects[o].pieces.size());
    rects_.resize(scene_.objects.size());

    // The image at t = 0, every row dirty.
    place_objects(0.0);
    prev_polys_ = polys_;
    moving_.resize(scene_.objects.size());
    for (std::size_t o = 0; o < scene_.objects.size(); ++o) {
        const Motion& m = scene_.objects[o].motion;
        moving_[o] = m.velocity.x != 0 || m.velocity.y != 0 || m.rotation_deg_s != 0 || m.scaling_per_s != 0;
    }
    // Every object's edge walk at t = 0 (a still object's is kept for the whole run), the
    // moving ones' edges marked as the pixels near them at time_us().
    acc_.resize(scene_.objects.size());
    prev_y0_ = h_;
    prev_y1_ = -1;
    for (std::size_t o = 0; o < scene_.objects.size(); ++o)
        walk_object(o, moving_[o] ? prev_marks_.data() : nullptr, prev_y0_, prev_y1_);
    render(true);
    cur_ = next_;

    const CameraParams& cam = scene_.camera;
    // Each pixel's thresholds and reference level are set when it first changes
    // (ready_pixel()): most pixels never do, and their logs, exponentials and normal draws
    // would be most of the set-up. The draws are the same as drawing every pixel's in order:
    // pixel i's are the 4 i-th to (4 i + 3)-th numbers of the thresholds' stream.
    lref_.resize(n);
    ion_.resize(n);
    ioff_.resize(n);
    con_.resize(n);
    coff_.resize(n);
    ready_.assign(n, 0);
    thresholds_rng_ = Random(scene_.seed, kSaltThresholds);
    last_.assign(n, INT64_MIN / 2);
    hist_.assign(n, 0.0);
    hist_step_.assign(n, 0);

    object_first_piece_.assign(1, 0);
    for (std::size_t o = 0; o < scene_.objects.size(); ++o) {
        object_first_piece_.push_back(object_first_piece_.back() + scene_.objects[o].pieces.size());
        piece_object_.resize(object_first_piece_.back(), static_cast<std::uint32_t>(o));
    }
    limit_ = scene_.simulation.step_fraction * cam.contrast;
    crossing_tol_us_ = kCrossingTolPerFraction * scene_.simulation.step_fraction;

    const double noise_rate = cam.noise_hz * static_cast<double>(n) + cam.hot_pixel_hz * cam.hot_pixels;
    noise_rate_per_us_ = noise_rate / 1e6;
    if (cam.hot_pixels > 0) {
        Random hot(scene_.seed, kSaltHot);
        std::set<std::uint32_t> chosen;
        while (chosen.size() < static_cast<std::size_t>(cam.hot_pixels))
            chosen.insert(static_cast<std::uint32_t>(hot.below(n)));
        hot_.assign(chosen.begin(), chosen.end());
    }
    next_noise_ = noise_rate_per_us_ > 0 ? noise_rng_.exponential(1.0 / noise_rate_per_us_) : end_ + 1.0;
}

// Pixel p's thresholds (drawn from the thresholds' stream at pixel p's place: two normals, each
// two numbers) and its reference level, set from its value at t = 0, which is cur_[p] until it
// first changes.
void Simulator::ready_pixel(std::size_t p) {
    ready_[p] = 1;
    const CameraParams& cam = scene_.camera;
    double a = cam.contrast, b = cam.contrast;
    if (cam.contrast_sigma > 0) {
        Random thr = thresholds_rng_;
        thr.skip(4 * static_cast<std::uint64_t>(p));
        // A threshold below 1 % of C would fire on rounding noise; the normal's far tail is cut there.
        const double floor_c = 0.01 * cam.contrast;
        a = std::max(floor_c, cam.contrast + cam.contrast_sigma * thr.normal());
        b = std::max(floor_c, cam.contrast + cam.contrast_sigma * thr.normal());
    }
    con_[p] = static_cast<float>(a);
    coff_[p] = static_cast<float>(b);
    lref_[p] = std::log(kLogEps + cur_[p]);
    ion_[p] = std::exp(lref_[p] + con_[p]) - kLogEps;
    ioff_[p] = std::exp(lref_[p] - coff_[p]) - kLogEps;
}

void Simulator::place_objects(double t_us) {
    const double t_s = t_us / 1e6;
    for (std::size_t o = 0; o < scene_.objects.size(); ++o) {
        const Object& obj = scene_.objects[o];
        const Pose pose(obj.motion, t_s, scene_.duration_s);
        double minx = INFINITY, maxx = -INFINITY, miny = INFINITY, maxy = -INFINITY;
        for (std::size_t k = 0; k < obj.pieces.size(); ++k) {
            const auto& src = obj.pieces[k].polygon;
            auto& dst = polys_[o][k];
            dst.resize(src.size());
            for (std::size_t v = 0; v < src.size(); ++v) {
                const Vec2 p = pose.apply(src[v]);
                dst[v] = p;
                minx = std::min(minx, p.x);
                maxx = std::max(maxx, p.x);
                miny = std::min(miny, p.y);
                maxy = std::max(maxy, p.y);
            }
        }
        Rect r;
        // Pixels with any part of the object: columns floor(minx) .. floor(maxx) (the last may
        // be touched at its left side only, harmless), and everything left of the sensor
        // counts for column 0.
        if (maxx >= 0 && minx < w_ && maxy >= 0 && miny < h_) {
            r.x0 = static_cast<int>(std::max(0.0, std::floor(minx)));
            r.x1 = static_cast<int>(std::min(w_ - 1.0, std::floor(maxx)));
            r.y0 = static_cast<int>(std::max(0.0, std::floor(miny)));
            r.y1 = static_cast<int>(std::min(h_ - 1.0, std::floor(maxy)));
        }
        rects_[o] = r;
    }
}


// Adds an object's edge walk into its window (ObjectAcc) and, when `marks` is set, marks
// every pixel an edge passes through in rows [y0, y1], which grow to hold the rows marked:
// the cell of every piece of a slanted edge (the computed coverage of a pixel without one is
// a sum of whole piece heights, 0 or 1 up to rounding that kSnap removes) and every cell a
// horizontal edge meets (widened by kMarkMargin). Edges move less than kMaxMove (< 1 px) per
// step (step()), so a pixel whose coverage differs between the two ends of a step is touched
// by an edge at one end: a pixel wholly outside an object at one end and wholly inside at the
// other would need its boundary to sweep over the whole pixel.
// A moving object (Moving) marks the pixels and keeps no written bits: every cell its walk
// writes is a marked pixel or the one right of it, or column 0 (the part of an edge left of
// the sensor), and render() reads those. A still object, walked once, keeps written bits.
template <bool Dual, bool Moving>
struct Simulator::AccSink {
    double* cov;  // the window's cell (0, 0), i.e. sensor (acc.y0, acc.x0)
    double* val;
    std::uint64_t* written;
    std::size_t cells;  // per window row
    std::size_t words;  // per window row
    int x0, y0;
    std::uint64_t* marks;
    int& my0;
    int& my1;
    std::size_t mwords;
    int w, h;

    // Row r's part: pointers to its first window cell, written bits and marks, so that the
    // walk's pieces in the row (contiguous columns) index from registers.
    struct Row {
        double* cov;
        double* val;
        std::uint64_t* written;
        std::uint64_t* marks;
        int x0;
        void add_pair(int k, double v0, double v1, double w0, double w1) noexcept {
            const std::size_t c = static_cast<std::size_t>(k - x0);
            cov[c] += v0;
            cov[c + 1] += v1;
            if constexpr (Dual) {
                val[c] += w0;
                val[c + 1] += w1;
            }
            if constexpr (Moving) {
                marks[static_cast<unsigned>(k) >> 6] |= std::uint64_t{1} << (static_cast<unsigned>(k) & 63u);
            } else {
                std::uint64_t* wr = written + (c >> 6);
                const unsigned bit = static_cast<unsigned>(c) & 63u;
                wr[0] |= std::uint64_t{3} << bit;  // cells c and c + 1 (the latter in the next word when bit is 63)
                if (bit == 63) wr[1] |= 1;
            }
        }
        // A single addition (at column 0, for the part of an edge left of the sensor, which
        // covers no pixel of its own).
        void add(int k, double v, double w2) noexcept {
            const std::size_t c = static_cast<std::size_t>(k - x0);
            cov[c] += v;
            if constexpr (Dual) val[c] += w2;
            if constexpr (!Moving) written[c >> 6] |= std::uint64_t{1} << (c & 63u);
        }
    };
    Row row(int r) const noexcept {
        const std::size_t wrow = static_cast<std::size_t>(r - y0);
        return {cov + wrow * cells, Dual ? val + wrow * cells : nullptr, Moving ? nullptr : written + wrow * words,
                Moving ? marks + static_cast<std::size_t>(r) * mwords : nullptr, x0};
    }
    void rows(int r0, int r1) noexcept {
        if (r0 < my0) my0 = r0;
        if (r1 > my1) my1 = r1;
    }
    void flat(double y, double xl, double xr) noexcept {
        if (!Moving || y + kMarkMargin < 0 || y - kMarkMargin >= h) return;
        const double lo_x = xl - kMarkMargin, hi_x = xr + kMarkMargin;
        if (hi_x < 0 || lo_x >= w) return;
        const int lo = lo_x <= 0 ? 0 : static_cast<int>(lo_x);  // truncation is floor for x >= 0
        const int hi = hi_x >= w - 1 ? w - 1 : static_cast<int>(hi_x);
        const int r0 = std::max(0, static_cast<int>(std::floor(y - kMarkMargin)));
        const int r1 = std::min(h - 1, static_cast<int>(std::floor(y + kMarkMargin)));
        for (int r = r0; r <= r1; ++r) set_range(marks + static_cast<std::size_t>(r) * mwords, lo, hi);
        if (r0 <= r1) rows(r0, r1);
    }
};

void Simulator::walk_object(std::size_t o, std::uint64_t* marks, int& y0, int& y1) {
    const Object& obj = scene_.objects[o];
    ObjectAcc& acc = acc_[o];
    const Rect& r = rects_[o];
    if (r.empty()) {  // off the sensor: no pixel to cover, nothing to mark
        acc.y1 = acc.y0 - 1;
        return;
    }
    // The walk writes rows r.y0 .. r.y1 (those of the vertices) and columns from r.x0 - 1
    // (rounding can put a vertex on a column line a hair to its left) to r.x1 + 2 (a cell and
    // its right neighbour, the cell again one further by rounding), within 0 .. w_.
    acc.x0 = std::max(0, r.x0 - 1) & ~63;
    acc.y0 = r.y0;
    acc.y1 = r.y1;
    acc.words = static_cast<std::size_t>(std::min(w_, r.x1 + 2) - acc.x0) / 64 + 1;
    const std::size_t rows = static_cast<std::size_t>(r.y1 - r.y0 + 1);
    const bool dual = obj.pieces.size() > 1;
    // Growing keeps the cells zero (every cell is zero between renders).
    if (marks == nullptr && acc.written.size() < rows * acc.words) acc.written.resize(rows * acc.words);
    if (acc.cov.size() < rows * acc.words * 64) acc.cov.resize(rows * acc.words * 64);
    if (dual && acc.val.size() < rows * acc.words * 64) acc.val.resize(rows * acc.words * 64);
    auto walk = [&]<bool Dual, bool Moving>() {
        AccSink<Dual, Moving> sink{acc.cov.data(), Dual ? acc.val.data() : nullptr, Moving ? nullptr : acc.written.data(),
                                   acc.words * 64, acc.words, acc.x0, acc.y0, marks, y0, y1, words_, w_, h_};
        if constexpr (Dual) {
            for (std::size_t k = 0; k < obj.pieces.size(); ++k)
                walk_coverage<true>(polys_[o][k], 1.0, obj.pieces[k].intensity, w_, h_, sink);
        } else {
            walk_coverage<false>(polys_[o][0], 1.0, 0.0, w_, h_, sink);
        }
    };
    if (dual) {
        if (marks != nullptr) walk.template operator()<true, true>();
        else walk.template operator()<true, false>();
    } else {
        if (marks != nullptr) walk.template operator()<false, true>();
        else walk.template operator()<false, false>();
    }
}

void Simulator::render(bool all_rows) {
    if (all_rows) {
        for (int y = 0; y < h_; ++y) set_range(row_bits(dirty_, y), 0, w_ - 1);
        dirty_y0_ = 0;
        dirty_y1_ = h_ - 1;
    } else {
        // The pixels the moving edges pass through now (cur_marks_, marked by their edge
        // walks) and at time_us() (prev_marks_, kept from the step that reached it). cur_marks_
        // is all zero here: the union below clears prev_marks_ as it reads it, and the two
        // swap after the step.
        cur_y0_ = h_;
        cur_y1_ = -1;
        for (std::size_t o = 0; o < rects_.size(); ++o)
            if (moving_[o]) walk_object(o, cur_marks_.data(), cur_y0_, cur_y1_);
        dirty_y0_ = std::min(cur_y0_, prev_y0_);
        dirty_y1_ = std::max(cur_y1_, prev_y1_);
    }
    // The dirty pixels start from the background, and are listed in row-major order
    // (emit_crossings() reads the list).
    const std::size_t w = static_cast<std::size_t>(w_);
    std::uint32_t* listed = dirty_list_.data();
    for (int y = dirty_y0_; y <= dirty_y1_; ++y) {
        std::uint64_t* d = row_bits(dirty_, y);
        // (Every row: the dirty bits kept, with zero_row_ for the marks to clear; it stays zero.)
        const std::uint64_t* c = row_bits(all_rows ? dirty_ : cur_marks_, y);
        std::uint64_t* p = all_rows ? zero_row_.data() : row_bits(prev_marks_, y);
        const std::size_t base = static_cast<std::size_t>(y) * w;
        for (std::size_t k = 0; k < words_; ++k) {
            const std::uint64_t dk = c[k] | p[k];
            d[k] = dk;
            p[k] = 0;  // read for the last time (cleared here rather than in a pass of its own)
            if (dk != 0) listed = list_bits(listed, static_cast<std::uint32_t>(base + k * 64), dk);
        }
    }
    dirty_n_ = static_cast<std::size_t>(listed - dirty_list_.data());
    for (std::size_t j = 0; j < dirty_n_; ++j) next_[dirty_list_[j]] = bg_[dirty_list_[j]];
    // Each object over what lies behind it: I = I (1 - b) + sum_k b_k I_k, b = sum_k b_k, its
    // pieces' coverages (they never overlap, so b is the object's own coverage), evaluated only
    // at the dirty pixels.
    for (std::size_t o = 0; o < rects_.size(); ++o) {
        const Rect& r = rects_[o];
        if (r.empty()) continue;
        const bool moving = moving_[o] != 0;
        if (!moving) {  // a still object's window is kept: only pixels marked dirty need it
            bool touches = false;
            const int ty0 = std::max(r.y0, dirty_y0_), ty1 = std::min(r.y1, dirty_y1_);
            for (int y = ty0; y <= ty1 && !touches; ++y) {
                const std::uint64_t* d = row_bits(dirty_, y);
                for (std::size_t k = static_cast<std::size_t>(r.x0) / 64; k <= static_cast<std::size_t>(r.x1) / 64; ++k)
                    touches = touches || (d[k] & word_mask(k, r.x0, r.x1)) != 0;
            }
            if (!touches) continue;
        }
        const Object& obj = scene_.objects[o];
        const bool multi = obj.pieces.size() > 1;
        const double level = obj.pieces[0].intensity;
        ObjectAcc& acc = acc_[o];
        const std::size_t cells = acc.words * 64;
        const std::size_t kw = static_cast<std::size_t>(acc.x0) / 64;  // the window's first sensor word
        // The object's columns r.x0 .. r.x1 in each word of the window (the same in every row).
        inside_.resize(std::max(inside_.size(), acc.words));
        for (std::size_t j = 0; j < acc.words; ++j) inside_[j] = word_mask(kw + j, r.x0, r.x1);
        if (!moving) {
            for (int y = r.y0; y <= r.y1; ++y) {
                const std::size_t row = static_cast<std::size_t>(y - acc.y0);
                const double* ac = acc.cov.data() + row * cells;
                const double* ai = multi ? acc.val.data() + row * cells : nullptr;
                double* out = &next_[static_cast<std::size_t>(y) * w + static_cast<std::size_t>(acc.x0)];  // at column acc.x0
                const bool in_dirty = y >= dirty_y0_ && y <= dirty_y1_;
                const std::uint64_t* d = in_dirty ? row_bits(dirty_, y) + kw : zero_row_.data();
                // The running sums over the window's cells, in column order: adding 0 leaves a
                // sum as it is, so only the cells the walk wrote (its written bits) are added;
                // composited where the row is dirty.
                double b = 0, s = 0;
                const std::uint64_t* wr = acc.written.data() + row * acc.words;
                for (std::size_t j = 0; j < acc.words; ++j) {
                    const std::uint64_t inside = inside_[j];
                    const std::uint64_t dm = d[j] & inside;
                    for (std::uint64_t m = (wr[j] & inside) | dm; m != 0; m &= m - 1) {
                        const std::size_t c = j * 64 + static_cast<std::size_t>(std::countr_zero(m));
                        b += ac[c];
                        if (multi) s += ai[c];
                        if ((dm & (m & -m)) == 0 || b <= kSnap) continue;
                        const double bc = b >= 1.0 - kSnap ? 1.0 : b;
                        out[c] = out[c] * (1.0 - bc) + (multi ? s : bc * level);
                    }
                }
            }
            continue;
        }
        // A moving object: the cells its walk wrote are its marked pixels (all dirty), the
        // cell right of each, and column 0 (then r.x0 is 0), all within r.x0 - 2 .. r.x1 + 3.
        // So the running sum at a dirty pixel c of the object's columns is that of the cells
        // before it plus ac[c]: the sum is carried from dirty pixel to dirty pixel, adding at
        // each its own cell and, after compositing it, the cell right of it, each read and
        // cleared (a cell added twice holds 0 the second time; adding 0 leaves a sum as it
        // is, so the nonzero cells are added in column order, as a dense running sum would).
        // The first column's cell starts the sum (the cell right of a dirty r.x0 - 1, or
        // column 0). The cells just outside the object's columns that the walk may write by
        // rounding (r.x0 - 2, r.x0 - 1; r.x1 + 1 .. r.x1 + 3) are cleared, not added (the one
        // right of r.x1 is added after the last compositing: harmless).
        std::size_t near_cells[5];
        std::size_t near_n = 0;
        for (const int col : {r.x0 - 2, r.x0 - 1, r.x1 + 1, r.x1 + 2, r.x1 + 3})
            if (col >= acc.x0 && col < acc.x0 + static_cast<int>(cells))
                near_cells[near_n++] = static_cast<std::size_t>(col - acc.x0);
        const std::size_t first = static_cast<std::size_t>(r.x0 - acc.x0);
        const int ry0 = std::max(r.y0, dirty_y0_), ry1 = std::min(r.y1, dirty_y1_);  // walked rows are dirty rows
        for (int y = ry0; y <= ry1; ++y) {
            const std::size_t row = static_cast<std::size_t>(y - acc.y0);
            double* ac = acc.cov.data() + row * cells;
            double* ai = multi ? acc.val.data() + row * cells : nullptr;
            double* out = &next_[static_cast<std::size_t>(y) * w + static_cast<std::size_t>(acc.x0)];  // at column acc.x0
            const std::uint64_t* d = row_bits(dirty_, y) + kw;
            for (std::size_t i = 0; i < near_n; ++i) {
                ac[near_cells[i]] = 0;
                if (multi) ai[near_cells[i]] = 0;
            }
            Sum b = sum_add(sum_zero(), ac + first), s = sum_zero();
            ac[first] = 0;
            if (multi) {
                s = sum_add(s, ai + first);
                ai[first] = 0;
            }
            for (std::size_t j = 0; j < acc.words; ++j)
                for (std::uint64_t m = d[j] & inside_[j]; m != 0; m &= m - 1) {
                    const std::size_t c = j * 64 + static_cast<std::size_t>(std::countr_zero(m));
                    b = sum_add(b, ac + c);
                    ac[c] = 0;
                    if (multi) {
                        s = sum_add(s, ai + c);
                        ai[c] = 0;
                    }
                    composite(out + c, b, s, multi, level);  // where covered (b > kSnap)
                    b = sum_add(b, ac + c + 1);
                    ac[c + 1] = 0;
                    if (multi) {
                        s = sum_add(s, ai + c + 1);
                        ai[c + 1] = 0;
                    }
                }
        }
    }
}

double Simulator::max_displacement() const noexcept {
    double worst = 0;
    for (std::size_t o = 0; o < polys_.size(); ++o) {
        if (!moving_[o]) continue;
        for (std::size_t k = 0; k < polys_[o].size(); ++k)
            for (std::size_t v = 0; v < polys_[o][k].size(); ++v) {
                const Vec2 a = polys_[o][k][v], b = prev_polys_[o][k][v];
                worst = std::max(worst, std::max(std::abs(a.x - b.x), std::abs(a.y - b.y)));
            }
    }
    return worst;
}

Simulator::Placement& Simulator::placement(std::size_t o, std::uint64_t key) {
    const std::uint64_t tag = key | (static_cast<std::uint64_t>(o) << (kKeyBits + 2));
    // The instants of the first kDirectBits halvings (most samples: the step's midpoint above
    // all) are found in a table of their own, indexed by object and key; the others hashed.
    const bool direct = (key & (kKeyEnd / kDirect - 1)) == 0 && key < kKeyEnd;
    const std::size_t d = o * kDirect + static_cast<std::size_t>(key / (kKeyEnd / kDirect));
    if (direct) {
        if (direct_[d] != 0) return places_[direct_[d] - 1];
        direct_used_.push_back(static_cast<std::uint32_t>(d));
        direct_[d] = static_cast<std::uint32_t>(places_n_ + 1);
        return new_placement(o, key, tag);
    }
    auto slot_of = [this](std::uint64_t t) {
        // The top bits of a Fibonacci hash of the tag folded once: the keys are dyadic (their
        // low bits mostly zero) and the object sits above them, so the product's middle bits,
        // taken before, put most tags of an instant in one or two slots (long probes).
        const std::size_t mask = slot_tag_.size() - 1;
        const int shift = 64 - std::countr_zero(slot_tag_.size());
        std::size_t i = static_cast<std::size_t>(((t ^ (t >> 29)) * 0x9E3779B97F4A7C15ull) >> shift);
        while (slot_tag_[i] != 0 && slot_tag_[i] != t + 1) i = (i + 1) & mask;
        return i;
    };
    std::size_t i = slot_of(tag);
    if (slot_tag_[i] != 0) return places_[slot_place_[i]];
    if (2 * (places_n_ + 1) > slot_tag_.size()) {  // keep the table at most half full
        slot_tag_.assign(2 * slot_tag_.size(), 0);
        slot_place_.resize(slot_tag_.size());
        slots_used_.clear();
        for (std::size_t j = 0; j < places_n_; ++j) {
            const std::size_t s = slot_of(places_[j].tag);
            slot_tag_[s] = places_[j].tag + 1;
            slot_place_[s] = static_cast<std::uint32_t>(j);
            slots_used_.push_back(static_cast<std::uint32_t>(s));
        }
        i = slot_of(tag);
    }
    slot_tag_[i] = tag + 1;
    slot_place_[i] = static_cast<std::uint32_t>(places_n_);
    slots_used_.push_back(static_cast<std::uint32_t>(i));
    return new_placement(o, key, tag);
}

Simulator::Placement& Simulator::new_placement(std::size_t o, std::uint64_t key, std::uint64_t tag) {
    if (places_.size() <= places_n_) places_.resize(places_n_ + 1);
    Placement& pl = places_[places_n_++];
    pl.tag = tag;
    pl.pose = Pose(scene_.objects[o].motion, key_time(key) / 1e6, scene_.duration_s);
    pl.piece_at.assign(scene_.objects[o].pieces.size(), kNotPlaced);
    return pl;
}

// On the step's first sample: the pixels each piece can cover within the step: its
// vertices at both ends, widened by 2 px (a vertex moves less than kMaxMove between them,
// along a path close to the straight one); an empty rectangle off the sensor.
void Simulator::make_rects() {
    rects_ready_ = true;
    piece_rect_.resize(object_first_piece_.back());
    auto to_pixels = [&](double x0, double x1, double y0, double y1) {
        PixelRect r{0, -1, 0, -1};
        x0 -= 2.0, x1 += 2.0, y0 -= 2.0, y1 += 2.0;
        if (x1 >= 0 && y1 >= 0 && x0 < w_ && y0 < h_)  // the clamps keep the casts in range
            r = {static_cast<int>(std::floor(std::max(0.0, x0))), static_cast<int>(std::min(w_ - 1.0, x1)),
                 static_cast<int>(std::floor(std::max(0.0, y0))), static_cast<int>(std::min(h_ - 1.0, y1))};
        return r;
    };
    for (std::size_t o = 0; o < scene_.objects.size(); ++o)
        for (std::size_t k = 0; k < polys_[o].size(); ++k) {
            Box b{INFINITY, -INFINITY, INFINITY, -INFINITY};
            for (const auto* polys : {&prev_polys_[o][k], &polys_[o][k]})
                for (const Vec2& q : *polys)
                    b = {std::min(b.x0, q.x), std::max(b.x1, q.x), std::min(b.y0, q.y), std::max(b.y1, q.y)};
            piece_rect_[object_first_piece_[o] + k] = to_pixels(b.x0, b.x1, b.y0, b.y1);
        }
}

void Simulator::near_pieces(std::size_t p, int x, int y) {
    if (!rects_ready_) make_rects();
    near_pixel_ = p;
    // Every piece, without a jump per piece (which pieces hold a pixel is unpredictable): the
    // index is written and kept when the pixel is inside (all four differences >= 0).
    near_.resize(piece_rect_.size());
    std::size_t n = 0;
    for (std::size_t g = 0; g < piece_rect_.size(); ++g) {
        const PixelRect& r = piece_rect_[g];
        near_[n] = static_cast<std::uint32_t>(g);
        n += static_cast<std::size_t>(((x - r.x0) | (r.x1 - x) | (y - r.y0) | (r.y1 - y)) >= 0);
    }
    near_n_ = n;
}

// The same compositing as render(), for one pixel, with each piece's coverage from its edges
// (only the pieces that can reach the pixel within the step are placed: near_, an object
// without any adds nothing).
double Simulator::sample(std::size_t p, std::uint64_t key) {
    ++stats_.pixel_samples;
    const std::size_t w = static_cast<std::size_t>(w_);
    const int x = static_cast<int>(p % w), y = static_cast<int>(p / w);
    if (near_pixel_ != p) near_pieces(p, x, y);
    double v = bg_[p];
    const std::size_t n = near_n_;
    for (std::size_t i = 0; i < n;) {
        const std::size_t o = piece_object_[near_[i]];
        const Object& obj = scene_.objects[o];
        const bool multi = obj.pieces.size() > 1;
        Placement& pl = placement(o, key);
        double b = 0, s = 0;
        for (; i < n && piece_object_[near_[i]] == o; ++i) {
            const std::size_t k = near_[i] - object_first_piece_[o];
            const std::vector<Vec2>& src = obj.pieces[k].polygon;
            if (pl.piece_at[k] == kNotPlaced) {
                pl.piece_at[k] = static_cast<std::uint32_t>(placed_.size());
                for (const Vec2& q : src) placed_.push_back(pl.pose.apply(q));
            }
            const double c = pixel_coverage(std::span<const Vec2>(placed_.data() + pl.piece_at[k], src.size()), x, y);
            b += c;
            if (multi) s += c * obj.pieces[k].intensity;
        }
        if (b <= kSnap) continue;
        const double bc = b >= 1.0 - kSnap ? 1.0 : b;
        v = v * (1.0 - bc) + (multi ? s : bc * obj.pieces[0].intensity);
    }
    if (record_ != nullptr) record_->push_back({p, key_time(key), v});
    return v;
}

void Simulator::refine(std::size_t p, std::uint64_t ka, std::uint64_t kb, double a, double b, bool settled,
                       std::vector<Event>& ev) {
    const double ta = key_time(ka), tb = key_time(kb);
    const double q = std::abs(a - b) / (kLogEps + std::min(a, b));
    const bool splittable = tb - ta > scene_.simulation.min_step_us && kb - ka >= 2;
    const bool crosses = reaches_level(p, a, b);
    if (splittable && q > limit_) {
        // Halved: each part checked again.
        ++split_samples_;
        const std::uint64_t km = ka + (kb - ka) / 2;
        const double m = sample(p, km);
        // A half that crosses is settled when the parabola through a, m, b (at 0, 1, 2 half
        // lengths) moves its crossing by at most the tolerance (as emit_crossings() does with
        // a pixel's history): c u (u - 1) is the parabola's departure from the half's line
        // (the same c for both halves).
        const double c = 0.5 * ((b - m) - (m - a));
        const double half_us = 0.5 * (tb - ta);
        // (Both halves judged against the levels as they stand before the first half's
        // crossings move them.)
        const double on = ion_[p], off = ioff_[p];
        auto settled_by = [&](double x0, double x1) {
            if (!reaches(x0, x1, on, off)) return false;  // no crossing: no matter
            return bend_shift_us(c, x0, x1, x1 > x0 ? on : off, half_us) <= crossing_tol_us_;
        };
        refine(p, ka, km, a, m, settled_by(a, m), ev);
        refine(p, km, kb, m, b, settled_by(m, b), ev);
        return;
    }
    if (crosses && !settled && splittable) {
        // I is taken as linear in the interval; the midpoint tells how far the crossing's time
        // moves when the interval is halved. Settled within the tolerance, the halves are kept.
        const std::uint64_t km = ka + (kb - ka) / 2;
        const double m = sample(p, km), tm = key_time(km);
        const double level = b > a ? ion_[p] : ioff_[p];
        const double whole = ta + (level - a) / (b - a) * (tb - ta);
        const bool first_half = b > a ? m >= level : m <= level;
        const double halved = first_half ? ta + (level - a) / (m - a) * (tm - ta) : tm + (level - m) / (b - m) * (tb - tm);
        const bool ok = std::abs(whole - halved) <= crossing_tol_us_;
        refine(p, ka, km, a, m, ok, ev);
        refine(p, km, kb, m, b, ok, ev);
        return;
    }
    stats_.max_step_change = std::max(stats_.max_step_change, q / scene_.camera.contrast);
    if (crosses) cross(p, ta, tb, a, b, ev);
}

void Simulator::cross(std::size_t p, double ta, double tb, double a, double b, std::vector<Event>& ev) {
    const double dt = tb - ta;
    const double refractory = scene_.camera.refractory_us;
    const std::size_t w = static_cast<std::size_t>(w_);
    auto emit = [&](double tc, std::uint8_t pol) {
        const std::int64_t ts = std::max<std::int64_t>(1, std::llround(tc));
        if (refractory > 0 && static_cast<double>(ts - last_[p]) < refractory) {
            ++stats_.refractory;
            return;
        }
        last_[p] = ts;
        ev.push_back({ts, static_cast<std::uint16_t>(p % w), static_cast<std::uint16_t>(p / w), pol});
    };
    if (b > a) {
        do {
            emit(ta + (ion_[p] - a) / (b - a) * dt, 1);
            lref_[p] += con_[p];
            ion_[p] = std::exp(lref_[p] + con_[p]) - kLogEps;
        } while (b >= ion_[p]);
        ioff_[p] = std::exp(lref_[p] - coff_[p]) - kLogEps;  // only the last reference's is needed
    } else {
        do {
            emit(ta + (ioff_[p] - a) / (b - a) * dt, 0);
            lref_[p] -= coff_[p];
            ioff_[p] = std::exp(lref_[p] - coff_[p]) - kLogEps;
        } while (b <= ioff_[p]);
        ion_[p] = std::exp(lref_[p] + con_[p]) - kLogEps;
    }
}

// Each changed pixel from its value at t0 to its value at t1, sampled on its own within the
// step where its |dL| bound exceeds the step fraction or a crossing's time needs it (refine()).
void Simulator::emit_crossings(double t0, double t1, std::vector<Event>& ev) {
    step_t0_ = t0;
    step_len_ = t1 - t0;
    places_n_ = 0;
    placed_.clear();
    split_samples_ = 0;
    if (slot_tag_.empty()) {
        slot_tag_.assign(256, 0);
        slot_place_.resize(256);
    }
    for (const std::uint32_t i : slots_used_) slot_tag_[i] = 0;
    slots_used_.clear();
    if (direct_.empty()) direct_.assign(scene_.objects.size() * kDirect, 0);
    for (const std::uint32_t d : direct_used_) direct_[d] = 0;
    direct_used_.clear();
    near_pixel_ = SIZE_MAX;  // the pieces move: their rectangles are made again (make_rects)
    rects_ready_ = false;
    double worst = 0;
    const std::uint32_t step_index = static_cast<std::uint32_t>(stats_.steps);
    // The dirty pixels (render()'s list, row-major order); those whose value changed go on.
    std::size_t changed = 0;
    auto pixel = [&](std::size_t p) {
        const double a = cur_[p], b = next_[p];
        if (a == b) return;
        ++changed;
        if (ready_[p] == 0) ready_pixel(p);
        cur_[p] = b;
        const double d = std::abs(a - b), den = kLogEps + std::min(a, b);
        const bool had_history = hist_step_[p] == step_index;
        const double h = hist_[p];
        hist_[p] = a;
        hist_step_[p] = step_index + 1;
        if (d > limit_ * den) {
            refine(p, 0, kKeyEnd, a, b, false, ev);
            return;
        }
        worst = std::max(worst, d / den);
        // Most pixels do not cross: nothing to do but note the change. A ready pixel's value
        // lies strictly between its thresholds (ioff_ < cur_ < ion_: so they are set, and
        // cross() leaves them so, each a whole threshold of at least 0.01 C beyond the value
        // that reached the last level), so a rise cannot reach ioff_ nor a fall ion_: the
        // pixel crosses exactly when its new value is outside the two, whichever way it
        // moved. Tested without a branch on the direction, which is unpredictable (and with
        // '&', not '&&', so that the two comparisons make one jump).
        if ((static_cast<int>(b < ion_[p]) & static_cast<int>(b > ioff_[p])) != 0) return;
        // A crossing. Where the pixel also changed in the step before, the parabola through
        // its three values tells how far the crossing's time would move if I bends like it;
        // within the tolerance the straight line is kept without a sample. A pixel that
        // starts to change in this step (an edge enters it: a kink) is always sampled.
        if (had_history) {
            const double level = b > a ? ion_[p] : ioff_[p];
            const double r = last_len_ / step_len_;  // the step before, in units of this one
            // Newton form through (-r, h), (0, a), (1, b): the parabola's departure from the
            // line through (0, a) and (1, b) at the crossing's place u is c u (u - 1).
            const double c = ((b - a) - (a - h) / r) / (1.0 + r);
            if (bend_shift_us(c, a, b, level, step_len_) <= crossing_tol_us_) {
                cross(p, t0, t1, a, b, ev);
                return;
            }
        }
        refine(p, 0, kKeyEnd, a, b, false, ev);
    };
    for (std::size_t i = 0; i < dirty_n_; ++i) pixel(dirty_list_[i]);
    changed_n_ = changed;
    stats_.max_step_change = std::max(stats_.max_step_change, worst / scene_.camera.contrast);
}

void Simulator::emit_noise(double t1, std::vector<Event>& ev) {
    const double bg_rate = scene_.camera.noise_hz * static_cast<double>(scene_.sensor.pixels());
    const double total = bg_rate + scene_.camera.hot_pixel_hz * scene_.camera.hot_pixels;
    const std::uint64_t n = static_cast<std::uint64_t>(scene_.sensor.pixels());
    while (next_noise_ <= t1) {
        std::uint32_t p;
        std::uint8_t pol;
        if (noise_rng_.uniform() * total < bg_rate) {
            p = static_cast<std::uint32_t>(noise_rng_.below(n));
            pol = static_cast<std::uint8_t>(noise_rng_.next() >> 63);
        } else {
            p = hot_[noise_rng_.below(hot_.size())];
            pol = 1;
        }
        const std::int64_t ts = std::max<std::int64_t>(1, std::llround(next_noise_));
        ev.push_back({ts, static_cast<std::uint16_t>(p % static_cast<std::uint32_t>(w_)),
                      static_cast<std::uint16_t>(p / static_cast<std::uint32_t>(w_)), pol});
        ++stats_.noise;
        next_noise_ += noise_rng_.exponential(1.0 / noise_rate_per_us_);
    }
}

bool Simulator::step(std::vector<Event>& out) {
    if (t_ >= end_) return false;
    const SimulationParams& sp = scene_.simulation;
    double dt = dt_;
    for (;;) {
        const double t1 = std::min(end_, t_ + dt);
        place_objects(t1);
        const double taken = t1 - t_;
        // Edges move less than a pixel per step, so that the pixels near them are all that
        // can change (mark_edges). The step fraction is kept per pixel (emit_crossings).
        const double moved = max_displacement();
        if (moved > kMaxMove && taken > sp.min_step_us) {
            ++stats_.rejected_steps;
            dt = std::max(sp.min_step_us, taken * 0.9 * kMaxMove / moved);
            continue;
        }
        render(false);
        step_events_.clear();
        emit_crossings(t_, t1, step_events_);
        emit_noise(t1, step_events_);
        std::sort(step_events_.begin(), step_events_.end(), [](const Event& a, const Event& b) {
            if (a.t != b.t) return a.t < b.t;
            if (a.y != b.y) return a.y < b.y;
            if (a.x != b.x) return a.x < b.x;
            return a.p < b.p;
        });
        for (const Event& e : step_events_) ++(e.p ? stats_.on : stats_.off);
        out.insert(out.end(), step_events_.begin(), step_events_.end());
        prev_polys_.swap(polys_);  // place_objects() overwrites every vertex of polys_
        prev_marks_.swap(cur_marks_);
        std::swap(prev_y0_, cur_y0_);
        std::swap(prev_y1_, cur_y1_);
        ++stats_.steps;
        last_len_ = taken;
        // The next step: at most max_step_us, edges moving at most 0.9 kMaxMove, and short
        // enough that the samples keeping the step fraction stay a small share of the pixels
        // rendered (a sample costs several times a rendered pixel; kSplitShare).
        double grow = 2.0;
        if (moved > 0) grow = std::min(grow, 0.9 * kMaxMove / moved);
        const double share = static_cast<double>(split_samples_) / static_cast<double>(std::max<std::size_t>(changed_n_, 1));
        if (share > kSplitShare) grow = std::min(grow, std::max(0.5, kSplitShare / share));
        dt_ = std::min(sp.max_step_us, taken * grow);
        dt_ = std::max(dt_, sp.min_step_us);
        t_ = t1;
        return true;
    }
}

std::vector<Event> simulate(const Scene& scene) {
    Simulator sim(scene);
    std::vector<Event> out;
    while (sim.step(out)) {
    }
    return out;
}

}  // namespace evcorner::sim
