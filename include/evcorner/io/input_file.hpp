#pragma once
// A file opened for reading in large blocks, or standard input for the path "-".
// The first bytes can be looked at before they are read (peek), so that a format is
// told from the content of a pipe as well as of a file: the input is opened once and
// every byte comes from the operating system once.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/io/decompress.hpp"

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
    /// Bytes handed out by read() so far (bytes only peeked at do not count); once
    /// decompress() was called, the compressed bytes decoded so far (progress against size()).
    [[nodiscard]] std::uint64_t consumed() const noexcept { return decoder_ ? raw_used_ : consumed_; }

    /// From the first unread byte on, the input is a stream compressed with `c` (several
    /// concatenated streams too): peek() and read() hand out the decompressed bytes. A
    /// damaged stream, one cut short, or other data after its end throws InputError naming
    /// the compressed byte offset ("the gzip stream is cut short ..."). Call once.
    void decompress(Compression c);
    /// The compression decompress() was given, if any.
    [[nodiscard]] std::optional<Compression> compression() const noexcept {
        return decoder_ ? std::optional<Compression>(decoder_->kind()) : std::nullopt;
    }

private:
    std::size_t read_fd(char* buf, std::size_t n);
    std::size_t read_source(char* buf, std::size_t n);  // read_fd, or through the decoder
    std::size_t read_decoded(char* buf, std::size_t n);

    std::string name_;
    int fd_ = -1;
    bool owns_fd_ = false;
    std::optional<std::uint64_t> size_;
    std::uint64_t consumed_ = 0;
    std::string ahead_;           // bytes peeked at and not yet read
    std::size_t ahead_pos_ = 0;   // the first unread byte of ahead_
    bool eof_ = false;            // the descriptor reported the end

    // Decompression (decompress()): compressed bytes wait in raw_[raw_pos_, raw_fill_).
    std::unique_ptr<Decompressor> decoder_;
    std::vector<char> raw_;
    std::size_t raw_pos_ = 0, raw_fill_ = 0;
    std::uint64_t raw_used_ = 0;  // compressed bytes given to the decoder
    bool stream_ended_ = false;   // the decoder reported the end of a stream
    bool decoded_end_ = false;    // every stream decoded and the file ended
};

}  // namespace evcorner::io
