#pragma once
// Reader for jAER's AEDAT 2.0 files (iniVation / jAER, "AER-DAT2.0"): ASCII header lines
// starting with '#' (the first one "#!AER-DAT2.0"), then big-endian records
// { uint32 address, uint32 timestamp [us] }. The address layout depends on the camera,
// named by the "# AEChip:" header line:
//   DAVIS (DAVIS240A/B/C, DAVIS346, DAVIS128, DAVIS208, DAVIS640): polarity (DVS)
//     events have bit 31 = 0 and bit 10 = 0; x = bits 12..21, y = bits 22..30,
//     polarity = bit 11 (1 = ON). Bit 31 = 1 (APS samples, IMU samples) and bit 10 = 1
//     (external / special events) are skipped.
//   DVS128 (Tmpdiff128): x = bits 1..7, y = bits 8..14, ON iff bit 0 = 0; bit 15 = 1
//     (external events) is skipped.
// Coordinates are returned as stored (jAER displays them mirrored; no flip is applied).
// The 32-bit timestamp wraps every 71.6 minutes; the wrap is unrolled into int64.
//
// ReaderOptions::aedat2_chip names the camera instead of the header (a wrong or missing
// "# AEChip" line); ReaderOptions::sensor overrides the size, and a size above 128x128
// means the DAVIS layout whatever the header says. Unless the chip is given, the header's
// chip is checked against the data before any event is returned: when more than half of
// the first 4096 address words (DVS and special events; APS and IMU samples do not count)
// within the first 131 072 records (1 MiB) decode outside the sensor (for DVS128: have any
// of bits 16..31 set), or, for a DAVIS chip, more than half of at least 64 of them have
// only their low 16 bits set (DVS128 words), the constructor throws an InputError that
// says so and names --chip and --size. A header with no record after it is a file cut
// short.

#include <string>
#include <string_view>

#include "evcorner/io/binary_reader.hpp"

namespace evcorner::io {

class Aedat2Reader final : public BinaryReader {
public:
    enum class Layout { davis, dvs128 };

    /// Reads `file` from its first unread byte and parses its header. Throws InputError.
    explicit Aedat2Reader(InputFile file, ReaderOptions options = {});
    /// Opens `path` and parses its header. Throws InputError.
    explicit Aedat2Reader(std::string path, ReaderOptions options = {})
        : Aedat2Reader(InputFile(std::move(path)), std::move(options)) {}

    [[nodiscard]] std::string_view format() const noexcept override { return "aedat2"; }
    /// Whether `name` names a camera this reader knows (as in "# AEChip:" and aedat2_chip:
    /// DVS128, DAVIS128, DAVIS208, DAVIS240A/B/C, DAVIS346, DAVIS640, or jAER class names
    /// that contain them; case-insensitive).
    [[nodiscard]] static bool known_chip(std::string_view name);
    /// The "# AEChip:" header value ("" when absent).
    [[nodiscard]] const std::string& chip() const noexcept { return chip_; }
    [[nodiscard]] Layout layout() const noexcept { return layout_; }
    /// Address words skipped because they are not polarity events (APS, IMU, special).
    [[nodiscard]] std::uint64_t other_words() const noexcept { return other_words_; }

private:
    bool decode() override;
    void check_layout();

    std::string chip_;
    Layout layout_ = Layout::davis;
    std::uint64_t other_words_ = 0;
    Unwrap32 unwrap_;  // the 32-bit time counter
};

}  // namespace evcorner::io
