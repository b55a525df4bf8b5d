#pragma once
// Reader for Prophesee RAW files in the EVT 2.0 encoding: '%' header lines (see
// prophesee_header.hpp), then 32-bit little-endian words, type = bits 31..28:
//   0x0 CD_OFF, 0x1 CD_ON: t_lsb = bits 27..22, x = bits 21..11, y = bits 10..0;
//   0x8 EV_TIME_HIGH: bits 27..0 = t >> 6;
//   0xA EXT_TRIGGER, 0xE OTHERS, 0xF CONTINUED and unknown types are skipped.
// An event's time is (time_high << 6) | t_lsb microseconds; the 34-bit time wraps
// every 4.8 hours and the wrap is unrolled. A CD event before the first
// EV_TIME_HIGH has no time and is an error.

#include <string>

#include "evcorner/io/binary_reader.hpp"

namespace evcorner::io {

class Evt2Reader final : public BinaryReader {
public:
    /// Reads `file` from its first unread byte and parses its header. Throws InputError.
    explicit Evt2Reader(InputFile file, ReaderOptions options = {});
    /// Opens `path` and parses its header. Throws InputError.
    explicit Evt2Reader(std::string path, ReaderOptions options = {})
        : Evt2Reader(InputFile(std::move(path)), std::move(options)) {}

    [[nodiscard]] std::string_view format() const noexcept override { return "evt2"; }
    /// Words of other types (triggers, OTHERS, unknown) skipped so far.
    [[nodiscard]] std::uint64_t other_words() const noexcept { return other_words_; }

private:
    bool decode() override;

    std::uint64_t other_words_ = 0;
    std::int64_t time_high_ = -1;  // (t >> 6) with wraps unrolled; -1 before the first
    std::uint32_t last_raw_high_ = 0;
};

}  // namespace evcorner::io
