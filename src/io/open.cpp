#include "evcorner/io/open.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "evcorner/error.hpp"
#include "evcorner/io/aedat2_reader.hpp"
#include "evcorner/io/aedat4_reader.hpp"
#include "evcorner/io/atis_reader.hpp"
#include "evcorner/io/csv_reader.hpp"
#include "evcorner/io/dat_reader.hpp"
#include "evcorner/io/formats.hpp"
#include "evcorner/io/evt2_reader.hpp"
#include "evcorner/io/evt3_reader.hpp"
#include "evcorner/io/hdf5_events.hpp"
#include "evcorner/io/line_source.hpp"
#include "evcorner/io/mat_reader.hpp"
#include "evcorner/io/npy.hpp"
#include "evcorner/io/prophesee_header.hpp"
#include "evcorner/io/ros_bag.hpp"
#include "evcorner/io/text_reader.hpp"

namespace evcorner::io {

namespace {

// Past this many bytes a header is not a header: decide with what was seen.
constexpr std::size_t kMaxHead = std::size_t{1} << 16;

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

// The format whose magic (formats.hpp) `head` starts with; nullptr when none.
const InputFormat* by_magic(std::string_view head) noexcept {
    for (const InputFormat& f : input_formats())
        for (const std::string_view m : f.magic)
            if (!m.empty() && starts_with(head, m)) return &f;
    return nullptr;
}

// A format's title up to its first ':', ',' or " (": "AEDAT 2.0", "ROS 2 bag".
std::string_view short_title(const InputFormat& f) noexcept {
    return f.title.substr(0, std::min({f.title.find(':'), f.title.find(','), f.title.find(" (")}));
}

// Files told by their first bytes that no reader takes ("unsupported format: this looks
// like WHAT", with the hint). Checked in order; `offset` is where the magic stands.
struct Magic {
    std::size_t offset;
    std::string_view magic;
    std::string_view what;
    std::string_view hint;
};
constexpr std::string_view kAny = "";
const Magic kMagics[] = {
    {0, "#ROSBAG", "a ROS bag of an unknown version", kAny},
    {0, "#!AER-DAT3", "an AEDAT 3.x file", "AEDAT 2.0 and 4.0 are read; convert it with the DV software"},
    {0, "#!AER-DAT", "an AEDAT file of an unknown version", "AEDAT 2.0 and 4.0 are read"},
    {0, "Event Stream", "an Event Stream (.es) file", kAny},
    {0, std::string_view("PK\x03\x04", 4), "a zip archive (a .npz?)",
     "unzip it and pass the .npy or text file inside"},
    {0, std::string_view("PK\x05\x06", 4), "an empty zip archive", kAny},
    {0, std::string_view("\x89PNG\r\n\x1a\n", 8), "a PNG image", kAny},
    {0, std::string_view("\xff\xd8\xff", 3), "a JPEG image", kAny},
    {0, "GIF8", "a GIF image", kAny},
    {0, std::string_view("II*\0", 4), "a TIFF image", kAny},
    {0, std::string_view("MM\0*", 4), "a TIFF image", kAny},
    {0, "%PDF-", "a PDF document", kAny},
    {0, std::string_view("\x7f" "ELF", 4), "an ELF executable or library", kAny},
    {0, std::string_view("7z\xbc\xaf\x27\x1c", 6), "a 7-Zip archive", kAny},
    {0, std::string_view("Rar!\x1a\x07", 6), "a RAR archive", kAny},
    {0, std::string_view("\x04\x22\x4d\x18", 4), "an LZ4 frame (compressed data)",
     "decompress it first (lz4 -d); gzip, zstd, bzip2 and xz are read directly"},
    {0, "PAR1", "an Apache Parquet file", kAny},
    {257, "ustar", "a tar archive", "extract it and pass the event file inside"},
    {4, "ftyp", "an MP4/MOV video", kAny},
};

// Thrown for a file no reader takes: what it looks like, never its raw bytes.
[[noreturn]] void unsupported(const InputFile& file, std::string_view what, std::string_view hint) {
    throw InputError(file.name(), "unsupported format: this looks like " + std::string(what) +
                                      (hint.empty() ? std::string() : " (" + std::string(hint) + ")") +
                                      "; evcorner reads " + input_format_names());
}

// Whether `head` can be the start of a text file: no NUL byte, and few other control
// bytes (a stray escape sequence in a text file is the text parser's to report, escaped).
bool looks_like_text(std::string_view head) {
    std::size_t control = 0;
    for (const char ch : head) {
        const auto c = static_cast<unsigned char>(ch);
        if (c == 0) return false;
        if (c < 0x20 && c != '\n' && c != '\r' && c != '\t' && c != '\f' && c != '\v') ++control;
    }
    return control < 4 || control * 16 <= head.size();
}

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
    // (A later peek() may move the bytes: `start` is taken again after each.)
    std::string_view start = file.peek(kLongest);
    if (const InputFormat* f = by_magic(file.peek(64))) return std::string(f->name);
    start = file.peek(kLongest);
    if (!file.compression()) {
        if (const auto c = compression_from_magic(start)) {
            // Compressed: text and CSV inside are read through the decompressor.
            file.decompress(*c);
            const std::string_view codec = compression_name(*c);
            std::string inner;
            try {
                inner = detect_format(file);
            } catch (const InputError& e) {
                // Say that the message is about the data inside the compressed file.
                std::string why = e.what();
                if (starts_with(why, file.name() + ": ")) why.erase(0, file.name().size() + 2);
                constexpr std::string_view kLooks = "unsupported format: this looks like ";
                if (starts_with(why, "byte ")) why.insert(0, "compressed ");  // the decompressor's own
                else if (starts_with(why, kLooks)) why.insert(kLooks.size(), std::string(codec) + "-compressed data holding ");
                else why = "in the " + std::string(codec) + "-compressed data: " + why;
                throw InputError(file.name(), why);
            }
            if (inner != "ecd-text" && inner != "csv")
                unsupported(file, fmt::format("{}-compressed {} data", codec, inner),
                            fmt::format("only text and CSV are read compressed; decompress it first"));
            return inner;
        }
    }
    start = file.peek(kLongest);
    if (start.size() < kLongest && start.size() >= 2) {
        // The whole input is a few bytes that begin a signature: a file cut short.
        std::string what;
        for (const InputFormat& f : input_formats())
            for (const std::string_view m : f.magic)
                if (!m.empty() && starts_with(m, start)) {
                    what.append(what.empty() ? "" : " or ").append(short_title(f));
                    break;
                }
        if (!what.empty())
            throw InputError(file.name(), InputError::Unit::byte, start.size(),
                             fmt::format("the file ends inside the {} signature: it is cut short", what));
    }
    {
        const std::string_view head = file.peek(512);
        for (const Magic& m : kMagics) {
            if (head.size() < m.offset + m.magic.size() || head.substr(m.offset, m.magic.size()) != m.magic) continue;
            unsupported(file, m.what, m.hint);
        }
        if (starts_with(head, "\xff\xfe") || starts_with(head, "\xfe\xff"))
            unsupported(file, "UTF-16 text", "save it as UTF-8 or ASCII");
        // ATIS .bin has no magic: the name's extension, then the records' plausibility.
        const std::string_view n = file.name();
        if (!file.compression() && n.size() >= 4 && (n.substr(n.size() - 4) == ".bin" || n.substr(n.size() - 4) == ".BIN") &&
            looks_like_atis(n, file.peek(5 * 4096), file.size()))
            return "atis-bin";
    }
    start = file.peek(kLongest);
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
                             "Prophesee RAW encoding EVT " + quote_bytes(h.evt) + " is not supported (EVT 2.0 and 3.0 are)");
        if (whole && !p.done)
            throw InputError(file.name(), InputError::Unit::byte, head.size(),
                             "the file ends inside its '%' header, before a line naming the encoding "
                             "('% evt' or '% format'): it is cut short");
        throw InputError(file.name(), "a '%' header without an 'evt' or 'format' line: pass --format evt2, evt3 or dat");
    }
    // Text: CSV when the first line that is not a comment has a comma.
    bool comma = false;
    auto [head, whole] = head_until(file, [&](std::string_view h) {
        if (starts_with(h, "\xEF\xBB\xBF")) h.remove_prefix(3);  // a UTF-8 BOM
        return first_data_line(h, comma);
    });
    if (!looks_like_text(head.substr(0, 4096))) {
        std::string hint;
        const std::string_view n = file.name();
        if (n.size() >= 4 && (n.substr(n.size() - 4) == ".bin" || n.substr(n.size() - 4) == ".BIN"))
            hint = "a .bin file whose first records are not ATIS events in time order; --format atis-bin reads it anyway";
        else if (!file.compression())
            hint = "ATIS .bin data (N-MNIST, N-Caltech101) has no signature: --format atis-bin reads it";
        unsupported(file, "binary data of no known kind (not text, no known signature)", hint);
    }
    if (starts_with(head, "\xEF\xBB\xBF")) head.remove_prefix(3);
    first_data_line(head, comma);
    return comma ? "csv" : "ecd-text";
}

