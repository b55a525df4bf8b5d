#include "evcorner/io/memory_reader.hpp"

#include <algorithm>
#include <utility>

namespace evcorner::io {

MemoryReader::MemoryReader(std::span<const Event> events, std::optional<SensorSize> sensor, std::string name)
    : events_(events), sensor_(sensor), name_(std::move(name)) {}

std::size_t MemoryReader::read(std::span<Event> out) {
    const std::size_t n = std::min(out.size(), events_.size() - next_);
    std::copy_n(events_.begin() + static_cast<std::ptrdiff_t>(next_), n, out.begin());
    next_ += n;
    return n;
}

}  // namespace evcorner::io
