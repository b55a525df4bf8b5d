#pragma once
// Surface of Active Events (SAE): for each polarity, the timestamp of the latest
// event at every pixel (Benosman et al., 2014; Mueggler et al., BMVC 2017, Sec. 2).
// A pixel that never fired reads as kNever, older than every real timestamp.
//
// Stored form: a cell holds t + kBias (> 0 for every time the SAE takes, kMinTime..
// kMaxTime) and 0 for never, so that the planes start as zero pages (zeroed_array.hpp)
// that cost nothing until written. The order of the stored values is the order of the
// times, so the eFAST tests compare stored values directly; at() gives times back.

#include <cstddef>
#include <cstdint>
#include <limits>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/zeroed_array.hpp"

namespace evcorner {

class Sae {
public:
    static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min();
    /// Stored value = t + kBias; 0 = never fired.
    static constexpr std::int64_t kBias = std::int64_t{1} << 62;
    /// The times the SAE holds: about +-146 000 years of microseconds around 0.
    static constexpr std::int64_t kMinTime = -kBias + 1;
    static constexpr std::int64_t kMaxTime = std::numeric_limits<std::int64_t>::max() - kBias;

    /// Bytes of state for a sensor of `size` with `planes` planes (8 per pixel and plane).
    [[nodiscard]] static constexpr std::uint64_t state_bytes(SensorSize size, int planes = 2) noexcept {
        return static_cast<std::uint64_t>(planes == 1 ? 1 : 2) * static_cast<std::uint64_t>(size.pixels()) *
               sizeof(std::int64_t);
    }

    /// `planes` = 2: one plane per polarity. 1: a single plane that both polarities
    /// share, for a caller that feeds events of one polarity only (half the memory).
    explicit Sae(SensorSize size, int planes = 2)
        : size_(size), planes_(planes == 1 ? 1 : 2),
          cells_(static_cast<std::size_t>(planes_) * static_cast<std::size_t>(size.pixels())) {}

    [[nodiscard]] SensorSize size() const noexcept { return size_; }

    /// Row-major plane of one polarity, in stored form: plane(p)[y * width + x].
    [[nodiscard]] const std::int64_t* plane(int p) const noexcept {
        return cells_.data() + static_cast<std::size_t>(p != 0 && planes_ == 2) * plane_size();
    }
    [[nodiscard]] std::int64_t* plane(int p) noexcept {
        return cells_.data() + static_cast<std::size_t>(p != 0 && planes_ == 2) * plane_size();
    }
    /// 2, or 1 when both polarities share one plane.
    [[nodiscard]] int planes() const noexcept { return planes_; }
    /// The time of the latest event at (x, y) of polarity p, or kNever. Unchecked.
    [[nodiscard]] std::int64_t at(int p, int x, int y) const noexcept {
        const std::int64_t v = plane(p)[static_cast<std::size_t>(y) * static_cast<std::size_t>(size_.width) +
                                        static_cast<std::size_t>(x)];
        return v == 0 ? kNever : v - kBias;
    }
    /// The stored form of time t (kMinTime <= t <= kMaxTime).
    [[nodiscard]] static constexpr std::int64_t stored(std::int64_t t) noexcept { return t + kBias; }
    /// Records `e`, which must lie on the sensor with p 0/1 and a time in range. Unchecked.
    void update_unchecked(const Event& e) noexcept {
        plane(e.p)[static_cast<std::size_t>(e.y) * static_cast<std::size_t>(size_.width) + e.x] = stored(e.t);
    }
    /// Every pixel back to never fired.
    void clear() { cells_.clear(); }

    [[nodiscard]] std::size_t memory_bytes() const noexcept {
        return cells_.size() * sizeof(std::int64_t);
    }

private:
    [[nodiscard]] std::size_t plane_size() const noexcept {
        return static_cast<std::size_t>(size_.pixels());
    }

    SensorSize size_;
    int planes_;
    ZeroedArray<std::int64_t> cells_;
};

}  // namespace evcorner
