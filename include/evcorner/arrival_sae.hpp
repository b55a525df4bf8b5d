#pragma once
// Arrival-ordered Surface of Active Events: for each polarity, the arrival sequence
// number of the latest event at every pixel (1 for the first event of the stream,
// then 2, 3, ...; 0 = never fired). Unlike timestamps, sequence numbers are unique,
// so "the newest pixels" is always well defined: ties in time are broken by arrival.
//
// Each plane carries a frame of `pad` never-fired cells on every side, so that a
// window of radius <= pad around any pixel of the sensor can be read without bounds
// checks (cells outside the sensor read as never fired). The planes start as zero
// pages (zeroed_array.hpp): memory is committed only where events write.

#include <cstddef>
#include <cstdint>
#include <span>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/zeroed_array.hpp"

namespace evcorner {

class ArrivalSae {
public:
    /// `planes` = 2: one plane per polarity; 1: one plane both polarities share (for a
    /// caller that feeds one polarity only).
    ArrivalSae(SensorSize size, int pad, int planes = 2)
        : size_(size),
          pad_(pad),
          planes_(planes == 1 ? 1 : 2),
          stride_(static_cast<std::size_t>(size.width) + 2 * static_cast<std::size_t>(pad)),
          plane_size_(stride_ * (static_cast<std::size_t>(size.height) + 2 * static_cast<std::size_t>(pad))),
          cells_(static_cast<std::size_t>(planes_) * plane_size_) {}

    /// Bytes of state for a sensor of `size` with a frame of `pad` and `planes` planes.
    [[nodiscard]] static constexpr std::uint64_t state_bytes(SensorSize size, int pad, int planes = 2) noexcept {
        return static_cast<std::uint64_t>(planes == 1 ? 1 : 2) *
               (static_cast<std::uint64_t>(size.width) + 2 * static_cast<std::uint64_t>(pad)) *
               (static_cast<std::uint64_t>(size.height) + 2 * static_cast<std::uint64_t>(pad)) * sizeof(std::uint64_t);
    }

    [[nodiscard]] SensorSize size() const noexcept { return size_; }
    [[nodiscard]] int pad() const noexcept { return pad_; }
    /// Distance in cells between vertically adjacent pixels.
    [[nodiscard]] std::size_t stride() const noexcept { return stride_; }

    /// Index of pixel (x, y) inside a plane (padding included).
    [[nodiscard]] std::size_t index(int x, int y) const noexcept {
        return (static_cast<std::size_t>(y) + pad_) * stride_ + static_cast<std::size_t>(x) + pad_;
    }
    [[nodiscard]] const std::uint64_t* plane(int p) const noexcept {
        return cells_.data() + static_cast<std::size_t>(p != 0 && planes_ == 2) * plane_size_;
    }
    [[nodiscard]] std::uint64_t at(int p, int x, int y) const noexcept { return plane(p)[index(x, y)]; }

    /// Stamps `e` with the next sequence number and returns it. `e` must lie on the
    /// sensor (unchecked).
    std::uint64_t update_unchecked(const Event& e) noexcept {
        // `&`, not `&&`: no branch on the polarity (which a compiler emitted, and mispredicted).
        cells_[static_cast<std::size_t>((e.p != 0) & (planes_ == 2)) * plane_size_ + index(e.x, e.y)] = ++last_;
        return last_;
    }
    /// update_unchecked() for every event of `events`, in order (one loop with the
    /// state in registers: a store per event). Every event must lie on the sensor.
    void update_unchecked(std::span<const Event> events) noexcept {
        std::uint64_t* const cells = cells_.data() + static_cast<std::size_t>(pad_) * stride_ + pad_;
        const std::size_t stride = stride_;
        const std::size_t other = planes_ == 2 ? plane_size_ : 0;
        std::uint64_t last = last_;
        for (const Event& e : events)
            cells[static_cast<std::size_t>(e.p != 0) * other + static_cast<std::size_t>(e.y) * stride + e.x] = ++last;
        last_ = last;
    }
    /// The sequence number of the latest event (0 before the first).
    [[nodiscard]] std::uint64_t last() const noexcept { return last_; }

    [[nodiscard]] std::size_t memory_bytes() const noexcept {
        return cells_.size() * sizeof(std::uint64_t);
    }

private:
    SensorSize size_;
    int pad_;
    int planes_;
    std::size_t stride_;
    std::size_t plane_size_;
    ZeroedArray<std::uint64_t> cells_;
    std::uint64_t last_ = 0;
};

}  // namespace evcorner
