#pragma once
// The part every binary event-file reader shares: a block buffer over the file with
// the byte offset of every position, the '#'/'%' ASCII header lines such files start
// with, and the checks each decoded event passes on its way out (sensor bounds, time
// order), so that a format's reader is only its word decoding.
//
// Errors name the file and the byte offset of the offending record. Events decoded
// before an error are returned first; the error is thrown by the next read() and by
// every read() after it (a damaged stream is not resynchronised).

#include <cstddef>
#include <cstdint>
#include <exception>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "evcorner/error.hpp"
#include "evcorner/event.hpp"
#include "evcorner/io/byte_order.hpp"
#include "evcorner/io/event_checks.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/input_file.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::io {

/// A 32-bit microsecond counter made monotonic: a backwards jump of more than half the
/// counter's range is the counter wrapping, which adds 2^32 us from then on.
class Unwrap32 {
public:
    std::int64_t operator()(std::uint32_t raw) noexcept {
        if (have_ && raw < last_ && last_ - raw > 0x8000'0000u) epoch_ += std::int64_t{1} << 32;
        last_ = raw;
        have_ = true;
        return epoch_ + raw;
    }

private:
    std::int64_t epoch_ = 0;
    std::uint32_t last_ = 0;
    bool have_ = false;
};

class BinaryReader : public EventReader {
public:
    std::size_t read(std::span<Event> out) final;

    [[nodiscard]] std::span<const SkipRun> skipped_in_batch() const noexcept final { return skips_.batch(); }
    [[nodiscard]] std::uint64_t skipped() const noexcept final { return skips_.total(); }
    [[nodiscard]] std::optional<SensorSize> sensor() const noexcept final { return sensor_; }
    [[nodiscard]] const std::string& name() const noexcept final { return file_.name(); }
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept final { return offset(); }
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() const noexcept final { return file_.size(); }
    /// Events returned so far.
    [[nodiscard]] std::uint64_t events() const noexcept { return events_; }

protected:
    /// Reads `file` from its first unread byte, which is byte offset 0 in messages.
    BinaryReader(InputFile file, ReaderOptions options);

    /// Decodes events into the batch with push() until batch_full() or the end of the
    /// data; returns false at the end. Throws (fail()) on bad input.
    virtual bool decode() = 0;

    /// Sets the sensor from the file's metadata (nullopt: it has none); options.sensor,
    /// then options.fallback_sensor, take precedence / stand in. Call once the header
    /// is parsed, before the first event.
    void set_file_sensor(std::optional<SensorSize> from_file) noexcept;
    /// Largest coordinate the format can encode, used when no sensor is known at all.
    void set_address_limit(int side) noexcept { address_limit_ = side; }

    // -- the byte buffer
    /// Makes at least `want` bytes available (fewer only at end of file); returns how many are.
    std::size_t fill(std::size_t want);
    /// The whole records of `bytes` bytes each available now (at least one unless the
    /// file has ended: 0 then). A file that ends inside a record is an error at its
    /// offset: "the file ends inside `what` (k of `bytes` bytes)".
    std::size_t whole_records(std::size_t bytes, std::string_view what);
    [[nodiscard]] const unsigned char* data() const noexcept {
        return reinterpret_cast<const unsigned char*>(buf_.data()) + pos_;
    }
    [[nodiscard]] std::size_t available() const noexcept { return fill_ - pos_; }
    void consume(std::size_t n) noexcept { pos_ += n; }
    /// File offset of data().
    [[nodiscard]] std::uint64_t offset() const noexcept { return buf_offset_ + pos_; }

    /// Reads one header line if the next byte is `marker`: the line without its line
    /// break (and '\r'). Returns false (consuming nothing) when the next byte is not
    /// `marker` or at the end of the file. A file that ends before the line's break is
    /// cut short: an error at its end.
    bool header_line(char marker, std::string& line);

    // -- the events
    [[nodiscard]] bool batch_full() const noexcept { return n_ == out_.size(); }
    [[nodiscard]] std::size_t batch_room() const noexcept { return out_.size() - n_; }
    /// Events in the batch so far (after read(): the count it returned).
    [[nodiscard]] std::size_t batch_count() const noexcept { return n_; }
    /// Validates and appends one event; `at` is the file offset of its record.
    void push(std::int64_t t, std::uint32_t x, std::uint32_t y, bool on, std::uint64_t at) {
        if (x >= limit_w_ || y >= limit_h_) [[unlikely]] {
            outside(x, y, at);
            return;
        }
        if (t < last_t_) [[unlikely]]
            backwards(t, at);
        last_t_ = t;
        out_[n_++] = Event{t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                           static_cast<std::uint8_t>(on)};
    }

    /// push() for `count` <= batch_room() records at once, for formats whose records
    /// decode independently: decode(i, e) fills e from record i. Stops before the first record
    /// that fails a check (outside the sensor, time going backwards, or p > 1) and returns
    /// how many were pushed; the caller passes that one to push() (or fails), which skips
    /// or reports it. The loop keeps its state in locals: stores to the events (a byte
    /// field may alias anything) would otherwise reload the members every record.
    template <class Decode>
    std::size_t push_run(std::size_t count, Decode decode) {
        Event* const out = out_.data() + n_;
        const std::uint32_t lw = limit_w_, lh = limit_h_;
        std::int64_t last = last_t_;
        std::size_t i = 0;
        for (; i < count; ++i) {
            Event e;
            decode(i, e);
            const bool ok = (e.x < lw) & (e.y < lh) & (e.t >= last) & (e.p <= 1);
            if (!ok) [[unlikely]]
                break;
            out[i] = e;
            last = e.t;
        }
        n_ += i;
        last_t_ = last;
        return i;
    }

    [[noreturn]] void fail(std::uint64_t at, const std::string& reason) const;
    [[nodiscard]] const ReaderOptions& options() const noexcept { return options_; }

private:
    void outside(std::uint32_t x, std::uint32_t y, std::uint64_t at);
    [[noreturn]] void backwards(std::int64_t t, std::uint64_t at) const;

    InputFile file_;
    ReaderOptions options_;
    std::vector<char> buf_;
    std::size_t pos_ = 0;
    std::size_t fill_ = 0;
    std::uint64_t buf_offset_ = 0;  // file offset of buf_[0]
    bool eof_ = false;

    std::optional<SensorSize> sensor_;
    int address_limit_ = kMaxSensorSide;
    std::uint32_t limit_w_ = kMaxSensorSide;
    std::uint32_t limit_h_ = kMaxSensorSide;

    std::span<Event> out_;
    std::size_t n_ = 0;
    std::int64_t last_t_ = INT64_MIN;
    std::uint64_t events_ = 0;
    SkipLog skips_;
    std::exception_ptr error_;  // sticky: thrown by every read() once set
    bool done_ = false;
};

}  // namespace evcorner::io
