#include "evcorner/io/csv_reader.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <utility>

#include "evcorner/error.hpp"
#include "decimal_time.hpp"

namespace evcorner::io {

namespace {

inline bool is_space(char c) { return c == ' ' || c == '\t'; }
inline bool is_digit(char c) { return static_cast<unsigned char>(c - '0') < 10; }

std::string lower_trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    std::string r(s);
    for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (r.size() >= 2 && (r.front() == '"' || r.front() == '\'') && r.back() == r.front())
        r = r.substr(1, r.size() - 2);
    return r;
}

}  // namespace

CsvReader::CsvReader(InputFile file, ReaderOptions options)
    : lines_(std::move(file)), options_(std::move(options)) {
    format_ = "csv";
    if (const auto c = lines_.file().compression()) format_.append("+").append(compression_name(*c));  // not "+" + string: GCC 12 -Wrestrict false positive
    sensor_ = options_.sensor ? options_.sensor : options_.fallback_sensor;
    const std::string& u = options_.csv_time_unit;
    unit_given_ = !u.empty();
    if (u == "us" || u.empty()) time_unit_ = TimeUnit::us;
    else if (u == "ms") time_unit_ = TimeUnit::ms;
    else if (u == "s") time_unit_ = TimeUnit::s;
    else if (u == "ns") time_unit_ = TimeUnit::ns;
    else throw InputError(lines_.file().name(), "unknown CSV time unit '" + u + "' (us, ns, ms or s)");
    if (!options_.csv_columns.empty()) set_columns(options_.csv_columns, false);
}

