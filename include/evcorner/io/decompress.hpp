#pragma once
// Streaming decompression of gzip, zstd, bzip2 and xz data, told by their magic bytes
// (never by a file name's extension). InputFile::decompress() puts a Decompressor between
// the file and its readers, so every byte-stream reader (text, CSV) reads compressed files
// unchanged, in constant memory.

#include <cstddef>
#include <memory>
#include <optional>
#include <string_view>

namespace evcorner::io {

enum class Compression { gzip, zstd, bzip2, xz };

/// The compression whose magic bytes `head` starts with: gzip 1f 8b, zstd 28 b5 2f fd,
/// bzip2 "BZh1".."BZh9", xz fd "7zXZ" 00. nullopt when none (or `head` is too short to tell).
std::optional<Compression> compression_from_magic(std::string_view head) noexcept;
/// "gzip", "zstd", "bzip2", "xz".
std::string_view compression_name(Compression c) noexcept;

/// One compressed stream (one gzip member, zstd frame sequence, bzip2 or xz stream),
/// decompressed step by step. step() consumes input from [in, in_end) and produces output
/// into [out, out_end), advancing both pointers; it returns true once the stream's end
/// was decoded. Damaged data throws std::runtime_error with the codec's reason.
class Decompressor {
public:
    static std::unique_ptr<Decompressor> make(Compression c);
    virtual ~Decompressor() = default;
    virtual bool step(const char*& in, const char* in_end, char*& out, char* out_end) = 0;
    [[nodiscard]] virtual Compression kind() const noexcept = 0;
};

}  // namespace evcorner::io
