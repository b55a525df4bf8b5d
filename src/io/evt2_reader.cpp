#include "evcorner/io/evt2_reader.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "evcorner/io/prophesee_header.hpp"

namespace evcorner::io {

namespace {
constexpr std::size_t kWord = 4;
}  // namespace

Evt2Reader::Evt2Reader(InputFile file, ReaderOptions options)
    : BinaryReader(std::move(file), std::move(options)) {
    PropheseeHeader h;
    std::string line;
    while (!h.ended && header_line('%', line)) h.add_line(line);
    if (!h.evt.empty() && h.evt != "2.0")
        fail(0, fmt::format("the header says EVT {}, not EVT 2.0", h.evt));
    // Without "% end" the header's end is where the data starts: no data at all is a
    // file cut short at the end of a header line.
    if (!h.ended && fill(1) == 0)
        fail(offset(), offset() == 0 ? "the file is empty"
                                     : "the file ends right after its header, with no event data: it is cut short");
    set_address_limit(2048);
    set_file_sensor(h.sensor());
}

bool Evt2Reader::decode() {
    const std::size_t available = whole_records(kWord, "a 32-bit word");
    if (available == 0) return false;
    const std::size_t words = std::min(available, batch_room());
    const unsigned char* p = data();
    const std::uint64_t base = offset();
    for (std::size_t i = 0; i < words; ++i, p += kWord) {
        const std::uint32_t w = load_le32(p);
        const std::uint32_t type = w >> 28;
        if (type <= 1) {
            if (time_high_ < 0) [[unlikely]]
                fail(base + i * kWord, "CD event before the first EV_TIME_HIGH word: its time is unknown");
            push((time_high_ << 6) | ((w >> 22) & 0x3F), (w >> 11) & 0x7FF, w & 0x7FF, type == 1,
                 base + i * kWord);
        } else if (type == 0x8) {
            const std::uint32_t raw = w & 0x0FFF'FFFF;
            if (time_high_ < 0) {
                time_high_ = raw;
            } else {
                // More than half the 28-bit range backwards: the counter wrapped.
                std::int64_t epoch = time_high_ & ~std::int64_t{0x0FFF'FFFF};
                if (raw < last_raw_high_ && last_raw_high_ - raw > 0x0800'0000u) epoch += std::int64_t{1} << 28;
                time_high_ = epoch | raw;
            }
            last_raw_high_ = raw;
        } else {
            ++other_words_;
        }
    }
    consume(words * kWord);
    return true;
}

}  // namespace evcorner::io