void CsvReader::set_columns(const std::string& spec, bool from_header) {
    std::vector<Field> cols;
    std::array<int, 4> seen{};
    std::size_t start = 0;
    for (;;) {
        const auto comma = spec.find(',', start);
        const std::string name = lower_trim(std::string_view(spec).substr(start, comma - start));
        Field f = kIgnore;
        if (name == "t" || name == "ts" || name == "timestamp" || name == "time" || name == "t_us") f = kT;
        else if (name == "x") f = kX;
        else if (name == "y") f = kY;
        else if (name == "p" || name == "pol" || name == "polarity") f = kP;
        else if (name == "score") f = kScore;
        else if (!from_header && name != "_")
            throw InputError(lines_.file().name(), "unknown CSV column " + quote_bytes(name) + " in " + quote_bytes(spec) +
                                               " (t, x, y, p, score, or _ to ignore one)");
        if (f == kScore && has_score_)
            throw InputError(lines_.file().name(), "CSV column " + quote_bytes(name) + " named twice in " + quote_bytes(spec));
        if (f == kScore) has_score_ = true;
        if (f < kIgnore && seen[f]++ > 0)
            throw InputError(lines_.file().name(), "CSV column " + quote_bytes(name) + " named twice in " + quote_bytes(spec));
        cols.push_back(f);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    if (std::count(seen.begin(), seen.end(), 1) != 4) {
        const std::string why = "CSV columns " + quote_bytes(spec) + " do not name each of t, x, y and p";
        if (from_header) throw InputError(lines_.file().name(), InputError::Unit::line, lines_.line(), why);
        throw InputError(lines_.file().name(), why);
    }
    columns_ = std::move(cols);
    columns_known_ = true;
}

bool CsvReader::parse(const char* p, const char* end, Event& ev, const char*& why) {
    std::size_t col = 0;
    for (;; ++col) {
        if (col >= columns_.size()) {
            why = "more columns than the column order names";
            return false;
        }
        while (p < end && is_space(*p)) ++p;
        const char* f = p;
        while (p < end && *p != ',') ++p;
        const char* fe = p;
        while (fe > f && is_space(fe[-1])) --fe;
        const Field kind = columns_[col];
        if (kind == kT) {
            // A float: a decimal point, or exponent notation ("1e-3").
            const auto n = static_cast<std::size_t>(fe - f);
            const bool has_point = std::memchr(f, '.', n) != nullptr || std::memchr(f, 'e', n) != nullptr ||
                                   std::memchr(f, 'E', n) != nullptr;
            TimeUnit unit = time_unit_;
            bool whole = unit == TimeUnit::us;
            if (!unit_given_) {
                // The first time decides: with a decimal point seconds, else microseconds.
                if (float_time_ == Tri::unknown) float_time_ = has_point ? Tri::yes : Tri::no;
                if (float_time_ == Tri::yes) {
                    unit = TimeUnit::s;
                    whole = false;
                } else if (has_point) {
                    why = options_.keyword_spelling
                          ? "a decimal point in a time column whose first time was an integer: times are "
                            "microseconds when the first has no decimal point, else seconds (time_unit sets the unit)"
                          : "a decimal point in a time column whose first time was an integer: times are "
                            "microseconds when the first has no decimal point, else seconds (--time-unit sets the unit)";
                    return false;
                }
            }
            const detail::DecimalTime t = detail::parse_decimal_time(f, fe, unit, whole);
            if (t.error != nullptr) {
                why = whole && unit_given_ && has_point && std::strcmp(t.error, detail::kNotATimestamp) != 0
                          ? (options_.keyword_spelling ? "a fraction of a microsecond, but time_unit is us (whole microseconds)"
                                                       : "a fraction of a microsecond, but --time-unit is us (whole microseconds)")
                          : t.error;
                return false;
            }
            ev.t = t.us;
        } else if (kind == kX || kind == kY) {
            std::uint32_t v = 0;
            const char* q = f;
            if (q == fe) {
                why = kind == kX ? "expected x, a non-negative integer" : "expected y, a non-negative integer";
                return false;
            }
            for (; q < fe; ++q) {
                if (!is_digit(*q) || (v = v * 10 + static_cast<std::uint32_t>(*q - '0')) >= 65536) {
                    why = kind == kX ? "x is not an integer in 0..65535" : "y is not an integer in 0..65535";
                    return false;
                }
            }
            (kind == kX ? ev.x : ev.y) = static_cast<std::uint16_t>(v);
        } else if (kind == kScore) {
            const auto res = std::from_chars(f, fe, score_);
            if (res.ec != std::errc() || res.ptr != fe || f == fe) {
                why = "expected a score, a number";
                return false;
            }
        } else if (kind == kP) {
            const std::size_t len = static_cast<std::size_t>(fe - f);
            if (len == 1 && (*f == '0' || *f == '1')) ev.p = static_cast<std::uint8_t>(*f - '0');
            else if (len == 2 && f[0] == '-' && f[1] == '1') ev.p = 0;
            else if (len == 4 && std::memcmp(f, "True", 4) == 0) ev.p = 1;
            else if (len == 5 && std::memcmp(f, "False", 5) == 0) ev.p = 0;
            else {
                why = "polarity must be 1 or 0 (or -1)";
                return false;
            }
        }
        if (p == end) break;
        ++p;  // the comma
    }
    if (col + 1 != columns_.size()) {
        why = "fewer columns than the column order names";
        return false;
    }
    return true;
}

std::size_t CsvReader::read(std::span<Event> out) {
    skips_.new_batch();
    batch_n_ = 0;
    if (error_) std::rethrow_exception(error_);
    std::size_t n = 0;
    try {
        const char* b;
        const char* e;
        while (n < out.size() && lines_.next(b, e)) {
            const char* q = b;
            while (q < e && is_space(*q)) ++q;
            if (q == e || *q == '#') continue;
            if (!is_digit(*q) && *q != '-' && *q != '+' && *q != '.') {
                // A header row: names the columns unless the options did.
                if (seen_row_) lines_.fail(b, e, "text where an event was expected");
                seen_row_ = true;
                if (options_.csv_columns.empty()) set_columns(std::string(b, e), true);
                continue;
            }
            if (!columns_known_) set_columns("t,x,y,p", false);
            seen_row_ = true;
            Event ev{};
            const char* why = nullptr;
            if (!parse(b, e, ev, why)) lines_.fail(b, e, why);
            if (ev.t < last_t_) lines_.fail(b, e, backwards_message(last_t_, ev.t));
            if (sensor_ && !sensor_->contains(ev)) {
                if (!options_.skip_invalid) lines_.fail(b, e, outside_sensor_message(ev.x, ev.y, sensor_, options_.keyword_spelling));
                skips_.skip(n);
                continue;
            }
            last_t_ = ev.t;
            if (has_score_) {
                if (scores_.size() < out.size()) scores_.resize(out.size());
                scores_[n] = score_;
            }
            out[n++] = ev;
        }
    } catch (const InputError&) {
        error_ = std::current_exception();
        if (n == 0 && skips_.batch().empty()) throw;
    }
    batch_n_ = n;
    return n;
}

}  // namespace evcorner::io
