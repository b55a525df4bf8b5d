#pragma once
// numpy .npy files of events (format versions 1.0, 2.0, 3.0).
//
// Written: a one-dimensional array of the structured dtype
//   [('t','<i8'), ('x','<u2'), ('y','<u2'), ('p','u1'), ('_','V3')]
// which is evcorner::Event byte for byte (16 bytes, 3 padding bytes written as zero),
// so numpy.load() gives t in microseconds, x, y, p directly.
//
// Read (C order only; Fortran order is refused):
// - a one-dimensional structured array whose fields are found by name, in any order and
//   among other fields: time 't', 'ts', 'timestamp', 'time' or 't_us'; 'x'; 'y'; polarity
//   'p', 'polarity', 'pol' or 'on' (names compared case-insensitively). Each of them any
//   integer ('i1'..'i8', 'u1'..'u8'), float ('f4', 'f8') or bool ('b1') of either byte order;
// - a two-dimensional (N, 4) array of one such numeric type, its columns named by
//   ReaderOptions::npy_columns (default "t,x,y,p", the written layout's order).
// Time: integers are microseconds, floats seconds, unless ReaderOptions::csv_time_unit
// names the unit ("us", "ns", "ms", "s"); floats are rounded to the nearest microsecond
// (halves away from zero), but a float time with a fraction in a given unit of us or ns is
// an error (docs/formats.md, "Times").
// x and y must be integers 0..65535 (a float one must be integral); polarity 1 = ON,
// 0 or -1 = OFF (or bool). The evcorner layout (and its packed 13-byte form, 'p' as bool)
// is read by a copying fast path; every other layout converts each field column-wise.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/io/binary_reader.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/output_file.hpp"

namespace evcorner::io {

/// The 192-byte header (format 1.0) of a one-dimensional C-order array of `count` records
/// of dtype `descr` (a numpy descr literal, "[('t', '<i8'), ...]"): written first with a
/// count of 0 and rewritten at close, in place.
std::string npy_header(std::string_view descr, std::uint64_t count);

class NpyWriter final : public EventWriter {
public:
    /// Creates `path` (a seekable file: the count goes in the header at close; not standard
    /// output). Throws OutputError.
    /// with_score: records carry a score, the field ('score', '<f8') after the padding.
    explicit NpyWriter(std::string path, bool with_score = false);
    ~NpyWriter() override;  ///< without close(): no file under the name
    void write(std::span<const Event> events) override;
    void write(std::span<const Event> events, std::span<const double> scores) override;
    /// Writes the final event count into the header; throws OutputError.
    void close() override;
    [[nodiscard]] const std::string& name() const noexcept override { return out_.name(); }

private:
    OutputFile out_;
    std::uint64_t count_ = 0;
    bool with_score_;
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
    /// A structured array's field named 'score' (any numeric type), as doubles.
    [[nodiscard]] std::span<const double> scores_in_batch() const noexcept override {
        return has_score_ ? std::span<const double>(scores_.data(), batch_count()) : std::span<const double>();
    }

    /// One field of a record: where it is and its numpy type.
    struct Field {
        std::size_t offset = 0;
        char kind = 'i';  // 'i' signed, 'u' unsigned, 'f' float, 'b' bool
        int size = 8;
        bool swap = false;  // big-endian ('>')
    };

private:
    bool decode() override;
    bool decode_fast();
    bool decode_general();
    std::uint64_t declared_ = 0;
    std::uint64_t read_ = 0;
    std::size_t itemsize_ = 16;
    bool fast_ = true;
    Field fields_[4];         // t, x, y, p
    double time_scale_ = 1;   // float time * scale = us
    std::int64_t time_mul_ = 1, time_div_ = 1;  // integer time * mul / div = us
    bool whole_time_ = false;  // float times in us or ns (given): a fraction is an error
    // Column-wise conversion buffers of decode_general().
    std::vector<std::int64_t> ct_;
    std::vector<std::uint32_t> cx_, cy_, cp_;
    bool has_score_ = false;
    Field score_field_;
    std::vector<double> cs_, scores_;  // the score column; the batch's scores
};

}  // namespace evcorner::io
