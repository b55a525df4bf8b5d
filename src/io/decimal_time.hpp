#pragma once
// A decimal time field of a text format ("12", "-0.5", "43.499039001") in a unit, to
// integer microseconds: the one float-time rule of the text readers (docs/formats.md,
// "Times"). Digits are read exactly (no binary floating point); the value is rounded to
// the nearest microsecond, halves away from zero. Refused, with a reason:
// - a nonzero digit finer than a nanosecond (more than 9 decimals of a second, 6 of a
//   millisecond, 3 of a microsecond, any fraction of a nanosecond): precision the
//   microsecond clock cannot keep, whose silent rounding would hide a unit mistake;
// - with `whole_only`, any nonzero fraction (a time column in microseconds holds whole
//   numbers: a fraction means the values are in another unit);
// - a value of |t| >= 9e12 seconds (about 285 000 years: microseconds far from int64's end).
// Exponent notation ("1.5e-3", "1e20") is read exactly too, as the decimal it stands for.

#include <cstdint>

#include "evcorner/io/event_reader.hpp"

namespace evcorner::io::detail {

/// Decimal digits of a microsecond in `u`'s fraction (s: 6, ms: 3, us: 0, ns: -3).
constexpr int us_digits(TimeUnit u) noexcept {
    return u == TimeUnit::s ? 6 : u == TimeUnit::ms ? 3 : u == TimeUnit::us ? 0 : -3;
}

/// The reason given for text that is not a number at all (callers may say more).
inline constexpr const char* kNotATimestamp = "expected a timestamp";

struct DecimalTime {
    std::int64_t us = 0;
    bool has_point = false;       ///< the text had a decimal point
    const char* error = nullptr;  ///< why the text is refused, or nullptr
};

/// Parses [b, e) (no surrounding spaces) as an optionally signed decimal in `unit`.
inline DecimalTime parse_decimal_time(const char* b, const char* e, TimeUnit unit, bool whole_only) noexcept;

/// "1.5e-3", "1e20": the mantissa's decimal point moved by the exponent, exactly, then
/// parsed as above (has_point set: exponent notation is a float). False when [b, e) has
/// no exponent (then `out` is untouched).
inline bool parse_exponent_time(const char* b, const char* e, TimeUnit unit, bool whole_only, DecimalTime& out) noexcept {
    const char* x = b;
    while (x < e && *x != 'e' && *x != 'E') ++x;
    if (x == e) return false;
    const auto is_digit = [](char c) { return static_cast<unsigned char>(c - '0') < 10; };
    out = {0, true, kNotATimestamp};
    const char* m = b;
    const bool negative = m < x && *m == '-';
    if (m < x && (*m == '-' || *m == '+')) ++m;
    // The mantissa's digits without its point, and how many come before the point.
    char digits[64];
    int n = 0, before = 0, seen = 0;
    bool point = false, nonzero = false;
    for (const char* c = m; c < x; ++c) {
        if (*c == '.' && !point) {
            point = true;
            continue;
        }
        if (!is_digit(*c)) return true;
        ++seen;
        if (n == 0 && *c == '0') {  // leading zeros carry no digit
            if (point) --before;
            continue;
        }
        if (n == static_cast<int>(sizeof digits)) {
            out = {0, true, "a timestamp of more than 64 significant digits"};
            return true;
        }
        nonzero |= *c != '0';
        digits[n++] = *c;
        if (!point) ++before;
    }
    if (seen == 0) return true;
    const char* y = x + 1;
    bool exp_negative = false;
    if (y < e && (*y == '-' || *y == '+')) exp_negative = *y++ == '-';
    if (y == e) return true;
    long exponent = 0;
    for (; y < e; ++y) {
        if (!is_digit(*y)) return true;
        if (exponent < 100000) exponent = exponent * 10 + (*y - '0');
    }
    if (exp_negative) exponent = -exponent;
    if (!nonzero) {
        out = {0, true, nullptr};
        return true;
    }
    const long place = before + exponent;  // digits before the point, once moved
    if (place > 40) {
        out = {0, true, "timestamp too large (at most 9e12 seconds)"};
        return true;
    }
    if (place < -40) {
        out = {0, true, "a time given to a fraction of a nanosecond (more than 9 decimals of a second)"};
        return true;
    }
    // The plain decimal: sign, digits with the point at `place`, zeros filled in.
    char plain[160];
    int k = 0;
    if (negative) plain[k++] = '-';
    if (place <= 0) {
        plain[k++] = '0';
        plain[k++] = '.';
        for (long i = 0; i < -place; ++i) plain[k++] = '0';
        for (int i = 0; i < n; ++i) plain[k++] = digits[i];
    } else {
        for (long i = 0; i < place; ++i) plain[k++] = i < n ? digits[i] : '0';
        if (place < n) {
            plain[k++] = '.';
            for (int i = static_cast<int>(place); i < n; ++i) plain[k++] = digits[i];
        }
    }
    out = parse_decimal_time(plain, plain + k, unit, whole_only);
    out.has_point = true;
    return true;
}

inline DecimalTime parse_decimal_time(const char* b, const char* e, TimeUnit unit, bool whole_only) noexcept {
    const char* const start = b;
    // Exponent notation is parsed apart; tried only where the plain reading stops (or would refuse).
    const auto exponent = [&](const char* from, DecimalTime& x) {
        for (const char* c = from; c < e; ++c)
            if (*c == 'e' || *c == 'E') return parse_exponent_time(start, e, unit, whole_only, x);
        return false;
    };
    DecimalTime r;
    const auto is_digit = [](char c) { return static_cast<unsigned char>(c - '0') < 10; };
    bool negative = false;
    if (b < e && (*b == '-' || *b == '+')) negative = *b++ == '-';
    // The integer part in the unit, and the fraction in nanoseconds: no overflow and no
    // floating point.
    std::int64_t ip = 0;
    int int_digits = 0;
    while (b < e && is_digit(*b)) {
        if (++int_digits > 18) {
            if (DecimalTime x; exponent(b, x)) return x;
            return {0, false, "timestamp too large (at most 9e12 seconds)"};
        }
        ip = ip * 10 + (*b++ - '0');
    }
    const int ns_digits = us_digits(unit) + 3;  // fraction digits down to a nanosecond
    std::int64_t frac_ns = 0;                   // the fraction in nanoseconds (ns_digits digits)
    int frac_digits = 0;
    bool frac_nonzero = false;
    if (b < e && *b == '.') {
        r.has_point = true;
        ++b;
        while (b < e && is_digit(*b)) {
            const int d = *b - '0';
            if (d != 0) {
                frac_nonzero = true;
                if (frac_digits >= ns_digits) {
                    if (DecimalTime x; exponent(b, x)) return x;
                    return {0, true, "a time given to a fraction of a nanosecond (more than 9 decimals of a second)"};
                }
            }
            if (frac_digits < ns_digits) frac_ns = frac_ns * 10 + d;
            ++frac_digits;
            ++b;
        }
    }
    if (DecimalTime x; b != e && (*b == 'e' || *b == 'E') && exponent(b, x)) return x;
    if (b != e || (int_digits == 0 && frac_digits == 0)) return {0, r.has_point, kNotATimestamp};
    if (whole_only && frac_nonzero)
        return {0, true, "a fraction of a microsecond in a time column of whole microseconds"};
    for (int d = frac_digits; d < ns_digits; ++d) frac_ns *= 10;
    constexpr std::int64_t kMaxUs = 9'000'000'000'000LL * 1'000'000;  // 9e12 s
    std::int64_t scale_ns = 1;  // nanoseconds in one unit
    for (int d = 0; d < ns_digits; ++d) scale_ns *= 10;
    if (scale_ns >= 1000 && ip >= kMaxUs / (scale_ns / 1000))
        return {0, r.has_point, "timestamp too large (at most 9e12 seconds)"};
    // Microseconds: ip * scale_ns / 1000 + frac_ns / 1000, rounded on the nanoseconds.
    std::int64_t whole_us, rem_ns;
    if (scale_ns >= 1000) {
        whole_us = ip * (scale_ns / 1000) + frac_ns / 1000;
        rem_ns = frac_ns % 1000;
    } else {  // ns: the integer part is nanoseconds
        whole_us = ip / 1000;
        rem_ns = ip % 1000;
    }
    const std::int64_t us = whole_us + (rem_ns >= 500 ? 1 : 0);
    r.us = negative ? -us : us;
    return r;
}

}  // namespace evcorner::io::detail
