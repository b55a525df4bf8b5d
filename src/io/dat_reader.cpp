#include "evcorner/io/dat_reader.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "evcorner/io/prophesee_header.hpp"

namespace evcorner::io {

namespace {
constexpr std::size_t kRecord = 8;
}  // namespace

DatReader::DatReader(InputFile file, ReaderOptions options)
    : BinaryReader(std::move(file), std::move(options)) {
    PropheseeHeader h;
    std::string line;
    while (!h.ended && header_line('%', line)) h.add_line(line);
    const std::uint64_t at = offset();
    if (fill(2) < 2) fail(at, "the file ends before the event type and size bytes that follow the header");
    event_type_ = data()[0];
    const int size = data()[1];
    if (event_type_ != 0x00 && event_type_ != 0x0C)
        fail(at, fmt::format("unsupported DAT event type 0x{:02x} (supported: 0x00 Event2d, 0x0C EventCD)",
                             event_type_));
    if (size != static_cast<int>(kRecord))
        fail(at + 1, fmt::format("DAT event size {} where Event2d records have 8 bytes", size));
    consume(2);
    set_address_limit(16384);
    set_file_sensor(h.sensor());
}

bool DatReader::decode() {
    const std::size_t available = whole_records(kRecord, "an event record");
    if (available == 0) return false;
    const std::size_t records = std::min(available, batch_room());
    const unsigned char* p = data();
    const std::uint64_t base = offset();
    for (std::size_t i = 0; i < records; ++i, p += kRecord) {
        const std::uint32_t raw = load_le32(p);
        const std::uint32_t d = load_le32(p + 4);
        const std::int64_t t = unwrap_(raw);
        const std::uint32_t pol = d >> 28;
        if (pol > 1) [[unlikely]] {
            consume(i * kRecord);
            fail(base + i * kRecord, fmt::format("polarity {} where 0 or 1 is expected", pol));
        }
        push(t, d & 0x3FFF, (d >> 14) & 0x3FFF, pol == 1, base + i * kRecord);
    }
    consume(records * kRecord);
    return true;
}

}  // namespace evcorner::io