std::string detect_format(const std::string& path) {
    InputFile file(path);
    return detect_format(file);
}

std::span<const std::string_view> input_file_extensions() noexcept {
    static const std::vector<std::string_view> extensions = [] {
        std::vector<std::string_view> all;
        for (const InputFormat& f : input_formats()) {
            std::string_view e = f.extensions;
            while (!e.empty()) {
                const auto sp = e.find(' ');
                const std::string_view one = e.substr(0, sp);
                if (std::find(all.begin(), all.end(), one) == all.end()) all.push_back(one);
                e.remove_prefix(sp == std::string_view::npos ? e.size() : sp + 1);
            }
        }
        return all;
    }();
    return extensions;
}

std::span<const std::string_view> input_compression_extensions() noexcept {
    static constexpr std::array<std::string_view, 4> kExtensions = {".gz", ".zst", ".bz2", ".xz"};
    return kExtensions;
}

bool is_event_input_path(const std::filesystem::path& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) return std::filesystem::is_regular_file(path / "metadata.yaml", ec);
    const auto lower_extension = [](const std::filesystem::path& p) {
        std::string e = p.extension().string();
        for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        return e;
    };
    const auto listed = [](std::span<const std::string_view> list, const std::string& e) {
        return std::find(list.begin(), list.end(), e) != list.end();
    };
    const std::string ext = lower_extension(path);
    if (listed(input_file_extensions(), ext)) return true;
    if (!listed(input_compression_extensions(), ext)) return false;
    const std::string inner = lower_extension(path.stem());
    return inner == ".txt" || inner == ".csv";
}

