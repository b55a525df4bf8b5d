#pragma once
// The input formats evcorner reads, one entry each: its name and aliases, what it is, the
// file-name extensions it goes by, the bytes it is told by, whether it is read by seeking,
// the reader options it takes, and how it opens. open_event_reader() (open.hpp), --format's
// choices and help, eval FOLDER's walk and `info --formats` all read this table; adding a
// format is its reader and its entry in src/io/formats.cpp.
//
// The reader options (ReaderOptions fields set by the user) have a table too: the CLI flag,
// the Python keyword and the help of each, and which formats take it.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/input_file.hpp"

namespace evcorner::io {

/// A user-set reader option, as a bit of InputFormat::options.
enum ReaderOptionBit : std::uint32_t {
    kOptCsvColumns = 1u << 0,
    kOptTimeUnit = 1u << 1,
    kOptNpyColumns = 1u << 2,
    kOptChip = 1u << 3,
    kOptMatVar = 1u << 4,
    kOptMatColumns = 1u << 5,
    kOptTopic = 1u << 6,
};

struct InputFormat {
    std::string_view name;        ///< --format's name; what the reader's format() starts with
    std::string_view aliases;     ///< other names --format takes, space-separated ("" none)
    std::string_view title;       ///< what it is, one line
    std::string_view extensions;  ///< lower-case file-name extensions, space-separated
    /// First bytes the format is told by (up to two; "" none: told otherwise, see
    /// detect_format()).
    std::string_view magic[2];
    bool by_seeking = false;  ///< read from a regular file only (not standard input or a pipe)
    bool compressed = false;  ///< also read through gzip, zstd, bzip2 or xz
    std::uint32_t options = 0;  ///< the ReaderOptionBit options it takes
    /// Opens the reader: `file` is opened on `path` with the header only peeked at.
    std::unique_ptr<EventReader> (*open)(InputFile&& file, const std::string& path, ReaderOptions&& options) = nullptr;
};

/// Every input format, in the order --format's help lists them.
std::span<const InputFormat> input_formats() noexcept;
/// The format named `name` or one of its aliases; nullptr when none is.
const InputFormat* find_input_format(std::string_view name) noexcept;
/// The names, comma-separated ("ecd-text, csv, ..."), for messages and help.
const std::string& input_format_names();

struct ReaderOptionInfo {
    std::uint32_t bit;
    std::string_view flag;     ///< the CLI option, "--csv-columns"
    std::string_view keyword;  ///< the Python keyword, "csv_columns"
    std::string_view help;
    /// The option's value in `o`, "" when not set; and setting it.
    std::string (*get)(const ReaderOptions& o);
    void (*set)(ReaderOptions& o, std::string value);
};

/// Every user-set reader option.
std::span<const ReaderOptionInfo> reader_option_infos() noexcept;

/// Throws std::invalid_argument naming the file, the option and the format when `options`
/// sets an option that `format` does not take (a value that would silently do nothing).
/// The time unit is exempt: a folder or batch of mixed formats shares it.
void check_reader_options(const InputFormat& format, const ReaderOptions& options, const std::string& file_name);

}  // namespace evcorner::io
