#pragma once
// Running a local detector on several threads with output identical to one thread.
//
// A detector is *local* with radius r when whether event e is a corner depends only on
// the earlier events within r pixels of e (eFAST: r = 4, the radius-4 circle; Harris:
// half its window). Then the sensor splits into parts, each a band of rows [y0, y1): a
// part keeps its own detector, over a sensor of just the rows [y0 - r, y1 + r) (the band
// and its halo, clipped to the sensor), feeds it, in input order, every event of its
// part in those rows, and keeps its answers only for the events of its band. Two ways
// to split (Locality::split_polarity, from the registry's entry):
//  - by polarity: when a decision reads only the events of e's own polarity (eFAST,
//    Harris), each part takes one polarity, and its detector keeps one state plane;
//  - by rows only: when a decision also reads the other polarity, each part takes both
//    polarities of its rows, and its detector keeps both planes.
// Each event is classified by exactly one part, from a state identical to that of a
// single detector run over the whole stream (the border rule sees the same distances: a
// halo is at least the detector's border margin), so the flags are identical, in input
// order, for any number of threads.
//
// Parts outnumber threads (by default four per thread) and are handed out per batch,
// largest first, to whichever thread is free: the load balances however the events move
// over the sensor, and the calling thread can do other work first (read the next batch:
// see run()). Bands are cut from the first batch, fixed from then on, each at least 2r
// rows high, so that a row lies in the halo of at most one other band.
//
// Threads, clocks and allocation stay outside the detectors: each part runs the
// detector's own batch loop (detector.hpp; eFAST's fastest path from efast.hpp).
//
// detect() and prepare() check every event as the detector's detect() does (InvalidEvent
// for an event off the sensor, with polarity other than 0/1, or a time the detector
// cannot hold) before any of it is used; the parts then run the unchecked loop.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <numeric>
#include <span>
#include <stdexcept>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner {

/// A fixed set of threads that run one job together: run(job) calls job(w) for every
/// worker w in 0..size() (w = 0 on the calling thread) and returns when all are done.
class WorkerPool {
public:
    explicit WorkerPool(int threads);
    ~WorkerPool();
    WorkerPool(const WorkerPool&) = delete;
    WorkerPool& operator=(const WorkerPool&) = delete;

    [[nodiscard]] int size() const noexcept { return threads_; }
    void run(const std::function<void(int)>& job);

private:
    struct State;
    int threads_;
    std::unique_ptr<State> state_;
};

/// How a local detector may be split: its radius, and whether a part may take one
/// polarity (true: its decisions read their own polarity only) or must take both.
struct Locality {
    int radius = 0;
    bool split_polarity = true;
    constexpr Locality(int r, bool by_polarity = true) noexcept : radius(r), split_polarity(by_polarity) {}
};

/// One part of the sensor: the band of rows [y0, y1) of polarity p (p = -1: both), and
/// the rows [lo, hi) its detector covers (the band and its halo, clipped to the sensor).
struct DetectPart {
    int p = 0;
    int y0 = 0, y1 = 0;
    int lo = 0, hi = 0;
    [[nodiscard]] bool owns(int pol, int y) const noexcept { return (p < 0 || pol == p) && y >= y0 && y < y1; }
};

/// Cuts the rows into at most `bands` bands holding similar numbers of `sample`'s events,
/// each at least max(1, 2 * radius) rows high (fewer bands on a short sensor). With
/// `split_polarity`, each polarity's rows separately: the OFF bands top to bottom, then
/// the ON bands; else bands of both polarities (p = -1), top to bottom.
std::vector<DetectPart> plan_parts(SensorSize size, int bands, int radius, std::span<const Event> sample,
                                   bool split_polarity = true);

namespace detail {
// The detector's batch loops: unqualified calls, so that argument-dependent lookup
// finds a detector's own overload (eFAST's, in efast.hpp) over the generic one. `span`
// holds the batch's times; a detector with an overload that takes it (eFAST) gets it.
template <class D>
std::size_t run_batch(D& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                      const TimeSpan& span) noexcept {
    if constexpr (requires { detect_unchecked(det, events, is_corner, span); })
        return detect_unchecked(det, events, is_corner, span);
    else
        return detect_unchecked(det, events, is_corner);
}
template <class D>
std::size_t run_batch_checked(D& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) {
    return detect(det, events, is_corner);
}

// A buffer of trivially copyable values whose pages are touched only where written.
template <class T>
struct RawBuffer {
    std::unique_ptr<T[]> data;
    void reserve(std::size_t n) {
        if (!data) data.reset(new T[n]);  // default-initialised: no writes
    }
};
}  // namespace detail

