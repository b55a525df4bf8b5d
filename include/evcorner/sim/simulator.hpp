#pragma once
// An event-camera simulator for scenes of moving polygons (scene.hpp), after the pixel model
// of ESIM (Rebecq, Gehrig, Scaramuzza, CoRL 2018) and v2e (Hu, Liu, Delbruck, CVPRW 2021),
// written from their descriptions:
//
//   I(x, y, t)  the image: background, then each object in list order composited over it with
//               its exact per-pixel area coverage (coverage.hpp); intensities in [0, 1]
//   L = log(eps + I), eps = 0.001; each pixel keeps a reference level, set to L at t = 0
//   an ON (OFF) event each time L reaches reference + C_on (reference - C_off); the
//               reference then moves by that C. C_on, C_off ~ N(C, sigma) per pixel, drawn once
//   crossing time: I is linear between two samples of a pixel (exact for an edge parallel to
//               a pixel side moving at constant speed), so the time at which I reaches the
//               threshold's intensity exp(reference +- C) - eps is interpolated linearly in I;
//               the interval is halved until that time moves by at most 50 us * step_fraction
//   multirate: the image is rendered at steps of at most max_step_us (vertices moving less
//               than 0.75 px); within a step a pixel whose L changed by more than
//               step_fraction * C is sampled on its own (exact coverage at the instant,
//               halving the interval) until no pixel's L changes by more than that between
//               two of its samples
//   refractory: an event less than refractory_us after the pixel's last emitted one is
//               dropped (its reference still moves, so the pixel stays in step with the light)
//   noise: Poisson background activity at noise_hz per pixel, random polarity, plus hot pixels
//               (ON at hot_pixel_hz each); neither touches references nor refractory state
//   timestamps: the crossing time rounded to the nearest microsecond (at least 1: nothing at
//               t = 0); events sorted by (t, y, x, p) within a step, steps in time order
//
// Streaming: step() hands out one step's events at a time; memory is a few arrays the size
// of the sensor (and each object's accumulator window, at most that size), whatever the
// duration. Steps are also short enough that no vertex moves
// 0.75 px; then only the pixels a moving edge passes through (before or after the step) can
// change, and only they are recomputed (kept as per-row bitmaps; each object's coverage is
// summed along a row only at the columns its edges wrote): the work per step follows the
// edges' length, not the objects' area.

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/sim/motion.hpp"
#include "evcorner/sim/random.hpp"
#include "evcorner/sim/scene.hpp"

namespace evcorner::sim {

inline constexpr double kLogEps = 0.001;

struct SimStats {
    std::uint64_t steps = 0;
    std::uint64_t rejected_steps = 0;  ///< retried shorter: some vertex moved too far
    std::uint64_t pixel_samples = 0;   ///< single pixels sampled within steps (per-pixel refinement)
    std::uint64_t on = 0;
    std::uint64_t off = 0;
    std::uint64_t noise = 0;       ///< background-activity and hot-pixel events (counted in on/off too)
    std::uint64_t refractory = 0;  ///< crossings dropped by the refractory period
    double max_step_change = 0;    ///< largest |delta L| / C between two samples of a pixel (bounded via |dI| / (eps + min I))
};

class Simulator {
public:
    explicit Simulator(Scene scene);

    /// Simulates the next step and appends its events, sorted, to `out`. Returns false, and
    /// appends nothing, once the scene's duration is reached.
    bool step(std::vector<Event>& out);

    /// Simulated time reached, microseconds (0 before the first step).
    [[nodiscard]] double time_us() const noexcept { return t_; }
    [[nodiscard]] const Scene& scene() const noexcept { return scene_; }
    [[nodiscard]] const SimStats& stats() const noexcept { return stats_; }
    /// The image at time_us(), row-major.
    [[nodiscard]] std::span<const double> image() const noexcept { return cur_; }

