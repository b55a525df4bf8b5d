#pragma once
// A file opened for reading in large blocks, or standard input for the path "-".
// The first bytes can be looked at before they are read (peek), so that a format is
// told from the content of a pipe as well as of a file: the input is opened once and
// every byte comes from the operating system once.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace evcorner::io {

class InputFile {
public:
    /// Opens `path` ("-" = standard input). Throws InputError when it cannot.
    explicit InputFile(std::string path);
    ~InputFile();
    InputFile(InputFile&& other) noexcept;
    InputFile(const InputFile&) = delete;
    InputFile& operator=(const InputFile&) = delete;
    InputFile& operator=(InputFile&&) = delete;

    /// Reads ahead until at least `n` bytes wait unread (fewer only at the end of the
    /// input) and returns all the unread bytes read ahead so far; read() hands them out
    /// first. On a pipe this waits for `n` bytes or the end. Throws InputError.
    std::string_view peek(std::size_t n);

    /// Reads up to buf.size() bytes; returns 0 only at end of file. Throws InputError.
    std::size_t read(std::span<char> buf);

    /// The name to show in messages ("<stdin>" for "-").
    [[nodiscard]] const std::string& name() const noexcept { return name_; }
    /// Size in bytes when the input is a regular file (nullopt: a pipe, a terminal, a
    /// device; such an input can only be read front to back).
    [[nodiscard]] std::optional<std::uint64_t> size() const noexcept { return size_; }
    /// Bytes handed out by read() so far (bytes only peeked at do not count).
    [[nodiscard]] std::uint64_t consumed() const noexcept { return consumed_; }

private:
    std::size_t read_fd(char* buf, std::size_t n);

    std::string name_;
    int fd_ = -1;
    bool owns_fd_ = false;
    std::optional<std::uint64_t> size_;
    std::uint64_t consumed_ = 0;
    std::string ahead_;           // bytes peeked at and not yet read
    std::size_t ahead_pos_ = 0;   // the first unread byte of ahead_
    bool eof_ = false;            // the descriptor reported the end
};

}  // namespace evcorner::io
