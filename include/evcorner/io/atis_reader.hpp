#pragma once
// ATIS .bin files: N-MNIST and N-Caltech101 (Orchard et al., "Converting static image
// datasets to spiking neuromorphic datasets using saccades", Front. Neurosci. 2015).
// No header: 5-byte (40-bit) records, bits 39-32 x, 31-24 y, bit 23 polarity (1 = ON),
// bits 22-0 time in microseconds, i.e. bytes x, y, then p<<7 | t[22:16], t[15:8], t[7:0].
//
// Time: the 23-bit field wraps after 2^23 us (8.4 s). A record whose time is more than
// 2^22 us below the one before is the counter wrapping: 2^23 us is added from there on;
// any other step back is an error. The samples evcorner is tested on never wrap.
//
// Sensor: none recorded; options.sensor, else options.fallback_sensor (x and y are 8 bits:
// events are checked against 256x256 when neither is set).
//
// Detection: the format has no magic. open_event_reader() takes a file as ATIS when its
// name ends in ".bin", its size (when known) is a multiple of 5, and the first records
// (up to 4096) have time never going back, but for at most one wrap of the 23-bit
// counter (8.4 s apart: more in 4096 events is noise, not a recording): looks_like_atis(). `--format
// atis-bin` reads any input as ATIS.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "evcorner/io/binary_reader.hpp"

namespace evcorner::io {

class AtisReader final : public BinaryReader {
public:
    explicit AtisReader(InputFile file, ReaderOptions options = {});
    explicit AtisReader(std::string path, ReaderOptions options = {})
        : AtisReader(InputFile(std::move(path)), std::move(options)) {}
    [[nodiscard]] std::string_view format() const noexcept override { return "atis-bin"; }

private:
    bool decode() override;
    std::int64_t epoch_ = 0;      // 2^23 us times the wraps seen
    std::uint32_t last_raw_ = 0;  // the 23-bit time of the previous record
};

/// Whether `head` (the first bytes of a file named `name`, `size` bytes long if known) is
/// plausibly ATIS .bin: see the header comment.
bool looks_like_atis(std::string_view name, std::string_view head, std::optional<std::uint64_t> size);

}  // namespace evcorner::io