    /// A single pixel sampled within a step (per-pixel refinement): pixel index, time in us,
    /// intensity.
    struct PixelSample {
        std::size_t pixel;
        double t_us;
        double value;
    };
    /// When set, every single-pixel sample is appended to `out` (for tests: each can be
    /// checked against a full render at its time); nullptr stops it.
    void record_samples(std::vector<PixelSample>* out) noexcept { record_ = out; }

private:
    struct Rect {
        int x0 = 0, x1 = -1, y0 = 0, y1 = -1;  // inclusive; empty when x1 < x0
        [[nodiscard]] bool empty() const noexcept { return x1 < x0 || y1 < y0; }
    };
    void place_objects(double t_us);  // fills polys_ and rects_ for time t
    void render(bool all_rows);       // renders into next_ over the dirty pixels (dirty_)
    // An object's own accumulators: its edge walk's additions (coverage_walk.hpp) into a
    // window of rows y0 .. y1 and of words columns from x0 (a multiple of 64) that holds every
    // cell the walk can write at the time being rendered. cov gets the coverage additions, val
    // (a checkerboard only) the intensity-weighted ones; written (a still object's only) has a
    // bit per cell the walk wrote. A moving object's cells are cleared as the compositing reads them (all zero
    // between renders, whatever the window); a still object's are written once and kept.
    struct ObjectAcc {
        int x0 = 0, y0 = 0, y1 = -1;
        std::size_t words = 0;  // 64-bit words (64 cells) per window row
        std::vector<double> cov, val;
        std::vector<std::uint64_t> written;
    };
    template <bool Dual, bool Moving>
    struct AccSink;
    // Sizes object o's window for its rectangle (rects_[o]) and walks its edges as placed in
    // polys_ into it. With marks (a moving object) it also marks the pixels its edges touch
    // (rows y0 .. y1 grow to hold them) and keeps no written bits; without (a still object,
    // walked once) it keeps them. An object off the sensor is not walked (its window is empty).
    void walk_object(std::size_t o, std::uint64_t* marks, int& y0, int& y1);
    [[nodiscard]] double max_displacement() const noexcept;
    void emit_crossings(double t0, double t1, std::vector<Event>& step_events);
    // Per-pixel sampling within a step (multirate): the times of a step [t0, t1] are keys,
    // t0 + (t1 - t0) key / 2^kKeyBits, so that the pixels sampled at the same instant share
    // one placement of the objects.
    static constexpr int kKeyBits = 48;  // a step's instants are keys of this many bits
    static constexpr std::uint64_t kKeyEnd = std::uint64_t{1} << kKeyBits;
    struct Box {
        double x0, x1, y0, y1;
    };
    struct Placement {  // one object's pose at one instant, and its pieces placed so far
        std::uint64_t tag = 0;  // object and key
        Pose pose;
        std::vector<std::uint32_t> piece_at;  // per piece: its vertices' first index in placed_, or kNotPlaced
    };
    static constexpr std::uint32_t kNotPlaced = UINT32_MAX;
    [[nodiscard]] double key_time(std::uint64_t key) const noexcept {
        return key == kKeyEnd ? step_t0_ + step_len_
                              : step_t0_ + step_len_ * (static_cast<double>(key) * (1.0 / static_cast<double>(kKeyEnd)));
    }
    Placement& placement(std::size_t o, std::uint64_t key);
    [[nodiscard]] double sample(std::size_t p, std::uint64_t key);  // pixel p's intensity at the key's time
    // Pixel p from a (at key ka) to b (at kb): splits the interval until its |dL| bound is at
    // most the step fraction and a crossing's interpolated time is settled, then emits.
    void refine(std::size_t p, std::uint64_t ka, std::uint64_t kb, double a, double b, bool settled,
                std::vector<Event>& ev);
    void cross(std::size_t p, double ta, double tb, double a, double b, std::vector<Event>& ev);
    // Whether a value going from a to b reaches `on` (rising) or `off` (falling); for pixel
    // p, its next levels ion_[p] and ioff_[p].
    [[nodiscard]] static bool reaches(double a, double b, double on, double off) noexcept {
        return b > a ? b >= on : b < a && b <= off;
    }
    [[nodiscard]] bool reaches_level(std::size_t p, double a, double b) const noexcept {
        return reaches(a, b, ion_[p], ioff_[p]);
    }
    void emit_noise(double t1, std::vector<Event>& step_events);
    [[nodiscard]] std::uint64_t* row_bits(std::vector<std::uint64_t>& bits, int y) noexcept {
        return bits.data() + static_cast<std::size_t>(y) * words_;
    }

