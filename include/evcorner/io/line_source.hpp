#pragma once
// The lines of a text file (or standard input), read in large blocks with constant
// memory: what the text-format readers (ECD text, CSV) share. A line is handed out
// without its line break and without a '\r' before it; the last line needs no break.
// Errors name the file and the 1-based line, quoting the offending text (unprintable bytes
// escaped). A UTF-8 byte order mark (EF BB BF) at the start of the input is skipped. The
// file may be decompressing (InputFile::decompress): a damaged or cut-short stream is an
// error at the line being read, naming the compressed byte offset.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "evcorner/io/input_file.hpp"

namespace evcorner::io {

/// `s` in single quotes for a message: at most `max` bytes ("..." after a cut), every
/// byte outside printable ASCII written as \xNN, so that no raw byte reaches a terminal.
std::string quote_bytes(std::string_view s, std::size_t max = 80);

class LineSource {
public:
    /// Reads the lines of `file` (from its first unread byte). A line longer than
    /// `buffer_bytes` is an error.
    explicit LineSource(InputFile file, std::size_t buffer_bytes = std::size_t{1} << 20)
        : file_(std::move(file)), buf_(buffer_bytes) {}
    /// Opens `path` ("-" = standard input). Throws InputError.
    explicit LineSource(std::string path, std::size_t buffer_bytes = std::size_t{1} << 20)
        : LineSource(InputFile(std::move(path)), buffer_bytes) {}

    /// The next line as [begin, end); false at the end of the input. Throws InputError.
    bool next(const char*& begin, const char*& end) {
        const char* data = buf_.data();
        const void* nl = std::memchr(data + pos_, '\n', fill_ - pos_);
        if (nl == nullptr) return next_after_refill(begin, end);
        begin = data + pos_;
        end = static_cast<const char*>(nl);
        pos_ = static_cast<std::size_t>(end - data) + 1;
        ++line_;
        if (end > begin && end[-1] == '\r') --end;
        return true;
    }

    /// Lines handed out so far: the number of the current line.
    [[nodiscard]] std::uint64_t line() const noexcept { return line_; }
    [[nodiscard]] const InputFile& file() const noexcept { return file_; }

    /// Throws InputError "FILE:LINE: reason: 'text'" for the current line [begin, end).
    [[noreturn]] void fail(const char* begin, const char* end, const std::string& reason) const;

private:
    bool next_after_refill(const char*& begin, const char*& end);
    void skip_bom();

    InputFile file_;
    std::vector<char> buf_;
    std::size_t pos_ = 0;   // start of the unread data in buf_
    std::size_t fill_ = 0;  // bytes valid in buf_
    bool eof_ = false;
    bool bom_checked_ = false;
    std::uint64_t line_ = 0;
};

}  // namespace evcorner::io
