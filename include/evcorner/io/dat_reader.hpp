#pragma once
// Reader for Prophesee DAT files (the "Event2d" / "EventCD" files of the Prophesee
// and ATIS tools, e.g. N-CARS): '%' header lines ("% Data file containing Event2d
// events.", "% Version 2", optional "% Width"/"% Height"/"% geometry"), then one byte
// event type (0x00 Event2d, 0x0C EventCD) and one byte event size (8), then
// little-endian records { uint32 t [us], uint32 d } with x = d & 0x3FFF,
// y = (d >> 14) & 0x3FFF, polarity = d >> 28 (0 or 1). The 32-bit time wraps every
// 71.6 minutes; the wrap is unrolled. Without a geometry in the header the sensor is
// ReaderOptions::fallback_sensor.

#include <string>

#include "evcorner/io/binary_reader.hpp"

namespace evcorner::io {

class DatReader final : public BinaryReader {
public:
    /// Reads `file` from its first unread byte and parses its header. Throws InputError.
    explicit DatReader(InputFile file, ReaderOptions options = {});
    /// Opens `path` and parses its header. Throws InputError.
    explicit DatReader(std::string path, ReaderOptions options = {})
        : DatReader(InputFile(std::move(path)), std::move(options)) {}

    [[nodiscard]] std::string_view format() const noexcept override { return "dat"; }
    [[nodiscard]] int event_type() const noexcept { return event_type_; }

private:
    bool decode() override;

    int event_type_ = 0;
    Unwrap32 unwrap_;  // the 32-bit time counter
};

}  // namespace evcorner::io
