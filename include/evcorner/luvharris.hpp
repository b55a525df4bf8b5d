#pragma once
// luvHarris: the look-up-table Harris of
//   A. Glover, A. Dinale, L. D. S. Rosa, S. Bamford, C. Bartolozzi, "luvHarris: A
//   Practical Corner Detector for Event-Cameras", IEEE TPAMI 2021,
// written from the paper's idea and ../docs/luvharris.md (every choice and its reason),
// not from its authors' code.
//
// Polarity is ignored. Per event (x, y):
//  1. if a refresh point is due (every refresh_us of event time after the first event,
//     and/or every refresh_events events), the Harris table is recomputed from the
//     surface as it stands (all events before this one);
//  2. the Threshold-Ordinal Surface (TOS, one byte per pixel, 0 at start) is updated: over
//     the tos_size x tos_size neighbourhood clipped to the sensor, each value v becomes 0
//     if v < 255 - tos_size * tos_threshold, else v - 1; then (x, y) becomes 255;
//  3. the table is read at (x, y): that value is last_score(); the event is a corner iff
//     it exceeds the threshold (adaptive: running mean + sigmas x standard deviation of
//     the values looked up before; or fixed).
// The table is the Harris response det(M) - k tr(M)^2 of the whole TOS, M the structure
// tensor of integer derivative kernels summed over a block, computed in integers (exact,
// k rounded to a multiple of 2^-16) and scaled to TOS levels per pixel. Same input, same
// output on any machine: no clock, no thread, no floating-point contraction.
// Cost: a refresh point keeps a copy of the TOS tiles (8x8) that events changed since the
// previous one and marks the table values that depend on them as stale; a stale value is
// computed from that copy when it is read (the same value the whole table would hold). A
// refresh after many events (more than pixels / 3) computes the whole table at once.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/zeroed_array.hpp"

namespace evcorner {

struct LuvHarrisParams {
    int tos_size = 7;               ///< TOS neighbourhood side k, odd, 3..31
    int tos_threshold = 2;          ///< TOS T: values below 255 - k*T drop to 0; 0..254/k
    int gradient = 5;               ///< derivative kernel side: 5 (the paper's Harris 5x5) or 3 (Sobel)
    int block = 5;                  ///< structure-tensor block side, odd: 1..15 (box), 3..9 (gaussian)
    bool gaussian_block = false;    ///< binomial (Gaussian-like) block weights instead of a box
    double k = 0.04;                ///< Harris k, 0..0.25 (rounded to a multiple of 2^-16)
    std::int64_t refresh_us = 1000;     ///< refresh every this much event time (0: never by time)
    std::int64_t refresh_events = 0;    ///< refresh every this many events (0: never by count)
    bool adaptive = true;           ///< threshold: running mean + sigmas * std (else `threshold`)
    double sigmas = 2.0;            ///< adaptive: standard deviations above the mean, finite
    double alpha = 1e-3;            ///< adaptive: weight of each new value in the running statistics, (0, 1]
    double threshold = 1e6;         ///< fixed rule: corner iff value > threshold, finite
    bool replicate_border = false;  ///< beyond the sensor the TOS reads as its nearest pixel (else 0)
};

/// The Harris response of the integer structure tensor (a, b; b, c), exactly
/// det - (k_q / 2^16) tr^2 in 128-bit integers, converted to double by a fixed sequence of
/// correctly rounded operations and multiplied by `scale`. Shared by the detector and its
/// oracle (naive/luvharris_naive.hpp).
double luv_harris_response(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t k_q, double scale) noexcept;

class LuvHarris {
public:
    using Params = LuvHarrisParams;

    /// Limits of the time rule's arithmetic: events with |t| < 2^62.
    static constexpr std::int64_t kMaxTime = (std::int64_t{1} << 62) - 1;
    static constexpr std::int64_t kMaxRefreshUs = std::int64_t{1} << 40;

    /// Throws std::invalid_argument for a parameter or sensor side out of range (the
    /// message names it). `planes` is ignored: luvHarris ignores polarity.
    explicit LuvHarris(SensorSize size, const Params& params = {}, int planes = 2);

    /// Bytes of state: the TOS and its copy at the latest refresh point, the table, its
    /// stale marks and the refresh's work buffers.
    [[nodiscard]] static std::uint64_t state_bytes(SensorSize size, const Params& params = {}, int planes = 2) noexcept;

    [[nodiscard]] EventLimits limits() const noexcept { return {size_, -kMaxTime, kMaxTime}; }

