#include "evcorner/io/open.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "evcorner/error.hpp"
#include "evcorner/io/aedat2_reader.hpp"
#include "evcorner/io/aedat4_reader.hpp"
#include "evcorner/io/csv_reader.hpp"
#include "evcorner/io/dat_reader.hpp"
#include "evcorner/io/evt2_reader.hpp"
#include "evcorner/io/evt3_reader.hpp"
#include "evcorner/io/hdf5_events.hpp"
#include "evcorner/io/npy.hpp"
#include "evcorner/io/prophesee_header.hpp"
#include "evcorner/io/ros_bag.hpp"
#include "evcorner/io/text_reader.hpp"

namespace evcorner::io {

namespace {

// Past this many bytes a header is not a header: decide with what was seen.
constexpr std::size_t kMaxHead = std::size_t{1} << 16;

struct Signature {
    std::string_view magic;
    std::string_view format;
    std::string_view what;
};
constexpr std::array<Signature, 4> kSignatures = {{
    {"#!AER-DAT2.0", "aedat2", "AEDAT 2.0"},
    {kAedat4Magic, "aedat4", "AEDAT 4.0"},
    {kHdf5Magic, "hdf5", "HDF5"},
    {"\x93NUMPY", "npy", ".npy"},
}};

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

// Peeks at growing amounts until `enough` says the head decides the format, the input
// ends, or kMaxHead bytes were seen. Returns the head and whether it is the whole input.
template <class Enough>
std::pair<std::string_view, bool> head_until(InputFile& file, Enough enough) {
    for (std::size_t want = 256;; want *= 4) {
        const std::string_view head = file.peek(want);
        const bool whole = head.size() < want;
        if (whole || want >= kMaxHead || enough(head)) return {head, whole};
    }
}

// The '%' header lines complete in `head`, and whether the header ended inside it.
struct ParsedHeader {
    PropheseeHeader h;
    bool done = false;
};
ParsedHeader parse_percent_header(std::string_view head) {
    ParsedHeader r;
    std::size_t pos = 0;
    while (pos < head.size() && head[pos] == '%' && !r.h.ended) {
        const auto nl = head.find('\n', pos);
        if (nl == std::string_view::npos) return r;
        r.h.add_line(head.substr(pos, nl - pos));
        pos = nl + 1;
    }
    r.done = r.h.ended || pos < head.size();
    return r;
}

// True when the first line that is not a comment is complete in `head`; `comma`: it has one.
bool first_data_line(std::string_view head, bool& comma) {
    std::size_t pos = 0;
    while (pos < head.size()) {
        const auto nl = head.find('\n', pos);
        const std::string_view line = head.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
        const auto first = line.find_first_not_of(" \t\r");
        if (first != std::string_view::npos && line[first] != '#') {
            comma = line.find(',') != std::string_view::npos;
            return nl != std::string_view::npos;
        }
        if (nl == std::string_view::npos) return false;
        pos = nl + 1;
    }
    return false;
}

}  // namespace

std::string detect_format(InputFile& file) {
    constexpr std::size_t kLongest = 16;  // covers every signature
    const std::string_view start = file.peek(kLongest);
    if (const std::string_view bag = detect_bag_format(start); !bag.empty()) return std::string(bag);
    for (const Signature& s : kSignatures)
        if (starts_with(start, s.magic)) return std::string(s.format);
    if (start.size() < kLongest && start.size() >= 2) {
        // The whole input is a few bytes that begin a signature: a file cut short.
        std::string what;
        for (const Signature& s : kSignatures)
            if (starts_with(s.magic, start)) what += (what.empty() ? "" : " or ") + std::string(s.what);
        if (!what.empty())
            throw InputError(file.name(), InputError::Unit::byte, start.size(),
                             fmt::format("the file ends inside the {} signature: it is cut short", what));
    }
    if (starts_with(start, "%")) {
        // Prophesee: the '%' header names the encoding (RAW) or says "Data file" (DAT).
        const auto [head, whole] = head_until(file, [](std::string_view h) { return parse_percent_header(h).done; });
        const ParsedHeader p = parse_percent_header(head);
        const PropheseeHeader& h = p.h;
        if (h.is_dat) return "dat";
        if (h.evt == "3.0") return "evt3";
        if (h.evt == "2.0") return "evt2";
        if (!h.evt.empty())
            throw InputError(file.name(),
                             "Prophesee RAW encoding EVT " + h.evt + " is not supported (EVT 2.0 and 3.0 are)");
        if (whole && !p.done)
            throw InputError(file.name(), InputError::Unit::byte, head.size(),
                             "the file ends inside its '%' header, before a line naming the encoding "
                             "('% evt' or '% format'): it is cut short");
        throw InputError(file.name(), "a '%' header without an 'evt' or 'format' line: pass --format evt2, evt3 or dat");
    }
    // Text: CSV when the first line that is not a comment has a comma.
    bool comma = false;
    const auto [head, whole] = head_until(file, [&](std::string_view h) { return first_data_line(h, comma); });
    first_data_line(head, comma);
    return comma ? "csv" : "ecd-text";
}

std::string detect_format(const std::string& path) {
    InputFile file(path);
    return detect_format(file);
}

std::unique_ptr<EventReader> open_event_reader(const std::string& path, ReaderOptions options,
                                               std::string_view format) {
    // A folder is a rosbag2 bag (metadata.yaml and its .db3 / .mcap files).
    if (std::error_code ec; std::filesystem::is_directory(path, ec)) return open_bag_reader(path, std::move(options), format);
    InputFile file(path);
    std::string fmt_name(format);
    if (fmt_name == "auto") fmt_name = detect_format(file);
    constexpr std::array<std::string_view, 12> kNames = {"ecd-text", "text", "csv", "npy",  "aedat2", "aedat",
                                                         "aedat4",   "evt2", "evt3", "dat", "hdf5",   "h5"};
    if (std::find(kNames.begin(), kNames.end(), fmt_name) == kNames.end() && !is_bag_format(fmt_name))
        throw InputError(file.name(), "unknown input format '" + fmt_name + "' (known: " + std::string(kInputFormats) + ")");
    if (!options.aedat2_chip.empty() && fmt_name != "aedat2" && fmt_name != "aedat")
        throw std::invalid_argument(file.name() + ": a camera chip (--chip) names the address layout of an "
                                    "AEDAT 2.0 file; this file is " + fmt_name);
    if (!options.topic.empty() && !is_bag_format(fmt_name))
        throw std::invalid_argument(file.name() + ": a topic (--topic) names what to read in a ROS bag; this file is " +
                                    fmt_name);
    // Bags are read by seeking: the reader opens the path itself.
    if (is_bag_format(fmt_name)) return open_bag_reader(path, std::move(options), fmt_name);
    if (fmt_name == "ecd-text" || fmt_name == "text") {
        if (!options.sensor) options.sensor = options.fallback_sensor;
        return std::make_unique<TextReader>(std::move(file), std::move(options));
    }
    if (fmt_name == "aedat2" || fmt_name == "aedat") return std::make_unique<Aedat2Reader>(std::move(file), std::move(options));
    if (fmt_name == "aedat4") return std::make_unique<Aedat4Reader>(std::move(file), std::move(options));
    if (fmt_name == "hdf5" || fmt_name == "h5") {
        // The HDF5 library seeks, and opens the file by its path: only a regular file will do.
        if (path == "-" || !file.size())
            throw InputError(file.name(), "HDF5 is read by seeking in a regular file; a pipe or standard input "
                                          "cannot be read as HDF5 (save it to a file first)");
        return std::make_unique<Hdf5Reader>(path, std::move(options));
    }
    if (fmt_name == "csv") return std::make_unique<CsvReader>(std::move(file), std::move(options));
    if (fmt_name == "evt3") return std::make_unique<Evt3Reader>(std::move(file), std::move(options));
    if (fmt_name == "evt2") return std::make_unique<Evt2Reader>(std::move(file), std::move(options));
    if (fmt_name == "npy") return std::make_unique<NpyReader>(std::move(file), std::move(options));
    return std::make_unique<DatReader>(std::move(file), std::move(options));
}

}  // namespace evcorner::io
