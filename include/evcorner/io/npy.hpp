#pragma once
// numpy .npy files of events (format version 1.0): a one-dimensional array of the
// structured dtype
//   [('t','<i8'), ('x','<u2'), ('y','<u2'), ('p','u1'), ('_','V3')]
// which is evcorner::Event byte for byte (16 bytes, 3 padding bytes written as zero),
// so numpy.load() gives t in microseconds, x, y, p directly. The reader also takes the
// packed 13-byte form without the padding field, and 'p' stored as '|b1' (bool).

#include <cstdint>
#include <span>
#include <string>

#include "evcorner/io/binary_reader.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/output_file.hpp"

namespace evcorner::io {

class NpyWriter final : public EventWriter {
public:
    /// Creates `path` (a seekable file: the count goes in the header at close; not standard
    /// output). Throws OutputError.
    explicit NpyWriter(std::string path);
    ~NpyWriter() override;  ///< without close(): no file under the name
    void write(std::span<const Event> events) override;
    /// Writes the final event count into the header; throws OutputError.
    void close() override;
    [[nodiscard]] const std::string& name() const noexcept override { return out_.name(); }

private:
    OutputFile out_;
    std::uint64_t count_ = 0;
    bool closed_ = false;
};

/// Reads event .npy files. No sensor metadata: ReaderOptions::fallback_sensor applies.
class NpyReader final : public BinaryReader {
public:
    /// Reads `file` from its first unread byte and parses its header. Throws InputError.
    explicit NpyReader(InputFile file, ReaderOptions options = {});
    /// Opens `path` and parses its header. Throws InputError.
    explicit NpyReader(std::string path, ReaderOptions options = {})
        : NpyReader(InputFile(std::move(path)), std::move(options)) {}
    [[nodiscard]] std::string_view format() const noexcept override { return "npy"; }
    /// The array length the header declares.
    [[nodiscard]] std::uint64_t declared_events() const noexcept { return declared_; }

private:
    bool decode() override;
    std::uint64_t declared_ = 0;
    std::uint64_t read_ = 0;
    std::size_t itemsize_ = 16;
};

}  // namespace evcorner::io
