#pragma once
// The body of the ROS bag fuzz targets: the input bytes are read in memory as a bag of
// `format` (open_bag_bytes: the containers read by seeking, SQLite from an image), to
// the end in small batches. The first byte's low bit picks skip_invalid; its second bit
// reads the topic "/caer/events" (the seeds' second event topic) instead of the default.
// InputError is the only exception allowed.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "evcorner/error.hpp"
#include "evcorner/io/ros_bag.hpp"

namespace evcorner::fuzz {

inline int run_bag(const std::uint8_t* data, std::size_t size, const char* format) {
    io::ReaderOptions options;
    options.fallback_sensor = std::nullopt;
    options.skip_invalid = size > 0 && (data[0] & 1) != 0;
    if (size > 0 && (data[0] & 2) != 0) options.topic = "/caer/events";
    std::vector<Event> buf(1024);
    try {
        const auto reader = io::open_bag_bytes(std::span<const unsigned char>(data, size), format, options);
        for (;;) {
            const std::size_t n = reader->read(buf);
            if (n == 0 && reader->skipped_in_batch().empty()) break;
        }
        (void)reader->topics();
    } catch (const InputError&) {
    }
    return 0;
}

}  // namespace evcorner::fuzz
