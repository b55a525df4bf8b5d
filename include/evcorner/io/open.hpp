#pragma once
// Opening an event file of any supported format: the format is told by the content
// (magic bytes, header), or forced by name.

#include <memory>
#include <string>
#include <string_view>

#include "evcorner/io/event_reader.hpp"

namespace evcorner::io {

/// The format names open_event_reader() accepts, besides "auto".
inline constexpr std::string_view kInputFormats = "ecd-text, csv, npy, aedat2, aedat4, evt2, evt3, dat, hdf5";

/// Tells the format of `path` from its first bytes: "aedat2" ("#!AER-DAT2.0"), "aedat4"
/// ("#!AER-DAT4.0\r\n"), "hdf5" (the HDF5 signature at byte 0), "npy",
/// "evt2" / "evt3" (a Prophesee '%' header with "% evt 2.0|3.0" or "% format EVT2|EVT3"),
/// "dat" ("% Data file containing ..."), "csv" (the first non-comment line has a
/// comma), else "ecd-text". Throws InputError for a
/// Prophesee header that names no supported encoding. Standard input ("-") is always
/// "ecd-text" unless forced.
std::string detect_format(const std::string& path);

/// Opens `path` ("-" = standard input) with the reader of `format` ("auto": detect).
/// Formats without sensor metadata (text, files whose header has no geometry) validate
/// against options.sensor, else options.fallback_sensor (the DAVIS240C's 240x180
/// unless changed). Throws InputError.
std::unique_ptr<EventReader> open_event_reader(const std::string& path, ReaderOptions options = {},
                                               std::string_view format = "auto");

}  // namespace evcorner::io
