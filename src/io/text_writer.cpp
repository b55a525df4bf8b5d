#include "evcorner/io/text_writer.hpp"

#include <charconv>
#include <cstdint>

namespace evcorner::io {

namespace {

// Writes v in decimal at dst; returns the end.
char* put_uint(char* dst, std::uint64_t v) noexcept {
    char tmp[20];
    int n = 0;
    do {
        tmp[n++] = static_cast<char>('0' + v % 10);
        v /= 10;
    } while (v != 0);
    while (n > 0) *dst++ = tmp[--n];
    return dst;
}

}  // namespace

std::size_t format_text_line(const Event& e, char* dst) noexcept {
    char* p = dst;
    std::uint64_t mag = static_cast<std::uint64_t>(e.t);
    if (e.t < 0) {
        *p++ = '-';
        mag = 0 - mag;
    }
    p = put_uint(p, mag / 1'000'000);
    *p++ = '.';
    std::uint64_t frac = mag % 1'000'000;
    for (int d = 5; d >= 0; --d) {
        p[d] = static_cast<char>('0' + frac % 10);
        frac /= 10;
    }
    p += 6;
    *p++ = '0';
    *p++ = '0';
    *p++ = '0';
    *p++ = ' ';
    p = put_uint(p, e.x);
    *p++ = ' ';
    p = put_uint(p, e.y);
    *p++ = ' ';
    *p++ = static_cast<char>('0' + (e.p != 0));
    *p++ = '\n';
    return static_cast<std::size_t>(p - dst);
}

std::size_t format_text_line(const Event& e, double score, char* dst) noexcept {
    std::size_t n = format_text_line(e, dst) - 1;  // without its '\n'
    dst[n++] = ' ';
    // The shortest form that reads back to the same double fits in 32 bytes
    // ("-2.2250738585072014e-308").
    const auto res = std::to_chars(dst + n, dst + kMaxScoredTextLine - 1, score);
    n = static_cast<std::size_t>(res.ptr - dst);
    dst[n++] = '\n';
    return n;
}

void TextWriter::write(const Event& e, double score) {
    char* dst = out_.reserve(kMaxScoredTextLine);
    out_.commit(format_text_line(e, score, dst));
}

void TextWriter::write(const Event& e) {
    char* dst = out_.reserve(kMaxTextLine);
    out_.commit(format_text_line(e, dst));
}

}  // namespace evcorner::io