    bool process(const Event& e) {
        check_event(e, limits());
        return process_unchecked(e);
    }
    bool process_unchecked(const Event& e) noexcept;

    /// The table value looked up for the latest event; kNoScore before the first refresh.
    [[nodiscard]] double last_score() const noexcept { return score_; }

    /// Recomputes the table from the TOS now (what a refresh point does).
    void refresh() noexcept;
    /// Refreshes done so far, and those of them that computed the whole table at once.
    [[nodiscard]] std::uint64_t refreshes() const noexcept { return refreshes_; }
    [[nodiscard]] std::uint64_t full_refreshes() const noexcept { return full_refreshes_; }
    /// Table values computed so far (a whole-table refresh counts every pixel).
    [[nodiscard]] std::uint64_t table_values_computed() const noexcept { return computed_; }

    /// The TOS value at (x, y) and the table value at (x, y) (unchecked; a stale value is
    /// computed on this call, so the table reads as if recomputed whole at the latest refresh).
    [[nodiscard]] int tos(int x, int y) const noexcept { return tos_[index(x, y)]; }
    [[nodiscard]] double table(int x, int y) const noexcept;
    /// The adaptive rule's running mean and variance of the looked-up values.
    [[nodiscard]] double running_mean() const noexcept { return mean_; }
    [[nodiscard]] double running_variance() const noexcept { return var_; }
    /// k as the table uses it: k_q / 2^16.
    [[nodiscard]] std::int64_t k_q() const noexcept { return k_q_; }
    /// The factor from integer responses to TOS levels per pixel.
    [[nodiscard]] double scale() const noexcept { return scale_; }

    [[nodiscard]] const Params& params() const noexcept { return params_; }
    [[nodiscard]] SensorSize size() const noexcept { return size_; }
    [[nodiscard]] std::size_t memory_bytes() const noexcept;

private:
    [[nodiscard]] std::size_t index(int x, int y) const noexcept {
        return (static_cast<std::size_t>(y) + pad_) * stride_ + static_cast<std::size_t>(x) + pad_;
    }
    void update_tos(int x, int y) noexcept;
    void mark_dirty(int x, int y) noexcept;
    void fill_border() noexcept;

    Params params_;
    SensorSize size_;
    int pad_;             // TOS frame: gradient/2 + block/2
    std::size_t stride_;  // width + 2 pad
    int tos_drop_;        // 255 - tos_size * tos_threshold
    std::int64_t k_q_;
    double scale_;
    std::vector<std::int32_t> block_weights_;

    ZeroedArray<std::uint8_t> tos_;     // (height + 2 pad) x stride
    ZeroedArray<std::uint8_t> snap_;    // the TOS at the latest refresh point, same frame
    // The table (height x width), valid where stamp_ or full_epoch_ is at least the pixel's
    // tile's entry in stale_since_ (refresh epochs); computed on read elsewhere.
    mutable ZeroedArray<double> table_;
    mutable ZeroedArray<std::uint32_t> stamp_;
    std::vector<std::uint32_t> stale_since_;   // per 8x8 tile of the table
    std::vector<std::uint8_t> dirty_;          // per 8x8 tile of the TOS: changed since the refresh
    ZeroedArray<std::uint32_t> dirty_list_;    // those tiles, in order of marking
    std::size_t dirty_count_ = 0;
    std::size_t tiles_w_ = 0;
    std::uint32_t epoch_ = 0, full_epoch_ = 0;
    std::uint64_t events_since_refresh_ = 0;
    std::uint64_t full_refreshes_ = 0;
    mutable std::uint64_t computed_ = 0;
    // Refresh work buffers (allocated once, a few rows each): ring buffers of the
    // horizontal smooth / derivative passes, one row of the three gradient products, a
    // ring of their horizontal block sums.
    ZeroedArray<std::int16_t> hs_, hd_;
    ZeroedArray<std::int32_t> xx_;
    ZeroedArray<std::int64_t> bxx_;

    bool started_ = false;
    bool refreshed_ = false;
    std::int64_t t0_ = 0;
    std::int64_t next_t_ = 0;
    std::int64_t until_count_refresh_ = 0;  // events left before the count rule's next point
    std::uint64_t refreshes_ = 0;
    std::uint64_t stats_n_ = 0;
    double mean_ = 0.0, var_ = 0.0;
    double score_ = kNoScore;
};
static_assert(ScoredDetector<LuvHarris>);

}  // namespace evcorner
