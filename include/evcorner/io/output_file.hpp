#pragma once
// A buffered output file, or standard output for the path "-".
// Data reaches the file only in the pieces handed to write(); callers hand whole
// records, so a file cut short by an error still ends on a record boundary.

#include <string>
#include <string_view>
#include <vector>

namespace evcorner::io {

class OutputFile {
public:
    /// Creates or truncates `path` ("-" = standard output). Throws OutputError.
    explicit OutputFile(std::string path);
    ~OutputFile();  // flushes, swallowing errors; call close() to see them
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;

    /// Appends bytes; flushes when the buffer is full. Throws OutputError.
    void write(std::string_view bytes);
    /// Room for direct formatting: returns a pointer to at least n free bytes.
    char* reserve(std::size_t n);
    /// Commits n bytes written at the pointer reserve() returned.
    void commit(std::size_t n) noexcept { used_ += n; }

    void flush();
    /// Flushes and closes; throws OutputError on failure. Idempotent.
    void close();

    [[nodiscard]] const std::string& name() const noexcept { return name_; }

private:
    std::string name_;
    int fd_ = -1;
    bool owns_fd_ = false;
    std::vector<char> buf_;
    std::size_t used_ = 0;
};

}  // namespace evcorner::io