    Scene scene_;
    int w_, h_;
    std::size_t stride_;
    std::size_t words_;  // 64-bit words per bitmap row: bits for columns 0 .. w_
    double t_ = 0;
    double dt_;
    double end_;
    std::vector<double> bg_, cur_, next_;
    std::vector<double> lref_, ion_, ioff_;
    std::vector<float> con_, coff_;
    // Thresholds and reference levels are set when a pixel first changes (ready_pixel()):
    // ready_ says which are, thresholds_rng_ is the thresholds' stream at pixel 0.
    std::vector<char> ready_;
    Random thresholds_rng_{0};
    void ready_pixel(std::size_t p);
    std::vector<std::int64_t> last_;
    std::vector<ObjectAcc> acc_;  // per object, its edge walk at the time being rendered
    // Per object: its pieces' polygons at the time being rendered (polys_) and at time_us()
    // (prev_polys_), and the pixel rectangle it covers at the time being rendered.
    std::vector<std::vector<std::vector<Vec2>>> polys_, prev_polys_;
    std::vector<Rect> rects_;
    std::vector<char> moving_;
    // Bitmaps, one row of words_ words per sensor row. The pixels the moving edges touch at
    // the time being rendered (cur_marks_) and at time_us() (prev_marks_, kept from the step
    // that reached it), each with the range of rows [y0, y1] outside which it is all zero;
    // dirty_ is their union (valid over dirty_y0_ .. dirty_y1_), the pixels recomputed.
    std::vector<std::uint64_t> cur_marks_, prev_marks_, dirty_, zero_row_;
    int cur_y0_ = 0, cur_y1_ = -1, prev_y0_ = 0, prev_y1_ = -1, dirty_y0_ = 0, dirty_y1_ = -1;
    std::vector<std::uint64_t> inside_;  // render(): the composited object's columns, per window word
    std::vector<std::uint32_t> dirty_list_;  // the dirty pixels, row-major (render() writes the first dirty_n_)
    std::size_t dirty_n_ = 0;
    std::size_t changed_n_ = 0;  // the dirty pixels whose value changed in the last step (emit_crossings)
    // Per-pixel sampling: each object's first piece in a numbering of every object's pieces in
    // order (object_first_piece_, plus the end), the pixels each piece can cover within the
    // step (piece_rect_), the placements of the current step (a pool reused from step to step)
    // and their index by object and key; the step being refined and the crossing-time tolerance.
    std::vector<std::size_t> object_first_piece_;
    struct PixelRect {
        int x0, x1, y0, y1;  // inclusive
    };
    std::vector<PixelRect> piece_rect_;        // per piece (global index)
    std::vector<std::uint32_t> piece_object_;  // per piece (global index): its object
    // The pieces (global indices, in order) whose rectangles hold near_pixel_, the pixel being
    // sampled: found once per pixel and step (near_pieces()), not at every sample of it; the
    // first near_n_ entries of near_.
    std::vector<std::uint32_t> near_;
    std::size_t near_n_ = 0;
    std::size_t near_pixel_ = SIZE_MAX;
    void near_pieces(std::size_t p, int x, int y);
    bool rects_ready_ = false;  // piece_rect_ made for this step (on its first sample)
    void make_rects();
    std::vector<Vec2> placed_;  // the pieces placed at the step's sampled instants
    // Each pixel's value one step before cur_ (hist_), kept when it changed in that step too
    // (hist_step_: that step's index + 1), and the length of the step before this one: with
    // them a crossing's interval needs no midpoint sample where the three values say I is
    // close enough to linear (emit_crossings).
    std::vector<double> hist_;
    std::vector<std::uint32_t> hist_step_;
    double last_len_ = 0;
    std::uint64_t split_samples_ = 0;
    std::vector<PixelSample>* record_ = nullptr;  // samples of this step spent keeping the step fraction
    std::vector<Placement> places_;
    std::size_t places_n_ = 0;
    std::vector<std::uint64_t> slot_tag_;  // open addressing: tag + 1 of the placement (0: empty)
    std::vector<std::uint32_t> slot_place_, slots_used_;
    // The placements at the first kDirectBits halvings' instants (keys multiple of kKeyEnd /
    // kDirect): per object and key / (kKeyEnd / kDirect), the placement's index + 1 (0: none
    // yet this step), and the entries set this step.
    static constexpr int kDirectBits = 4;
    static constexpr std::uint64_t kDirect = std::uint64_t{1} << kDirectBits;
    std::vector<std::uint32_t> direct_, direct_used_;
    Placement& new_placement(std::size_t o, std::uint64_t key, std::uint64_t tag);
    double step_t0_ = 0, step_len_ = 0, limit_ = 0, crossing_tol_us_ = 0;
    // Noise: the next background-activity time and its stream.
    Random noise_rng_;
    double noise_rate_per_us_ = 0;
    double next_noise_ = 0;
    std::vector<std::uint32_t> hot_;
    std::vector<Event> step_events_;
    SimStats stats_;
};

/// Every event of a scene, for tests and small scenes (the CLI streams with step()).
std::vector<Event> simulate(const Scene& scene);

}  // namespace evcorner::sim
