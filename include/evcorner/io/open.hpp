#pragma once
// Opening an event file of any supported format: the format is told by the content
// (magic bytes, header), or forced by name. The input is opened once: the bytes the
// format is told from are peeked at and then read by the reader, so pipes, FIFOs and
// process substitutions (`<(...)`) work like files.

#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/input_file.hpp"

namespace evcorner::io {

/// The file-name extensions of the event files open_event_reader() reads, lower case with
/// the dot: ".txt", ".csv", ".npy", ".aedat", ".aedat2", ".aedat4", ".raw" (EVT 2.0/3.0),
/// ".dat", ".h5", ".hdf5", ".bin" (ATIS), ".mat", ".bag" (ROS 1), ".db3" (rosbag2 SQLite),
/// ".mcap". For a program that picks event files out of a folder by name; the reader
/// itself tells the format by the content.
std::span<const std::string_view> input_file_extensions() noexcept;

/// The extensions of the compressions text and CSV are read through (".gz", ".zst",
/// ".bz2", ".xz"), after ".txt" or ".csv".
std::span<const std::string_view> input_compression_extensions() noexcept;

/// Whether `path` is, by its form, an input open_event_reader() reads: a folder holding
/// metadata.yaml (a rosbag2 bag), or a file whose extension (case-insensitive) is one of
/// input_file_extensions(), or ".txt"/".csv" followed by one of
/// input_compression_extensions(). Only names are looked at, never the contents.
bool is_event_input_path(const std::filesystem::path& path);

/// Tells the format of `file` from its first bytes, which it only peeks at
/// (InputFile::peek), so a reader given `file` afterwards reads them too: "aedat2"
/// ("#!AER-DAT2.0"), "aedat4" ("#!AER-DAT4.0\r\n"), "hdf5" (the HDF5 signature at byte 0),
/// "npy", "evt2" / "evt3" (a Prophesee '%' header with "% evt 2.0|3.0" or
/// "% format EVT2|EVT3"), "dat" ("% Data file containing ..."), "csv" (the first
/// non-comment line has a comma), else "ecd-text" (an empty input too). Looks at no more
/// than the header needs (at most 64 KiB), so a pipe is not waited on for more.
/// Throws InputError for a Prophesee header that names no supported encoding, and for an
/// input that ends inside a signature or a '%' header (cut short).
std::string detect_format(InputFile& file);

/// detect_format() of the file at `path`, opened for the purpose. What it reads from a
/// pipe is gone afterwards: use open_event_reader() to read one.
std::string detect_format(const std::string& path);

/// Opens `path` ("-" = standard input) with the reader of `format` ("auto": detect).
/// Formats without sensor metadata (text, files whose header has no geometry) validate
/// against options.sensor, else options.fallback_sensor (the DAVIS240C's 240x180
/// unless changed). The formats read by seeking (InputFormat::by_seeking: HDF5, .mat,
/// ROS bags) need a regular file; every other format reads front to back and works on a
/// pipe. The format's entry in input_formats() (formats.hpp) opens the reader.
/// Throws InputError; std::invalid_argument for a reader option the format does not take
/// (check_reader_options()).
std::unique_ptr<EventReader> open_event_reader(const std::string& path, ReaderOptions options = {},
                                               std::string_view format = "auto");

}  // namespace evcorner::io