template <Detector D>
class ParallelDetector {
public:
    /// Most events a prepare() takes at once.
    static constexpr std::size_t kMaxBatch = std::size_t{1} << 16;

    /// `make(SensorSize, planes)` builds one detector: over the whole sensor with one state
    /// plane per polarity (planes = 2) for a single thread, or over a part's rows, with one
    /// plane (planes = 1) when the parts split by polarity, else two. `locality` is the
    /// detector's radius and split (an int: that radius, split by polarity);
    /// `parts_per_thread` parts per thread are handed out per batch.
    template <class Make>
    ParallelDetector(SensorSize size, int threads, Locality locality, Make make, int parts_per_thread = 4)
        : size_(checked_sensor_size(size, "ParallelDetector")), radius_(locality.radius),
          split_polarity_(locality.split_polarity), parts_per_thread_(std::max(1, parts_per_thread)),
          pool_(std::max(1, threads)), make_(std::move(make)) {
        if (pool_.size() == 1) {
            single_ = std::make_unique<D>(make_(size_, 2));
            limits_ = single_->limits();
        } else {
            limits_ = make_(SensorSize{1, 1}, part_planes()).limits();  // the detector's time range
            limits_.size = size_;
        }
    }

    /// Whether parts take one polarity each.
    [[nodiscard]] bool split_polarity() const noexcept { return split_polarity_; }

    /// What detect() and prepare() accept (the detector's limits over the whole sensor).
    [[nodiscard]] const EventLimits& limits() const noexcept { return limits_; }

    [[nodiscard]] int threads() const noexcept { return pool_.size(); }
    [[nodiscard]] std::span<const DetectPart> parts() const noexcept { return plan_; }

    /// Like detect(det, events, is_corner) for a single detector, continuing the stream:
    /// prepare() and run() over the span in batches, preparing batch k + 1 while batch k
    /// is detected. Not while batches of prepare() wait for their run(). Throws
    /// InvalidEvent for the first event limits() does not accept, before detecting any.
    std::size_t detect(std::span<const Event> events, std::span<std::uint8_t> is_corner) {
        if (single_) return detail::run_batch_checked(*single_, events, is_corner);
        if (queued_ != 0) throw std::logic_error("ParallelDetector::detect: batches prepared and not run");
        if (is_corner.size() < events.size())
            throw std::invalid_argument("ParallelDetector::detect: fewer flags than events");
        // The whole span's times hold every batch's (what eFAST's parts use: efast.hpp).
        const TimeSpan span = check_events_span(events, limits_);
        std::size_t corners = 0;
        if (events.empty()) return 0;
        prepare_unchecked(events.first(std::min(kMaxBatch, events.size())), span);
        for (std::size_t at = 0; at < events.size(); at += kMaxBatch) {
            const std::size_t n = std::min(kMaxBatch, events.size() - at);
            const std::size_t next = at + n;
            corners += run(is_corner.subspan(at, n), [&] {
                if (next < events.size())
                    prepare_unchecked(events.subspan(next, std::min(kMaxBatch, events.size() - next)), span);
            });
        }
        return corners;
    }

    /// Queues the next batch (at most kMaxBatch events, kept alive by the caller until its
    /// run() returns): sorts it out to the parts. At most two batches are queued; the
    /// first batch plans the parts. Throws InvalidEvent for the first event limits() does
    /// not accept (nothing queued).
    void prepare(std::span<const Event> events) {
        const TimeSpan span = check_events_span(events, limits_);
        prepare_unchecked(events, span);
    }
    /// prepare() without the check of the events: each must be accepted by limits().
    /// `span`: times holding the batch's (event_check.hpp), or TimeSpan::unknown().
    void prepare_unchecked(std::span<const Event> events, const TimeSpan& span = TimeSpan::unknown()) {
        if (events.size() > kMaxBatch) throw std::length_error("ParallelDetector::prepare: batch too large");
        if (queued_ == 2) throw std::logic_error("ParallelDetector::prepare: two batches queued already");
        if (plan_.empty()) make_parts(events);
        Slot& s = slots_[(front_ + queued_) % 2];
        s.span = span;
        scatter(events, s);
        ++queued_;
    }

