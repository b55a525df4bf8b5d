#include "evcorner/event_check.hpp"

#include <string>

namespace evcorner {

namespace {

std::string describe(const Event& e, const EventLimits& l, std::size_t index) {
    std::string s = "event";
    if (index != InvalidEvent::kNoIndex) {
        s += ' ';
        s += std::to_string(index);
    }
    s.append(" (t=").append(std::to_string(e.t)).append(" x=").append(std::to_string(e.x));
    s.append(" y=").append(std::to_string(e.y)).append(" p=").append(std::to_string(e.p)).append(")");
    const std::string sensor = std::to_string(l.size.width) + "x" + std::to_string(l.size.height) + " sensor";
    if (e.x >= l.size.width || e.y >= l.size.height) {
        s += " is off the " + sensor + " (x must be < " + std::to_string(l.size.width) + ", y < " +
             std::to_string(l.size.height) + ")";
    } else if (e.p > 1) {
        s += " has polarity " + std::to_string(e.p) + " (0 or 1 expected) on the " + sensor;
    } else {
        s += " has a time outside " + std::to_string(l.t_min) + ".." + std::to_string(l.t_max) +
             " us, which the detector cannot hold (" + sensor + ")";
    }
    return s;
}

}  // namespace

InvalidEvent::InvalidEvent(const Event& e, const EventLimits& limits, std::size_t index)
    : std::invalid_argument(describe(e, limits, index)), event_(e), index_(index), sensor_(limits.size) {}

}  // namespace evcorner
