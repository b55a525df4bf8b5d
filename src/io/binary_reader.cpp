#include "evcorner/io/binary_reader.hpp"

#include <algorithm>
#include <cstring>
#include <utility>
#include <fmt/format.h>

namespace evcorner::io {

namespace {
constexpr std::size_t kBufferSize = 1 << 20;
// A header line longer than this is not a header line: the file is not what it claims.
constexpr std::size_t kMaxHeaderLine = 1 << 16;
}  // namespace

BinaryReader::BinaryReader(InputFile file, ReaderOptions options)
    : file_(std::move(file)), options_(std::move(options)), buf_(kBufferSize) {
    set_file_sensor(std::nullopt);
}

void BinaryReader::set_file_sensor(std::optional<SensorSize> from_file) noexcept {
    sensor_ = options_.sensor ? options_.sensor : from_file ? from_file : options_.fallback_sensor;
    const int w = sensor_ ? sensor_->width : address_limit_;
    const int h = sensor_ ? sensor_->height : address_limit_;
    limit_w_ = static_cast<std::uint32_t>(w);
    limit_h_ = static_cast<std::uint32_t>(h);
}

std::size_t BinaryReader::whole_records(std::size_t bytes, std::string_view what) {
    const std::size_t avail = fill(bytes);
    if (avail > 0 && avail < bytes)
        fail(offset(), fmt::format("the file ends inside {} ({} of {} bytes)", what, avail, bytes));
    return avail / bytes;
}

std::size_t BinaryReader::fill(std::size_t want) {
    while (fill_ - pos_ < want && !eof_) {
        if (pos_ > 0) {
            std::memmove(buf_.data(), buf_.data() + pos_, fill_ - pos_);
            buf_offset_ += pos_;
            fill_ -= pos_;
            pos_ = 0;
        }
        if (want > buf_.size()) want = buf_.size();  // callers ask for small records only
        const std::size_t n = file_.read(std::span<char>(buf_.data() + fill_, buf_.size() - fill_));
        if (n == 0) eof_ = true;
        fill_ += n;
    }
    return fill_ - pos_;
}

bool BinaryReader::header_line(char marker, std::string& line) {
    if (fill(1) == 0 || buf_[pos_] != marker) return false;
    const std::uint64_t start = offset();
    line.clear();
    for (;;) {
        const std::size_t avail = fill(1);
        if (avail == 0)
            fail(offset(), fmt::format("the file ends inside the header line that starts at byte {}: "
                                       "it is cut short",
                                       start));
        const char* b = buf_.data() + pos_;
        const void* nl = std::memchr(b, '\n', avail);
        const std::size_t len = nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - b) : avail;
        if (line.size() + len > kMaxHeaderLine)
            fail(offset(), fmt::format("header line longer than {} bytes: not a valid header",
                                       kMaxHeaderLine));
        line.append(b, len);
        pos_ += len;
        if (nl) {
            ++pos_;
            if (!line.empty() && line.back() == '\r') line.pop_back();
            return true;
        }
    }
}

void BinaryReader::fail(std::uint64_t at, const std::string& reason) const {
    throw InputError(file_.name(), InputError::Unit::byte, at, reason);
}

void BinaryReader::outside(std::uint32_t x, std::uint32_t y, std::uint64_t at) {
    if (!options_.skip_invalid) fail(at, outside_sensor_message(x, y, sensor_, options_.keyword_spelling));
    skips_.skip(n_);
}

void BinaryReader::backwards(std::int64_t t, std::uint64_t at) const {
    fail(at, backwards_message(last_t_, t));
}

std::size_t BinaryReader::read(std::span<Event> out) {
    skips_.new_batch();
    if (error_) std::rethrow_exception(error_);
    if (done_ || out.empty()) return 0;
    out_ = out;
    n_ = 0;
    try {
        // A batch of skipped events only still returns, so that skip runs stay bounded.
        while (n_ < out_.size() && skips_.batch().size() < out_.size()) {
            if (!decode()) {
                done_ = true;
                break;
            }
        }
    } catch (const InputError&) {
        error_ = std::current_exception();
        if (n_ == 0 && skips_.batch().empty()) throw;
    }
    events_ += n_;
    return n_;
}

}  // namespace evcorner::io
