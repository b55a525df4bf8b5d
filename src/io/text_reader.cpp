#include "evcorner/io/text_reader.hpp"

#include <cstring>
#include <utility>

#include "evcorner/error.hpp"

namespace evcorner::io {

namespace {

// |t| below this many seconds keeps t in microseconds far from int64 overflow.
constexpr std::int64_t kMaxSeconds = 9'000'000'000'000;

inline bool is_space(char c) { return c == ' ' || c == '\t'; }
inline bool is_digit(char c) { return static_cast<unsigned char>(c - '0') < 10; }

struct Parsed {
    Event e{};
    const char* error = nullptr;  // reason, or nullptr when the line parsed
};

// Parses "t x y p" from [p, end). `end` excludes the line break.
Parsed parse_line(const char* p, const char* end) {
    Parsed r;
    while (p < end && is_space(*p)) ++p;

    bool negative = false;
    if (p < end && (*p == '-' || *p == '+')) negative = *p++ == '-';
    std::int64_t sec = 0;
    int int_digits = 0;
    while (p < end && is_digit(*p)) {
        sec = sec * 10 + (*p++ - '0');
        if (++int_digits > 13) return {r.e, "timestamp too large"};
    }
    std::int64_t frac_ns = 0;
    int frac_digits = 0;
    if (p < end && *p == '.') {
        ++p;
        while (p < end && is_digit(*p)) {
            if (frac_digits < 9) frac_ns = frac_ns * 10 + (*p - '0');
            ++frac_digits;
            ++p;
        }
    }
    if (int_digits == 0 && frac_digits == 0) return {r.e, "expected a timestamp in seconds"};
    if (sec >= kMaxSeconds) return {r.e, "timestamp too large"};
    for (int d = frac_digits; d < 9; ++d) frac_ns *= 10;
    // Nearest microsecond, halves away from zero; digits past the 9th cannot change it.
    std::int64_t us = sec * 1'000'000 + frac_ns / 1000 + (frac_ns % 1000 >= 500 ? 1 : 0);
    r.e.t = negative ? -us : us;

    std::uint32_t coord[2];
    for (int i = 0; i < 2; ++i) {
        if (p == end || !is_space(*p))
            return {r.e, i == 0 ? "expected a space and x after the timestamp"
                                : "expected a space and y after x"};
        while (p < end && is_space(*p)) ++p;
        if (p == end || !is_digit(*p))
            return {r.e, i == 0 ? "expected x, a non-negative integer"
                                : "expected y, a non-negative integer"};
        std::uint32_t v = 0;
        int digits = 0;
        while (p < end && is_digit(*p)) {
            v = v * 10 + static_cast<std::uint32_t>(*p++ - '0');
            if (++digits > 6) break;
        }
        if (v >= 65536 || digits > 5)
            return {r.e, i == 0 ? "x does not fit 16 bits" : "y does not fit 16 bits"};
        coord[i] = v;
    }
    r.e.x = static_cast<std::uint16_t>(coord[0]);
    r.e.y = static_cast<std::uint16_t>(coord[1]);

    if (p == end || !is_space(*p)) return {r.e, "expected a space and the polarity after y"};
    while (p < end && is_space(*p)) ++p;
    if (p == end || (*p != '0' && *p != '1') || (p + 1 < end && !is_space(p[1])))
        return {r.e, "polarity must be 0 or 1"};
    r.e.p = static_cast<std::uint8_t>(*p++ - '0');
    while (p < end && is_space(*p)) ++p;
    if (p != end) return {r.e, "unexpected text after the polarity"};
    return r;
}

}  // namespace

TextReader::TextReader(InputFile file, ReaderOptions options)
    : lines_(std::move(file)), options_(std::move(options)) {
    format_ = "ecd-text";
    if (const auto c = lines_.file().compression()) format_.append("+").append(compression_name(*c));  // not "+" + string: GCC 12 -Wrestrict false positive
}

std::size_t TextReader::read(std::span<Event> out) {
    skips_.new_batch();
    if (pending_) std::rethrow_exception(std::exchange(pending_, nullptr));
    std::size_t n = 0;
    try {
        const char* b;
        const char* e;
        while (n < out.size() && lines_.next(b, e)) {
            const char* q = b;
            while (q < e && is_space(*q)) ++q;
            if (q == e || *q == '#') continue;
            const Parsed r = parse_line(b, e);
            if (r.error != nullptr) lines_.fail(b, e, r.error);
            if (r.e.t < last_t_) lines_.fail(b, e, backwards_message(last_t_, r.e.t));
            if (options_.sensor && !options_.sensor->contains(r.e)) {
                if (!options_.skip_invalid) lines_.fail(b, e, outside_sensor_message(r.e.x, r.e.y, options_.sensor));
                skips_.skip(n);
                continue;
            }
            last_t_ = r.e.t;
            out[n++] = r.e;
        }
    } catch (const InputError&) {
        if (n == 0) throw;
        pending_ = std::current_exception();
    }
    events_ += n;
    return n;
}

std::vector<Event> read_text_file(const std::string& path, ReaderOptions options) {
    TextReader reader(path, options);
    return read_all_events(reader);
}

}  // namespace evcorner::io
