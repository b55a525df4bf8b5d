#pragma once
// A buffered output file, or standard output for the path "-".
// A file is written through a PendingFile (pending_file.hpp): under a temporary name,
// renamed onto its own name by close(); an OutputFile destroyed without close() leaves
// nothing under the name (and the old file, if any, untouched). Standard output and
// special files (/dev/null, FIFOs) are written directly.
// Data reaches the file only in the pieces handed to write(); callers hand whole
// records, so a stream cut short by an error still ends on a record boundary.

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace evcorner::io {

class PendingFile;

class OutputFile {
public:
    /// Creates `path` ("-" = standard output). Throws OutputError.
    explicit OutputFile(std::string path);
    /// Without close(): a file is removed (its temporary name), standard output or a
    /// special file gets the buffered data, errors swallowed. Call close() to see errors.
    ~OutputFile();
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;

    /// Appends bytes; flushes when the buffer is full. Throws OutputError.
    void write(std::string_view bytes);
    /// Room for direct formatting: returns a pointer to at least n free bytes.
    char* reserve(std::size_t n);
    /// Commits n bytes written at the pointer reserve() returned.
    void commit(std::size_t n) noexcept { used_ += n; }
    /// Flushes, then overwrites bytes at `offset` from the start (a header completed at
    /// the end). Needs a seekable file: fails on standard output to a pipe. Throws OutputError.
    void write_at(std::uint64_t offset, std::string_view bytes);

    void flush();
    /// Flushes and closes (puts a file under its name); throws OutputError on failure
    /// ("write failed: reason"). Idempotent.
    void close();

    /// The path given, or "<stdout>".
    [[nodiscard]] const std::string& name() const noexcept { return name_; }

private:
    void grow(std::size_t n);  // a buffer of n bytes; the old one must be empty

    std::string name_;
    int fd_ = -1;
    std::unique_ptr<PendingFile> file_;  // null for standard output
    // Left uninitialised (make_unique_for_overwrite): a short output touches only the
    // pages it writes, not the whole megabyte (256 page faults and ~1 M instructions).
    std::unique_ptr<char[]> buf_;
    std::size_t cap_ = 0;
    std::size_t used_ = 0;
};

}  // namespace evcorner::io
