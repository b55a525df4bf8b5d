#include "evcorner/io/line_source.hpp"

#include <fmt/format.h>

#include <span>

#include "evcorner/error.hpp"

namespace evcorner::io {

namespace {

// The offending line, shortened and with unprintable bytes escaped.
std::string quote(const char* b, const char* e) {
    std::string s;
    const bool cut = e - b > 80;
    if (cut) e = b + 80;
    for (const char* p = b; p < e; ++p) {
        const auto c = static_cast<unsigned char>(*p);
        if (c >= 0x20 && c < 0x7f)
            s += static_cast<char>(c);
        else
            s += fmt::format("\\x{:02x}", c);
    }
    return "'" + s + (cut ? "...'" : "'");
}

}  // namespace

void LineSource::fail(const char* begin, const char* end, const std::string& reason) const {
    throw InputError(file_.name(), InputError::Unit::line, line_, reason + ": " + quote(begin, end));
}

bool LineSource::next_after_refill(const char*& begin, const char*& end) {
    for (;;) {
        const char* data = buf_.data();
        const void* nl = std::memchr(data + pos_, '\n', fill_ - pos_);
        if (nl != nullptr) return next(begin, end);
        if (eof_) {
            if (pos_ == fill_) return false;
            begin = data + pos_;  // the last line, without a line break
            end = data + fill_;
            pos_ = fill_;
            ++line_;
            if (end > begin && end[-1] == '\r') --end;
            return true;
        }
        if (pos_ == 0 && fill_ == buf_.size()) {
            ++line_;
            fail(data, data + 80, fmt::format("line longer than {} bytes", buf_.size()));
        }
        std::memmove(buf_.data(), buf_.data() + pos_, fill_ - pos_);
        fill_ -= pos_;
        pos_ = 0;
        const std::size_t n = file_.read(std::span<char>(buf_.data() + fill_, buf_.size() - fill_));
        if (n == 0) eof_ = true;
        fill_ += n;
    }
}

}  // namespace evcorner::io
