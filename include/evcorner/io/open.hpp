#pragma once
// Opening an event file of any supported format: the format is told by the content
// (magic bytes, header), or forced by name.

#include <memory>
#include <string>
#include <string_view>

#include "evcorner/io/event_reader.hpp"

namespace evcorner::io {

/// Opens `path` ("-" = standard input) with the reader of `format` ("auto": detect).
/// Formats without sensor metadata (text) validate against options.sensor, or the
/// DAVIS240C's 240x180 when it is unset. Throws InputError.
std::unique_ptr<EventReader> open_event_reader(const std::string& path, ReaderOptions options = {},
                                               std::string_view format = "auto");

}  // namespace evcorner::io
