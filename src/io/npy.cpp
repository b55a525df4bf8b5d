#include "evcorner/io/npy.hpp"

#include <algorithm>
#include <cstring>
#include <fmt/format.h>

#include "evcorner/error.hpp"

namespace evcorner::io {

namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr std::size_t kHeaderTotal = 192;  // fixed, a multiple of 64, room for any count
constexpr std::size_t kMaxHeaderLen = 1 << 16;

std::string make_header(std::uint64_t count) {
    std::string dict = fmt::format(
        "{{'descr': [('t', '<i8'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1'), ('_', '|V3')], "
        "'fortran_order': False, 'shape': ({},), }}",
        count);
    const std::size_t len = kHeaderTotal - 10;
    dict.resize(len - 1, ' ');
    dict += '\n';
    std::string h(kMagic, 6);
    h += '\x01';
    h += '\x00';
    h += static_cast<char>(len & 0xFF);
    h += static_cast<char>(len >> 8);
    return h + dict;
}

}  // namespace

namespace {
std::string regular_file(std::string path) {
    if (path.size() == 1 && path[0] == '-')
        throw OutputError("<stdout>", "a .npy file cannot go to standard output (its header holds the count)");
    return path;
}
}  // namespace

NpyWriter::NpyWriter(std::string path) : out_(regular_file(std::move(path))) {
    out_.write(make_header(0));
}

NpyWriter::~NpyWriter() = default;  // without close(), out_ removes the unfinished file

void NpyWriter::write(std::span<const Event> events) {
    for (const Event& e : events) {
        char* dst = out_.reserve(sizeof(Event));
        std::memset(dst, 0, sizeof(Event));  // the padding bytes are part of the file
        std::memcpy(dst, &e.t, 8);
        std::memcpy(dst + 8, &e.x, 2);
        std::memcpy(dst + 10, &e.y, 2);
        dst[12] = static_cast<char>(e.p != 0);
        out_.commit(sizeof(Event));
    }
    count_ += events.size();
}

void NpyWriter::close() {
    if (closed_) return;
    // The count goes into the header once every event is written (a temporary file until
    // out_.close() puts it under its name).
    out_.write_at(0, make_header(count_));
    out_.close();
    closed_ = true;
}

NpyReader::NpyReader(InputFile file, ReaderOptions options)
    : BinaryReader(std::move(file), std::move(options)) {
    if (fill(10) < 10 || std::memcmp(data(), kMagic, 6) != 0) fail(0, "not a .npy file (no \\x93NUMPY magic)");
    const int major = data()[6];
    std::size_t len = 0;
    std::size_t pre = 10;
    if (major == 1) {
        len = data()[8] | std::size_t{data()[9]} << 8;
    } else if (major == 2 || major == 3) {
        if (fill(12) < 12) fail(8, "the file ends inside the header length");
        len = data()[8] | std::size_t{data()[9]} << 8 | std::size_t{data()[10]} << 16 | std::size_t{data()[11]} << 24;
        pre = 12;
    } else {
        fail(6, fmt::format("unsupported .npy format version {}", major));
    }
    if (len > kMaxHeaderLen) fail(8, fmt::format("header length {} exceeds {} bytes", len, kMaxHeaderLen));
    if (fill(pre + len) < pre + len) fail(pre, "the file ends inside the .npy header");
    std::string h(reinterpret_cast<const char*>(data()) + pre, len);
    consume(pre + len);
    std::string norm;
    for (char c : h)
        if (c != ' ' && c != '|' && c != '\n') norm += c == '"' ? '\'' : c;
    if (norm.find("'fortran_order':False") == std::string::npos)
        fail(pre, "only C-order arrays are supported (fortran_order must be False)");
    const std::string base = "'descr':[('t','<i8'),('x','<u2'),('y','<u2'),";
    if (norm.find(base + "('p','u1'),('_','V3')]") != std::string::npos ||
        norm.find(base + "('p','b1'),('_','V3')]") != std::string::npos)
        itemsize_ = 16;
    else if (norm.find(base + "('p','u1')]") != std::string::npos ||
             norm.find(base + "('p','b1')]") != std::string::npos)
        itemsize_ = 13;
    else
        fail(pre, "unsupported dtype: expected the event dtype [('t','<i8'),('x','<u2'),('y','<u2'),('p','u1')] "
                  "(optionally with ('_','V3') padding)");
    const auto s = norm.find("'shape':(");
    if (s == std::string::npos) fail(pre, "the header has no shape");
    std::size_t i = s + 9;
    std::uint64_t n = 0;
    int digits = 0;
    while (i < norm.size() && norm[i] >= '0' && norm[i] <= '9') {
        n = n * 10 + static_cast<std::uint64_t>(norm[i++] - '0');
        if (++digits > 18) fail(pre, "shape too large");
    }
    if (digits == 0 || i + 1 >= norm.size() || norm[i] != ',' || norm[i + 1] != ')')
        fail(pre, "only one-dimensional arrays are supported (shape (N,))");
    declared_ = n;
    if (const auto total = bytes_total()) {
        const std::uint64_t body = *total - offset();
        // Fewer bytes than declared is a cut-short file: decode() returns the events that are
        // there and then reports where it ends. More is a header that does not describe the data.
        if (body / itemsize_ > declared_ || (body / itemsize_ == declared_ && body % itemsize_ != 0))
            fail(offset(), fmt::format("the header declares {} events of {} bytes but {} bytes follow it",
                                       declared_, itemsize_, body));
    }
    set_file_sensor(std::nullopt);
}

bool NpyReader::decode() {
    if (read_ == declared_) return false;
    const std::size_t avail = fill(itemsize_);
    if (avail < itemsize_)
        fail(offset(), fmt::format("the file ends after {} of the {} events the header declares", read_, declared_));
    const std::size_t records =
        static_cast<std::size_t>(std::min<std::uint64_t>({avail / itemsize_, batch_room(), declared_ - read_}));
    const unsigned char* p = data();
    const std::uint64_t base = offset();
    const std::size_t size = itemsize_;
    std::size_t i = 0;
    while (i < records) {
        // The common case: a run of valid records.
        i += push_run(records - i, [&](std::size_t k, Event& e) {
            const unsigned char* r = p + (i + k) * size;
            std::memcpy(&e.t, r, 8);
            std::memcpy(&e.x, r + 8, 2);
            std::memcpy(&e.y, r + 10, 2);
            e.p = r[12];
        });
        if (i == records) break;
        // Record i failed a check: a polarity other than 0/1 is an error here, the rest
        // push() reports or skips.
        const unsigned char* r = p + i * size;
        if (r[12] > 1) [[unlikely]] {
            read_ += i;
            consume(i * size);
            fail(base + i * size + 12, fmt::format("polarity {} where 0 or 1 is expected", r[12]));
        }
        std::int64_t t;
        std::uint16_t x, y;
        std::memcpy(&t, r, 8);
        std::memcpy(&x, r + 8, 2);
        std::memcpy(&y, r + 10, 2);
        push(t, x, y, r[12] != 0, base + i * size);
        ++i;
    }
    read_ += records;
    consume(records * itemsize_);
    return true;
}

}  // namespace evcorner::io
