#pragma once
// The EVT 3.0 word decoder (layout in evcorner/io/evt3_reader.hpp), kept apart from where
// the words come from: the RAW file reader (Evt3Reader) and the ROS bag reader (payloads
// of event_camera_msgs/EventPacket messages with encoding "evt3", which, concatenated,
// form one EVT 3.0 stream) share it.
//
// A Sink receives the events and the failures:
//   bool full() const;                       // no room for another event
//   void push(std::int64_t t, std::uint32_t x, std::uint32_t y, bool on, std::uint64_t at);
//   [[noreturn]] void fail(std::uint64_t at, const char* reason);
// `at` is `base + 2 * i` for word i of the words passed: the caller's position of the word.

#include <bit>
#include <cstddef>
#include <cstdint>

#include "evcorner/io/byte_order.hpp"

namespace evcorner::io::detail {

class Evt3Decoder {
public:
    /// Emits what is left of a vector word that did not fit the last batch; false when
    /// the batch filled first.
    template <class Sink>
    bool drain(Sink& sink) {
        while (vec_mask_ != 0) {
            if (sink.full()) return false;
            const int bit = std::countr_zero(vec_mask_);
            vec_mask_ &= vec_mask_ - 1;
            sink.push(t_, vec_x_ + static_cast<std::uint32_t>(bit), y_, pol_, vec_at_);
        }
        return true;
    }

    /// Decodes the `words` 16-bit little-endian words at `p` (position `base`) until the
    /// sink is full; returns the words consumed. A vector word whose events did not all
    /// fit counts as consumed: drain() emits the rest first.
    template <class Sink>
    std::size_t decode(const unsigned char* p, std::size_t words, std::uint64_t base, Sink& sink) {
        if (!drain(sink)) return 0;
        std::size_t i = 0;
        for (; i < words && !sink.full(); ++i, p += 2) {
            const std::uint32_t w = load_le16(p);
            const std::uint64_t at = base + i * 2;
            switch (w >> 12) {
                case 0x0:
                    y_ = w & 0x7FF;
                    have_y_ = true;
                    break;
                case 0x2:
                    if (!have_high_ || !have_y_) [[unlikely]]
                        sink.fail(at, have_high_ ? "EVT_ADDR_X before the first EVT_ADDR_Y: its row is unknown"
                                                 : "event before the first EVT_TIME_HIGH: its time is unknown");
                    sink.push(t_, w & 0x7FF, y_, (w >> 11) & 1, at);
                    break;
                case 0x3:
                    base_x_ = w & 0x7FF;
                    pol_ = (w >> 11) & 1;
                    have_base_ = true;
                    break;
                case 0x4:
                case 0x5: {
                    if (!have_high_ || !have_y_ || !have_base_) [[unlikely]]
                        sink.fail(at, !have_high_ ? "event vector before the first EVT_TIME_HIGH: its time is unknown"
                                      : !have_y_  ? "event vector before the first EVT_ADDR_Y: its row is unknown"
                                                  : "event vector before the first VECT_BASE_X");
                    const bool v12 = (w >> 12) == 0x4;
                    vec_mask_ = w & (v12 ? 0xFFFu : 0xFFu);
                    vec_x_ = base_x_;
                    vec_at_ = at;
                    base_x_ += v12 ? 12 : 8;
                    if (!drain(sink)) return i + 1;  // the rest goes out with the next batch
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
        return i;
    }

    /// Words of other types (triggers, OTHERS, continued, unknown) skipped so far.
    [[nodiscard]] std::uint64_t other_words() const noexcept { return other_words_; }

private:
    std::uint64_t other_words_ = 0;
    std::int64_t epoch_ = 0;        // multiples of 2^24 us added by wraps
    std::uint32_t time_high_ = 0;   // 12 bits
    std::uint32_t time_low_ = 0;    // 12 bits
    std::int64_t t_ = 0;
    bool have_high_ = false;
    std::uint32_t y_ = 0;
    bool have_y_ = false;
    std::uint32_t base_x_ = 0;
    bool have_base_ = false;
    bool pol_ = false;
    // A vector word whose events did not all fit the batch.
    std::uint32_t vec_mask_ = 0;
    std::uint32_t vec_x_ = 0;
    std::uint64_t vec_at_ = 0;
};

}  // namespace evcorner::io::detail