    /// Detects the oldest queued batch into `is_corner` (its size) and returns its number
    /// of corners. `alongside` runs on the calling thread first, while the other threads
    /// already detect (it may prepare() the next batch); then the calling thread helps.
    /// An exception from `alongside` is rethrown once the batch is done.
    std::size_t run(std::span<std::uint8_t> is_corner, const std::function<void()>& alongside = {}) {
        if (single_) throw std::logic_error("ParallelDetector::run: one thread; use detect()");
        if (queued_ == 0) throw std::logic_error("ParallelDetector::run: no batch prepared");
        Slot& s = slots_[front_];
        if (is_corner.size() != s.n) throw std::invalid_argument("ParallelDetector::run: flags size differs from the batch");
        std::atomic<std::size_t> next{0};
        std::exception_ptr failed;
        pool_.run([&](int w) {
            if (w == 0 && alongside) {
                try {
                    alongside();
                } catch (...) {
                    failed = std::current_exception();
                }
            }
            for (std::size_t j; (j = next.fetch_add(1, std::memory_order_relaxed)) < s.order.size();)
                run_part(s.order[j], s);
        });
        // Corners are sparse: set them here rather than have threads write bytes that
        // share cache lines. Each event belongs to one part, so the order is the input's.
        // Only the parts that had events in this batch ran: the others hold old answers.
        std::fill(is_corner.begin(), is_corner.end(), std::uint8_t{0});
        std::size_t corners = 0;
        for (const std::uint32_t j : s.order) {
            const Part& part = parts_[j];
            for (std::size_t k = 0; k < part.found; ++k) is_corner[part.corners.data[k]] = 1;
            corners += part.found;
        }
        front_ = (front_ + 1) % 2;
        --queued_;
        if (failed) std::rethrow_exception(failed);
        return corners;
    }

    /// Bytes of state over all parts.
    template <class MemoryOf>
    [[nodiscard]] std::size_t memory_bytes(MemoryOf memory_of) const {
        if (single_) return memory_of(*single_);
        std::size_t b = 0;
        for (const auto& part : parts_) b += memory_of(*part.detector);
        return b;
    }

private:
    static constexpr std::uint32_t kHalo = std::uint32_t{1} << 31;  // in a position: halo event

    struct Part {
        std::unique_ptr<D> detector;
        int lo = 0;
        detail::RawBuffer<std::uint8_t> flags;
        detail::RawBuffer<std::uint32_t> corners;  // positions of the corners of its band
        std::size_t found = 0;
    };
    // One batch, sorted out to the parts.
    struct Slot {
        std::size_t n = 0;
        std::vector<detail::RawBuffer<Event>> events;      // the part's events, rows shifted by lo
        std::vector<detail::RawBuffer<std::uint32_t>> at;  // their positions in the batch (| kHalo)
        std::vector<std::uint32_t> count;
        std::vector<std::uint32_t> order;  // parts with events, largest first
        TimeSpan span;                     // holds the batch's times
    };

    [[nodiscard]] int part_planes() const noexcept { return split_polarity_ ? 1 : 2; }

    void make_parts(std::span<const Event> sample) {
        // 512 parts at most (scatter's tables): 256 bands per polarity, or 512 of both.
        const int bands = split_polarity_ ? std::clamp(pool_.size() * parts_per_thread_ / 2, 1, 256)
                                          : std::clamp(pool_.size() * parts_per_thread_, 1, 512);
        plan_ = plan_parts(size_, bands, radius_, sample, split_polarity_);
        const std::size_t P = plan_.size();
        const std::size_t H = static_cast<std::size_t>(size_.height);
        main_of_.assign(2 * H, 0);
        halo_of_.assign(2 * H, static_cast<std::uint16_t>(P));  // P: in no halo
        for (std::size_t j = 0; j < P; ++j) {
            const DetectPart& d = plan_[j];
            for (int p = 0; p < 2; ++p) {
                if (d.p >= 0 && d.p != p) continue;
                const std::size_t at = static_cast<std::size_t>(p) * H;
                for (int y = d.y0; y < d.y1; ++y) main_of_[at + static_cast<std::size_t>(y)] = static_cast<std::uint16_t>(j);
                for (int y = d.lo; y < d.hi; ++y)
                    if (y < d.y0 || y >= d.y1) halo_of_[at + static_cast<std::size_t>(y)] = static_cast<std::uint16_t>(j);
            }
            Part part;
            part.detector = std::make_unique<D>(make_(SensorSize{size_.width, d.hi - d.lo}, part_planes()));
            part.lo = d.lo;
            part.flags.reserve(kMaxBatch);
            part.corners.reserve(kMaxBatch);
            parts_.push_back(std::move(part));
        }
        lo_.assign(P, 0);
        for (std::size_t j = 0; j < P; ++j) lo_[j] = static_cast<std::uint16_t>(plan_[j].lo);
        for (Slot& s : slots_) {
            s.events.resize(P);
            s.at.resize(P);
            s.count.assign(P, 0);
            for (auto& b : s.events) b.reserve(kMaxBatch);
            for (auto& b : s.at) b.reserve(kMaxBatch);
        }
    }

