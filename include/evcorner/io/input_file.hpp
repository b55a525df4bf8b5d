#pragma once
// A file opened for reading in large blocks, or standard input for the path "-".

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace evcorner::io {

/// The first bytes of standard input, read once and kept, so that a format can be told
/// from its content before a reader opens "-"; that reader then gets them first.
std::string_view peek_stdin(std::size_t max_bytes);

class InputFile {
public:
    /// Opens `path` ("-" = standard input). Throws InputError when it cannot.
    explicit InputFile(std::string path);
    ~InputFile();
    InputFile(const InputFile&) = delete;
    InputFile& operator=(const InputFile&) = delete;

    /// Reads up to buf.size() bytes; returns 0 only at end of file. Throws InputError.
    std::size_t read(std::span<char> buf);

    /// The name to show in messages ("<stdin>" for "-").
    [[nodiscard]] const std::string& name() const noexcept { return name_; }
    /// Size in bytes when the input is a regular file.
    [[nodiscard]] std::optional<std::uint64_t> size() const noexcept { return size_; }
    /// Bytes read so far.
    [[nodiscard]] std::uint64_t consumed() const noexcept { return consumed_; }

private:
    std::string name_;
    int fd_ = -1;
    bool owns_fd_ = false;
    std::optional<std::uint64_t> size_;
    std::uint64_t consumed_ = 0;
};

}  // namespace evcorner::io
