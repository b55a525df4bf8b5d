#pragma once
// Running a local detector on several threads with output identical to one thread.
//
// A detector is *local* with radius r when whether event e is a corner depends only on
// the earlier events of e's polarity within r pixels of e (eFAST: r = 4, the radius-4
// circle; Harris: half its window). Then the sensor splits into parts, each a band of
// rows [y0[p], y1[p]) per polarity p: the thread of a part keeps its own detector, feeds
// it, in input order, every event of polarity p in rows [y0[p] - r, y1[p] + r) (the band
// and its halo), and keeps its answers only for the events of its bands. Each event is classified
// by exactly one part, from a state identical to that of a single detector run over the
// whole stream, so the flags are identical, in input order, for any number of threads.
//
// Parts: the (polarity, row) cells, OFF rows then ON rows, cut into runs holding similar
// numbers of the first batch's events (so two threads get OFF and ON split exactly in
// half, although ON and OFF events are rarely half and half); fixed from then on (each
// part's state only covers its bands and halos).
//
// Threads, clocks and allocation stay outside the detectors: detect() below is the
// batch loop of detector.hpp, run by each thread on its share.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/event.hpp"
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

/// One part of the sensor: for each polarity p, the band of rows [y0[p], y1[p]) it owns
/// (empty when y0[p] == y1[p]).
struct DetectPart {
    int y0[2] = {0, 0};
    int y1[2] = {0, 0};
    [[nodiscard]] bool owns(int p, int y) const noexcept { return y >= y0[p] && y < y1[p]; }
};

/// Splits `size` into `threads` parts with similar numbers of `sample`'s events: the
/// (polarity, row) cells in the order OFF rows 0..H-1, then ON rows 0..H-1, cut into
/// `threads` runs. A run holds one band of one polarity, or the end of OFF and the start
/// of ON; no halo is needed between polarities.
std::vector<DetectPart> plan_parts(SensorSize size, int threads, std::span<const Event> sample);

namespace detail {
// The detector's batch loop: an unqualified call, so that argument-dependent lookup
// finds a detector's own overload (eFAST's, in efast.hpp) over the generic one.
template <class D>
std::size_t run_batch(D& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return detect(det, events, is_corner);
}
}  // namespace detail

template <Detector D>
class ParallelDetector {
public:
    /// `make()` builds one detector (one per part); `radius` is the detector's locality.
    template <class Make>
    ParallelDetector(SensorSize size, int threads, int radius, Make make)
        : size_(size), radius_(radius), pool_(std::max(1, threads)) {
        for (int i = 0; i < pool_.size(); ++i) detectors_.push_back(std::make_unique<D>(make()));
        shares_.resize(static_cast<std::size_t>(pool_.size()));
    }

    [[nodiscard]] int threads() const noexcept { return pool_.size(); }
    [[nodiscard]] std::span<const DetectPart> parts() const noexcept { return parts_; }

    /// Like detect(det, events, is_corner) for a single detector, continuing the stream.
    std::size_t detect(std::span<const Event> events, std::span<std::uint8_t> is_corner) {
        if (pool_.size() == 1) return detail::run_batch(*detectors_[0], events, is_corner);
        if (parts_.empty()) parts_ = plan_parts(size_, pool_.size(), events);
        std::size_t corners = 0;
        for (std::size_t at = 0; at < events.size(); at += kChunk) {
            const std::size_t n = std::min(kChunk, events.size() - at);
            corners += detect_chunk(events.subspan(at, n), is_corner.subspan(at, n));
        }
        return corners;
    }

    /// Bytes of state over all parts.
    template <class MemoryOf>
    [[nodiscard]] std::size_t memory_bytes(MemoryOf memory_of) const {
        std::size_t b = 0;
        for (const auto& d : detectors_) b += memory_of(*d);
        return b;
    }

private:
    // Events per round of the threads: bounds the per-thread buffers (25 bytes an event).
    static constexpr std::size_t kChunk = std::size_t{1} << 16;

    std::size_t detect_chunk(std::span<const Event> events, std::span<std::uint8_t> is_corner) {
        const std::size_t n = events.size();
        for (auto& sh : shares_) {
            sh.seen.resize(n);
            sh.events.resize(n);
            sh.flags.resize(n);
            sh.corners.resize(n);
        }
        pool_.run([&](int w) {
            // Each thread clears its slice of the output, then runs its part.
            const std::size_t parts = shares_.size();
            const std::size_t from = n * static_cast<std::size_t>(w) / parts;
            const std::size_t to = n * (static_cast<std::size_t>(w) + 1) / parts;
            std::fill(is_corner.begin() + static_cast<std::ptrdiff_t>(from),
                      is_corner.begin() + static_cast<std::ptrdiff_t>(to), std::uint8_t{0});
            run_part(static_cast<std::size_t>(w), events);
        });
        // Corners are sparse: set them here rather than have threads write bytes that
        // share cache lines. Each event belongs to one part, so the order is the input's.
        std::size_t corners = 0;
        for (const auto& sh : shares_) {
            for (std::size_t k = 0; k < sh.found; ++k) is_corner[sh.corners[k]] = 1;
            corners += sh.found;
        }
        return corners;
    }

    struct Share {
        std::vector<std::uint32_t> seen;     // positions of the events this part must see
        std::vector<Event> events;           // those events, in order
        std::vector<std::uint8_t> flags;     // the detector's answers for them
        std::vector<std::uint32_t> corners;  // positions of the corners of its band
        std::size_t found = 0;
    };

    void run_part(std::size_t w, std::span<const Event> events) noexcept {
        const DetectPart part = parts_[w];
        Share& s = shares_[w];
        // Rows to see per polarity: the band and its halo, or nothing.
        int lo[2], hi[2];
        for (int p = 0; p < 2; ++p) {
            const bool empty = part.y0[p] >= part.y1[p];
            lo[p] = empty ? 0 : part.y0[p] - radius_;
            hi[p] = empty ? 0 : part.y1[p] + radius_;
        }
        // Branch-free selection of the events to see (polarity and rows are data and
        // would mispredict).
        std::size_t m = 0;
        for (std::size_t i = 0; i < events.size(); ++i) {
            const Event& e = events[i];
            s.seen[m] = static_cast<std::uint32_t>(i);
            s.events[m] = e;
            const int p = e.p & 1;
            m += static_cast<unsigned>(e.y >= lo[p]) & static_cast<unsigned>(e.y < hi[p]);
        }
        // The detector's own batch loop (eFAST's fastest path) over them all; answers for
        // halo events are dropped (a halo is a few rows).
        detail::run_batch(*detectors_[w], std::span<const Event>(s.events.data(), m),
                          std::span<std::uint8_t>(s.flags.data(), m));
        std::size_t found = 0;
        for (std::size_t k = 0; k < m; ++k) {
            const Event& e = s.events[k];
            s.corners[found] = s.seen[k];
            found += s.flags[k] & static_cast<unsigned>(part.owns(e.p & 1, e.y));
        }
        s.found = found;
    }

    SensorSize size_;
    int radius_;
    WorkerPool pool_;
    std::vector<std::unique_ptr<D>> detectors_;
    std::vector<DetectPart> parts_;
    std::vector<Share> shares_;
};

}  // namespace evcorner