    // Each event to its band's part, and to the part whose halo holds it (if any): one
    // pass. Branch-free for the band (rows and polarities are data and would mispredict);
    // a branch for the halo, which few events are in (2r rows at each band boundary).
    void scatter(std::span<const Event> events, Slot& s) {
        const std::size_t P = parts_.size();
        const std::size_t H = static_cast<std::size_t>(size_.height);
        Event* out[512];
        std::uint32_t* at[512];
        std::uint32_t count[512] = {};
        for (std::size_t j = 0; j < P; ++j) {
            out[j] = s.events[j].data.get();
            at[j] = s.at[j].data.get();
        }
        const std::uint16_t* main_of = main_of_.data();
        const std::uint16_t* halo_of = halo_of_.data();
        const std::uint16_t* lo = lo_.data();
        for (std::size_t i = 0; i < events.size(); ++i) {
            const Event& e = events[i];
            const std::size_t cell = static_cast<std::size_t>(e.p & 1) * H + e.y;
            const std::size_t a = main_of[cell];
            Event ea = e;
            ea.y = static_cast<std::uint16_t>(e.y - lo[a]);
            out[a][count[a]] = ea;
            at[a][count[a]++] = static_cast<std::uint32_t>(i);
            const std::size_t b = halo_of[cell];
            if (b < P) [[unlikely]] {
                Event eb = e;
                eb.y = static_cast<std::uint16_t>(e.y - lo[b]);
                out[b][count[b]] = eb;
                at[b][count[b]++] = static_cast<std::uint32_t>(i) | kHalo;
            }
        }
        s.n = events.size();
        s.order.clear();
        for (std::size_t j = 0; j < P; ++j) {
            s.count[j] = count[j];
            if (count[j] > 0) s.order.push_back(static_cast<std::uint32_t>(j));
        }
        std::sort(s.order.begin(), s.order.end(), [&](std::uint32_t a, std::uint32_t b) { return s.count[a] > s.count[b]; });
    }

    void run_part(std::size_t j, const Slot& s) noexcept {
        Part& part = parts_[j];
        const std::size_t m = s.count[j];
        const Event* ev = s.events[j].data.get();
        const std::uint32_t* at = s.at[j].data.get();
        std::uint8_t* flags = part.flags.data.get();
        // The detector's own batch loop over band and halo events alike; answers for
        // halo events are dropped (a halo is a few rows).
        detail::run_batch(*part.detector, std::span<const Event>(ev, m), std::span<std::uint8_t>(flags, m), s.span);
        std::uint32_t* corners = part.corners.data.get();
        std::size_t found = 0;
        for (std::size_t k = 0; k < m; ++k) {
            corners[found] = at[k];
            found += flags[k] & static_cast<unsigned>((at[k] & kHalo) == 0);
        }
        part.found = found;
    }

    SensorSize size_;
    EventLimits limits_;
    int radius_;
    bool split_polarity_;
    int parts_per_thread_;
    WorkerPool pool_;
    std::function<D(SensorSize, int)> make_;
    std::unique_ptr<D> single_;
    std::vector<DetectPart> plan_;
    std::vector<Part> parts_;
    std::vector<std::uint16_t> main_of_, halo_of_, lo_;  // per (polarity, row) cell; lo per part
    Slot slots_[2];
    int front_ = 0;   // the slot the next run() detects
    int queued_ = 0;  // prepared batches not yet run
};

}  // namespace evcorner
