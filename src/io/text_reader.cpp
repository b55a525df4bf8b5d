#include "evcorner/io/text_reader.hpp"

#include <charconv>
#include <cstring>
#include <utility>

#include "evcorner/error.hpp"
#include "decimal_time.hpp"

namespace evcorner::io {

namespace {

inline bool is_space(char c) { return c == ' ' || c == '\t'; }
inline bool is_digit(char c) { return static_cast<unsigned char>(c - '0') < 10; }

struct Parsed {
    Event e{};
    const char* error = nullptr;  // reason, or nullptr when the line parsed
    bool has_score = false;       // a fifth column: "t x y p score"
    double score = 0;
};

// Parses "t x y p" from [p, end). `end` excludes the line break.
Parsed parse_line(const char* p, const char* end) {
    Parsed r;
    while (p < end && is_space(*p)) ++p;

    const char* t_end = p;
    while (t_end < end && !is_space(*t_end)) ++t_end;
    const detail::DecimalTime t = detail::parse_decimal_time(p, t_end, TimeUnit::s, false);
    if (t.error != nullptr)
        return {r.e, std::strcmp(t.error, detail::kNotATimestamp) == 0 ? "expected a timestamp in seconds" : t.error};
    r.e.t = t.us;
    p = t_end;

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
    if (p != end) {
        // A score, as evcorner writes corners with their scores.
        const auto res = std::from_chars(p, end, r.score);
        if (res.ec != std::errc() || (res.ptr != end && !is_space(*res.ptr)))
            return {r.e, "unexpected text after the polarity (only a score may follow it)"};
        p = res.ptr;
        while (p < end && is_space(*p)) ++p;
        if (p != end) return {r.e, "unexpected text after the score"};
        r.has_score = true;
    }
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
    batch_n_ = 0;
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
            if (scored_ == Scored::unknown) {
                scored_ = r.has_score ? Scored::yes : Scored::no;
                if (r.has_score) scores_.resize(out.size());
            }
            if (r.has_score != (scored_ == Scored::yes))
                lines_.fail(b, e, r.has_score ? "a fifth column (a score), but the first event line had four"
                                              : "no score, but the first event line had one (t x y p score)");
            if (r.e.t < last_t_) lines_.fail(b, e, backwards_message(last_t_, r.e.t));
            if (options_.sensor && !options_.sensor->contains(r.e)) {
                if (!options_.skip_invalid) lines_.fail(b, e, outside_sensor_message(r.e.x, r.e.y, options_.sensor, options_.keyword_spelling));
                skips_.skip(n);
                continue;
            }
            last_t_ = r.e.t;
            if (scored_ == Scored::yes) {
                if (scores_.size() < out.size()) scores_.resize(out.size());
                scores_[n] = r.score;
            }
            out[n++] = r.e;
        }
    } catch (const InputError&) {
        if (n == 0) throw;
        pending_ = std::current_exception();
    }
    batch_n_ = n;
    events_ += n;
    return n;
}

std::vector<Event> read_text_file(const std::string& path, ReaderOptions options) {
    TextReader reader(path, options);
    return read_all_events(reader);
}

}  // namespace evcorner::io
