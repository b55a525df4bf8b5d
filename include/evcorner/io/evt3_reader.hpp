#pragma once
// Reader for Prophesee RAW files in the EVT 3.0 encoding: '%' header lines (see
// prophesee_header.hpp), then 16-bit little-endian words, type = bits 15..12, that
// update a decoder state and emit events:
//   0x0 EVT_ADDR_Y   y = bits 10..0
//   0x2 EVT_ADDR_X   one event at x = bits 10..0, polarity = bit 11
//   0x3 VECT_BASE_X  base x = bits 10..0, polarity = bit 11
//   0x4 VECT_12      events at base x + i for each set bit i of bits 11..0; base x += 12
//   0x5 VECT_8       the same with bits 7..0; base x += 8
//   0x6 EVT_TIME_LOW  t bits 11..0;  0x8 EVT_TIME_HIGH  t bits 23..12
//   0x7 CONTINUED_4, 0xA EXT_TRIGGER, 0xE OTHERS, 0xF CONTINUED_12 and unknown types
//   are skipped.
// The 24-bit time wraps every 16.8 s: a TIME_HIGH more than half the range below the
// previous one is a wrap and is unrolled. TIME_HIGH words repeat with the same value
// (keep-alives); they do not advance time. An event before the first TIME_HIGH or
// ADDR_Y, or a vector before the first VECT_BASE_X, is an error.

#include <memory>
#include <string>

#include "evcorner/io/binary_reader.hpp"

namespace evcorner::io {

class Evt3Reader final : public BinaryReader {
public:
    /// Reads `file` from its first unread byte and parses its header. Throws InputError.
    explicit Evt3Reader(InputFile file, ReaderOptions options = {});
    ~Evt3Reader() override;
    /// Opens `path` and parses its header. Throws InputError.
    explicit Evt3Reader(std::string path, ReaderOptions options = {})
        : Evt3Reader(InputFile(std::move(path)), std::move(options)) {}

    [[nodiscard]] std::string_view format() const noexcept override { return "evt3"; }
    /// Words of other types (triggers, OTHERS, continued, unknown) skipped so far.
    [[nodiscard]] std::uint64_t other_words() const noexcept;

private:
    bool decode() override;
    struct Sink;

    // The word decoder's state (src/io/evt3_decoder.hpp), kept opaque here.
    struct DecoderBox;
    std::unique_ptr<DecoderBox> dec_;
};

}  // namespace evcorner::io