std::unique_ptr<EventReader> open_event_reader(const std::string& path, ReaderOptions options,
                                               std::string_view format) {
    // A folder is a rosbag2 bag (metadata.yaml and its .db3 / .mcap files), and so is the
    // folder of a rosbag2 metadata.yaml given itself.
    if (std::error_code ec; std::filesystem::is_directory(path, ec)) return open_bag_reader(path, std::move(options), format);
    if (const std::filesystem::path p(path); p.filename() == "metadata.yaml" && (format == "auto" || format == "rosbag2")) {
        std::error_code ec;
        if (std::filesystem::is_regular_file(p, ec))
            return open_bag_reader(p.has_parent_path() ? p.parent_path().string() : std::string("."), std::move(options),
                                   format);
    }
    InputFile file(path);
    std::string fmt_name(format);
    if (fmt_name == "auto") fmt_name = detect_format(file);
    const InputFormat* f = find_input_format(fmt_name);
    if (f == nullptr)
        throw InputError(file.name(), "unknown input format '" + fmt_name + "' (known: " + input_format_names() + ")");
    check_reader_options(*f, options, file.name());
    if (f->compressed && !file.compression())
        if (const auto c = compression_from_magic(file.peek(8))) file.decompress(*c);  // a forced format
    return f->open(std::move(file), path, std::move(options));
}

}  // namespace evcorner::io
