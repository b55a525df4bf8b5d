#include "evcorner/io/open.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
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
#include "evcorner/io/text_reader.hpp"

namespace evcorner::io {

namespace {

// The first bytes of the file, enough to hold any header's format line.
std::string head_of(const std::string& path, std::size_t max_bytes) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return {};  // the reader reports why it cannot open the file
    std::string s(max_bytes, '\0');
    std::size_t got = 0;
    while (got < max_bytes) {
        const ssize_t n = ::read(fd, s.data() + got, max_bytes - got);
        if (n <= 0) break;
        got += static_cast<std::size_t>(n);
    }
    ::close(fd);
    s.resize(got);
    return s;
}

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

}  // namespace

std::string detect_format(const std::string& path) {
    // From a pipe, wait for no more than a header's worth of bytes.
    const std::string head = path == "-" ? std::string(peek_stdin(1 << 14)) : head_of(path, 1 << 16);
    if (starts_with(head, "#!AER-DAT2.0")) return "aedat2";
    if (starts_with(head, kAedat4Magic)) return "aedat4";
    if (starts_with(head, kHdf5Magic)) return "hdf5";
    if (starts_with(head, "\x93NUMPY")) return "npy";
    if (starts_with(head, "%")) {
        // Prophesee: the '%' header names the encoding (RAW) or says "Data file" (DAT).
        PropheseeHeader h;
        std::size_t pos = 0;
        while (pos < head.size() && head[pos] == '%' && !h.ended) {
            const auto nl = head.find('\n', pos);
            if (nl == std::string::npos) break;
            h.add_line(std::string_view(head).substr(pos, nl - pos));
            pos = nl + 1;
        }
        if (h.is_dat) return "dat";
        if (h.evt == "3.0") return "evt3";
        if (h.evt == "2.0") return "evt2";
        if (!h.evt.empty())
            throw InputError(path, "Prophesee RAW encoding EVT " + h.evt + " is not supported (EVT 2.0 and 3.0 are)");
        throw InputError(path, "a '%' header without an 'evt' or 'format' line: pass --format evt2, evt3 or dat");
    }
    // Text: CSV when the first line that is not a comment has a comma.
    std::size_t pos = 0;
    while (pos < head.size()) {
        auto nl = head.find('\n', pos);
        if (nl == std::string::npos) nl = head.size();
        const std::string_view line = std::string_view(head).substr(pos, nl - pos);
        const auto first = line.find_first_not_of(" \t\r");
        if (first != std::string_view::npos && line[first] != '#')
            return line.find(',') != std::string_view::npos ? "csv" : "ecd-text";
        pos = nl + 1;
    }
    return "ecd-text";
}

std::unique_ptr<EventReader> open_event_reader(const std::string& path, ReaderOptions options,
                                               std::string_view format) {
    std::string fmt_name(format);
    if (fmt_name == "auto") fmt_name = detect_format(path);
    if (fmt_name == "ecd-text" || fmt_name == "text") {
        if (!options.sensor) options.sensor = options.fallback_sensor;
        return std::make_unique<TextReader>(path, options);
    }
    if (fmt_name == "aedat2" || fmt_name == "aedat") return std::make_unique<Aedat2Reader>(path, options);
    if (fmt_name == "aedat4") return std::make_unique<Aedat4Reader>(path, options);
    if (fmt_name == "hdf5" || fmt_name == "h5") {
        if (path == "-") throw InputError("<stdin>", "HDF5 needs a file it can seek in; standard input cannot be read as HDF5");
        return std::make_unique<Hdf5Reader>(path, options);
    }
    if (fmt_name == "csv") return std::make_unique<CsvReader>(path, options);
    if (fmt_name == "evt3") return std::make_unique<Evt3Reader>(path, options);
    if (fmt_name == "evt2") return std::make_unique<Evt2Reader>(path, options);
    if (fmt_name == "npy") return std::make_unique<NpyReader>(path, options);
    if (fmt_name == "dat") return std::make_unique<DatReader>(path, options);
    throw InputError(path == "-" ? "<stdin>" : path,
                     "unknown input format '" + fmt_name + "' (known: " + std::string(kInputFormats) + ")");
}

}  // namespace evcorner::io
