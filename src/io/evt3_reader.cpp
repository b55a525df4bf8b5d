#include "evcorner/io/evt3_reader.hpp"

#include <algorithm>
#include <bit>
#include <fmt/format.h>

#include "evcorner/io/prophesee_header.hpp"

namespace evcorner::io {

namespace {
constexpr std::size_t kWord = 2;
}  // namespace

Evt3Reader::Evt3Reader(InputFile file, ReaderOptions options)
    : BinaryReader(std::move(file), std::move(options)) {
    PropheseeHeader h;
    std::string line;
    while (!h.ended && header_line('%', line)) h.add_line(line);
    if (!h.evt.empty() && h.evt != "3.0")
        fail(0, fmt::format("the header says EVT {}, not EVT 3.0", h.evt));
    // Without "% end" the header's end is where the data starts: no data at all is a
    // file cut short at the end of a header line.
    if (!h.ended && fill(1) == 0)
        fail(offset(), offset() == 0 ? "the file is empty"
                                     : "the file ends right after its header, with no event data: it is cut short");
    set_address_limit(2048);
    set_file_sensor(h.sensor());
}

// Emits what is left of the current vector word; false when the batch filled first.
bool Evt3Reader::drain_vector() {
    while (vec_mask_ != 0) {
        if (batch_full()) return false;
        const int bit = std::countr_zero(vec_mask_);
        vec_mask_ &= vec_mask_ - 1;
        push(t_, vec_x_ + static_cast<std::uint32_t>(bit), y_, pol_, vec_at_);
    }
    return true;
}

bool Evt3Reader::decode() {
    if (!drain_vector()) return true;
    const std::size_t words = whole_records(kWord, "a 16-bit word");
    if (words == 0) return false;
    const unsigned char* p = data();
    const std::uint64_t base = offset();
    std::size_t i = 0;
    for (; i < words && !batch_full(); ++i, p += kWord) {
        const std::uint32_t w = load_le16(p);
        const std::uint64_t at = base + i * kWord;
        switch (w >> 12) {
            case 0x0:
                y_ = w & 0x7FF;
                have_y_ = true;
                break;
            case 0x2:
                if (!have_high_ || !have_y_) [[unlikely]]
                    fail(at, have_high_ ? "EVT_ADDR_X before the first EVT_ADDR_Y: its row is unknown"
                                        : "event before the first EVT_TIME_HIGH: its time is unknown");
                push(t_, w & 0x7FF, y_, (w >> 11) & 1, at);
                break;
            case 0x3:
                base_x_ = w & 0x7FF;
                pol_ = (w >> 11) & 1;
                have_base_ = true;
                break;
            case 0x4:
            case 0x5: {
                if (!have_high_ || !have_y_ || !have_base_) [[unlikely]]
                    fail(at, !have_high_ ? "event vector before the first EVT_TIME_HIGH: its time is unknown"
                             : !have_y_  ? "event vector before the first EVT_ADDR_Y: its row is unknown"
                                         : "event vector before the first VECT_BASE_X");
                const bool v12 = (w >> 12) == 0x4;
                vec_mask_ = w & (v12 ? 0xFFFu : 0xFFu);
                vec_x_ = base_x_;
                vec_at_ = at;
                base_x_ += v12 ? 12 : 8;
                if (!drain_vector()) {
                    ++i;  // this word is done; its remaining events go out with the next batch
                    consume(i * kWord);
                    return true;
                }
                break;
            }
            case 0x6:
                time_low_ = w & 0xFFF;
                t_ = epoch_ + (std::int64_t{time_high_} << 12 | time_low_);
                break;
            case 0x8: {
                const std::uint32_t high = w & 0xFFF;
                // More than half the 12-bit range backwards: the 24-bit time wrapped.
                if (have_high_ && high < time_high_ && time_high_ - high > 0x800) epoch_ += std::int64_t{1} << 24;
                // A new TIME_HIGH starts its 4096 us period at low = 0; a repeated one
                // (a keep-alive) leaves the time as it is.
                if (!have_high_ || high != time_high_) time_low_ = 0;
                time_high_ = high;
                have_high_ = true;
                t_ = epoch_ + (std::int64_t{time_high_} << 12 | time_low_);
                break;
            }
            default:
                ++other_words_;
                break;
        }
    }
    consume(i * kWord);
    return true;
}

}  // namespace evcorner::io
