#pragma once
// Surface of Active Events (SAE): for each polarity, the timestamp of the latest
// event at every pixel (Benosman et al., 2014; Mueggler et al., BMVC 2017, Sec. 2).
// A pixel that never fired holds kNever, older than every real timestamp.

#include <cstdint>
#include <limits>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner {

class Sae {
public:
    static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min();

    /// `planes` = 2: one plane per polarity. 1: a single plane that both polarities
    /// share, for a caller that feeds events of one polarity only (half the memory).
    explicit Sae(SensorSize size, int planes = 2)
        : size_(size), planes_(planes == 1 ? 1 : 2),
          cells_(static_cast<std::size_t>(planes_) * static_cast<std::size_t>(size.pixels()), kNever) {}

    [[nodiscard]] SensorSize size() const noexcept { return size_; }

    /// Row-major plane of one polarity: plane(p)[y * width + x].
    [[nodiscard]] const std::int64_t* plane(int p) const noexcept {
        return cells_.data() + static_cast<std::size_t>(p != 0 && planes_ == 2) * plane_size();
    }
    [[nodiscard]] std::int64_t* plane(int p) noexcept {
        return cells_.data() + static_cast<std::size_t>(p != 0 && planes_ == 2) * plane_size();
    }
    /// 2, or 1 when both polarities share one plane.
    [[nodiscard]] int planes() const noexcept { return planes_; }
    [[nodiscard]] std::int64_t at(int p, int x, int y) const noexcept {
        return plane(p)[static_cast<std::size_t>(y) * size_.width + x];
    }
    void update(const Event& e) noexcept {
        plane(e.p)[static_cast<std::size_t>(e.y) * size_.width + e.x] = e.t;
    }
    void clear() noexcept { cells_.assign(cells_.size(), kNever); }

    [[nodiscard]] std::size_t memory_bytes() const noexcept {
        return cells_.size() * sizeof(std::int64_t);
    }

private:
    [[nodiscard]] std::size_t plane_size() const noexcept {
        return static_cast<std::size_t>(size_.pixels());
    }

    SensorSize size_;
    int planes_;
    std::vector<std::int64_t> cells_;
};

}  // namespace evcorner
