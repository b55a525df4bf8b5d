#include "evcorner/io/line_source.hpp"

#include <fmt/format.h>

#include <span>

#include "evcorner/error.hpp"

namespace evcorner::io {

std::string quote_bytes(std::string_view text, std::size_t max) {
    const char* b = text.data();
    const char* e = b + text.size();
    std::string s;
    const bool cut = text.size() > max;
    if (cut) e = b + max;
    for (const char* p = b; p < e; ++p) {
        const auto c = static_cast<unsigned char>(*p);
        if (c >= 0x20 && c < 0x7f)
            s += static_cast<char>(c);
        else
            s += fmt::format("\\x{:02x}", c);
    }
    return "'" + s + (cut ? "...'" : "'");
}

namespace {
std::string quote(const char* b, const char* e) { return quote_bytes(std::string_view(b, static_cast<std::size_t>(e - b))); }
}  // namespace

void LineSource::fail(const char* begin, const char* end, const std::string& reason) const {
    throw InputError(file_.name(), InputError::Unit::line, line_, reason + ": " + quote(begin, end));
}

void LineSource::skip_bom() {
    static constexpr char kBom[] = "\xEF\xBB\xBF";
    const std::size_t have = fill_ - pos_;
    const std::size_t n = have < 3 ? have : 3;
    if (std::memcmp(buf_.data() + pos_, kBom, n) != 0) {
        bom_checked_ = true;  // not a BOM
    } else if (n == 3) {
        pos_ += 3;
        bom_checked_ = true;
    } else if (eof_) {
        bom_checked_ = true;  // a file that is only part of a BOM: those bytes are its text
    }
}

bool LineSource::next_after_refill(const char*& begin, const char*& end) {
    for (;;) {
        if (!bom_checked_ && line_ == 0) {
            skip_bom();
            if (!bom_checked_ && !eof_ && fill_ > 0) {
                // Fewer than 3 bytes, all of them the start of a BOM: read more first.
                const std::size_t n = file_.read(std::span<char>(buf_.data() + fill_, buf_.size() - fill_));
                if (n == 0) eof_ = true;
                fill_ += n;
                continue;
            }
        }
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
        std::size_t n = 0;
        try {
            n = file_.read(std::span<char>(buf_.data() + fill_, buf_.size() - fill_));
        } catch (const InputError& e) {
            if (!file_.compression()) throw;
            // A damaged compressed stream: say which line of the text it stopped.
            std::string why = e.what();
            const std::string prefix = file_.name() + ": ";
            if (why.compare(0, prefix.size(), prefix) == 0) why.erase(0, prefix.size());
            if (why.compare(0, 5, "byte ") == 0) why.insert(0, "compressed ");
            throw InputError(file_.name(), InputError::Unit::line, line_ + 1, why);
        }
        if (n == 0) eof_ = true;
        fill_ += n;
    }
}

}  // namespace evcorner::io
