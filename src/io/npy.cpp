#include "evcorner/io/npy.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <optional>
#include <stdexcept>
#include <vector>

#include "evcorner/error.hpp"

namespace evcorner::io {

namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr std::size_t kHeaderTotal = 192;  // fixed, a multiple of 64, room for any count
constexpr std::size_t kMaxHeaderLen = 1 << 16;

std::string make_header(std::uint64_t count, bool with_score) {
    return npy_header(fmt::format("[('t', '<i8'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1'), ('_', '|V3'){}]",
                                  with_score ? ", ('score', '<f8')" : ""),
                      count);
}

}  // namespace

std::string npy_header(std::string_view descr, std::uint64_t count) {
    std::string dict = fmt::format("{{'descr': {}, 'fortran_order': False, 'shape': ({},), }}", descr, count);
    const std::size_t len = kHeaderTotal - 10;
    if (dict.size() + 1 > len) throw std::logic_error("npy_header: the dtype does not fit the fixed header");
    dict.resize(len - 1, ' ');
    dict += '\n';
    std::string h(kMagic, 6);
    h += '\x01';
    h += '\x00';
    h += static_cast<char>(len & 0xFF);
    h += static_cast<char>(len >> 8);
    return h + dict;
}

namespace {
std::string regular_file(std::string path) {
    if (path.size() == 1 && path[0] == '-')
        throw OutputError("<stdout>", "a .npy file cannot go to standard output (its header holds the count)");
    return path;
}
}  // namespace

NpyWriter::NpyWriter(std::string path, bool with_score)
    : out_(regular_file(std::move(path))), with_score_(with_score) {
    out_.write(make_header(0, with_score_));
}

NpyWriter::~NpyWriter() = default;  // without close(), out_ removes the unfinished file

void NpyWriter::write(std::span<const Event> events, std::span<const double> scores) {
    if (!with_score_ || scores.size() != events.size())
        throw std::logic_error("NpyWriter: scores on a writer opened without, or not one per event");
    constexpr std::size_t kRecord = sizeof(Event) + 8;
    constexpr std::size_t kBlock = 4096;
    for (std::size_t i = 0; i < events.size(); i += kBlock) {
        const std::size_t n = std::min(kBlock, events.size() - i);
        char* dst = out_.reserve(n * kRecord);
        std::memset(dst, 0, n * kRecord);
        for (std::size_t k = i; k < i + n; ++k) {
            const Event& e = events[k];
            std::memcpy(dst, &e.t, 8);
            std::memcpy(dst + 8, &e.x, 2);
            std::memcpy(dst + 10, &e.y, 2);
            dst[12] = static_cast<char>(e.p != 0);
            std::memcpy(dst + 16, &scores[k], 8);
            dst += kRecord;
        }
        out_.commit(n * kRecord);
    }
    count_ += events.size();
}

void NpyWriter::write(std::span<const Event> events) {
    if (with_score_) throw std::logic_error("NpyWriter: opened with scores, written without");
    // Records are reserved a block at a time (a call per event cost more than the copying).
    constexpr std::size_t kBlock = 4096;
    for (std::size_t i = 0; i < events.size(); i += kBlock) {
        const std::size_t n = std::min(kBlock, events.size() - i);
        char* dst = out_.reserve(n * sizeof(Event));
        std::memset(dst, 0, n * sizeof(Event));  // the padding bytes are part of the file
        for (const Event& e : events.subspan(i, n)) {
            std::memcpy(dst, &e.t, 8);
            std::memcpy(dst + 8, &e.x, 2);
            std::memcpy(dst + 10, &e.y, 2);
            dst[12] = static_cast<char>(e.p != 0);
            dst += sizeof(Event);
        }
        out_.commit(n * sizeof(Event));
    }
    count_ += events.size();
}

void NpyWriter::close() {
    if (closed_) return;
    // The count goes into the header once every event is written (a temporary file until
    // out_.close() puts it under its name).
    out_.write_at(0, make_header(count_, with_score_));
    out_.close();
    closed_ = true;
}

namespace {

// A Python literal of the .npy header: dict, list/tuple, string, integer, True/False/None.
struct Py {
    enum Kind { str, num, boolean, none, seq, dict } kind = none;
    std::string s;
    std::uint64_t n = 0;
    bool b = false;
    std::vector<Py> items;         // seq; dict: the values
    std::vector<std::string> keys;  // dict: the keys of items
    const Py* get(std::string_view key) const {
        for (std::size_t i = 0; i < keys.size(); ++i)
            if (keys[i] == key) return &items[i];
        return nullptr;
    }
};

class PyParser {
public:
    explicit PyParser(std::string_view text) : t_(text) {}
    // nullopt on a syntax error.
    std::optional<Py> parse() {
        auto v = value(0);
        skip();
        if (!v || i_ != t_.size()) return std::nullopt;
        return v;
    }

private:
    void skip() {
        while (i_ < t_.size() && std::isspace(static_cast<unsigned char>(t_[i_]))) ++i_;
    }
    std::optional<Py> value(int depth) {
        if (depth > 16) return std::nullopt;
        skip();
        if (i_ >= t_.size()) return std::nullopt;
        const char c = t_[i_];
        Py v;
        if (c == '\'' || c == '"') {
            const auto e = t_.find(c, i_ + 1);
            if (e == std::string_view::npos) return std::nullopt;
            v.kind = Py::str;
            v.s = std::string(t_.substr(i_ + 1, e - i_ - 1));
            i_ = e + 1;
            return v;
        }
        if (c >= '0' && c <= '9') {
            v.kind = Py::num;
            int digits = 0;
            while (i_ < t_.size() && t_[i_] >= '0' && t_[i_] <= '9') {
                if (++digits > 18) return std::nullopt;
                v.n = v.n * 10 + static_cast<std::uint64_t>(t_[i_++] - '0');
            }
            if (i_ < t_.size() && t_[i_] == 'L') ++i_;  // Python 2 longs
            return v;
        }
        for (const auto& [word, kind, b] : {std::tuple{"True", Py::boolean, true}, {"False", Py::boolean, false},
                                            {"None", Py::none, false}}) {
            const std::string_view w(word);
            if (t_.substr(i_, w.size()) == w) {
                i_ += w.size();
                v.kind = kind;
                v.b = b;
                return v;
            }
        }
        if (c == '[' || c == '(' || c == '{') {
            const char close = c == '[' ? ']' : c == '(' ? ')' : '}';
            v.kind = c == '{' ? Py::dict : Py::seq;
            ++i_;
            for (;;) {
                skip();
                if (i_ < t_.size() && t_[i_] == close) {
                    ++i_;
                    return v;
                }
                auto item = value(depth + 1);
                if (!item) return std::nullopt;
                if (v.kind == Py::dict) {
                    skip();
                    if (item->kind != Py::str || i_ >= t_.size() || t_[i_] != ':') return std::nullopt;
                    ++i_;
                    auto val = value(depth + 1);
                    if (!val) return std::nullopt;
                    v.keys.push_back(item->s);
                    v.items.push_back(std::move(*val));
                } else {
                    v.items.push_back(std::move(*item));
                }
                skip();
                if (i_ < t_.size() && t_[i_] == ',') ++i_;
                else if (i_ >= t_.size() || t_[i_] != close) return std::nullopt;
            }
        }
        return std::nullopt;
    }
    std::string_view t_;
    std::size_t i_ = 0;
};

// A numpy type string ('<u2', '|b1', '>f8', 'u1', '?'): the field's type, or nullopt.
std::optional<NpyReader::Field> parse_type(std::string_view ts) {
    NpyReader::Field f;
    if (ts == "?" || ts == "b1") ts = "|b1";
    if (ts.size() < 2) return std::nullopt;
    char order = '=';
    if (ts[0] == '<' || ts[0] == '>' || ts[0] == '|' || ts[0] == '=') {
        order = ts[0];
        ts.remove_prefix(1);
    }
    if (ts.size() != 2) return std::nullopt;
    f.kind = ts[0];
    f.size = ts[1] - '0';
    const bool ok = (f.kind == 'i' || f.kind == 'u') ? (f.size == 1 || f.size == 2 || f.size == 4 || f.size == 8)
                    : f.kind == 'f'                 ? (f.size == 4 || f.size == 8)
                    : f.kind == 'b'                 ? f.size == 1
                                                    : false;
    if (!ok) return std::nullopt;
    f.swap = order == '>' && f.size > 1;
    return f;
}

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

// Which of t, x, y, p (0..3) a field name or --npy-columns name means; -1: none, -2: ignore ('_').
int role_of(const std::string& name) {
    const std::string n = lower(name);
    if (n == "t" || n == "ts" || n == "timestamp" || n == "time" || n == "t_us") return 0;
    if (n == "x") return 1;
    if (n == "y") return 2;
    if (n == "p" || n == "polarity" || n == "pol" || n == "on") return 3;
    if (n == "_") return -2;
    return -1;
}

constexpr const char* kRoleName[4] = {"t", "x", "y", "p"};

// What a header byte string looks like when quoted in a message: printable, escaped.
std::string printable(std::string_view s) {
    std::string r;
    for (const char c : s.substr(0, 200)) {
        const auto u = static_cast<unsigned char>(c);
        if (u >= 0x20 && u < 0x7f) r += c;
        else r += fmt::format("\\x{:02x}", u);
    }
    return r;
}

template <class T>
inline T load(const unsigned char* p, bool swap) noexcept {
    if constexpr (sizeof(T) == 1) {
        return static_cast<T>(*p);
    } else {
        using U = std::conditional_t<sizeof(T) == 2, std::uint16_t, std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>;
        U u;
        std::memcpy(&u, p, sizeof u);
        if (swap) {
            if constexpr (sizeof(T) == 2) u = __builtin_bswap16(u);
            else if constexpr (sizeof(T) == 4) u = __builtin_bswap32(u);
            else u = __builtin_bswap64(u);
        }
        return std::bit_cast<T>(u);
    }
}

// Calls fn(T{}) with the C++ type of field f.
template <class Fn>
void with_type(const NpyReader::Field& f, Fn&& fn) {
    switch (f.kind) {
        case 'i':
            if (f.size == 1) return fn(std::int8_t{});
            if (f.size == 2) return fn(std::int16_t{});
            if (f.size == 4) return fn(std::int32_t{});
            return fn(std::int64_t{});
        case 'u':
        case 'b':
            if (f.size == 1) return fn(std::uint8_t{});
            if (f.size == 2) return fn(std::uint16_t{});
            if (f.size == 4) return fn(std::uint32_t{});
            return fn(std::uint64_t{});
        default:
            if (f.size == 4) return fn(float{});
            return fn(double{});
    }
}

}  // namespace

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
    const std::string h(reinterpret_cast<const char*>(data()) + pre, len);
    consume(pre + len);

    const auto dict = PyParser(h).parse();
    if (!dict || dict->kind != Py::dict) fail(pre, "the .npy header is not a Python dict: '" + printable(h) + "'");
    const Py* descr = dict->get("descr");
    const Py* fortran = dict->get("fortran_order");
    const Py* shape = dict->get("shape");
    if (descr == nullptr || fortran == nullptr || shape == nullptr || shape->kind != Py::seq)
        fail(pre, "the .npy header lacks 'descr', 'fortran_order' or 'shape'");
    if (fortran->kind != Py::boolean || fortran->b)
        fail(pre, "Fortran-order arrays are not supported (save it with numpy.ascontiguousarray first)");
    for (const Py& d : shape->items)
        if (d.kind != Py::num) fail(pre, "the shape holds something other than integers");

    // Time unit: integers in us and floats in s unless told.
    const std::string& unit = this->options().csv_time_unit;
    if (!unit.empty() && unit != "us" && unit != "ns" && unit != "ms" && unit != "s")
        fail(pre, "unknown time unit '" + unit + "' (us, ns, ms or s)");

    std::array<int, 4> found{-1, -1, -1, -1};
    std::string layout_desc;
    if (descr->kind == Py::str) {
        // A plain numeric array: (N, 4), its columns named by npy_columns.
        const auto type = parse_type(descr->s);
        if (!type || type->kind == 'b')
            fail(pre, "unsupported dtype '" + printable(descr->s) +
                          "': a plain array must be integer or float (i1..i8, u1..u8, f4, f8)");
        if (shape->items.size() != 2 || shape->items[1].n != 4)
            fail(pre, fmt::format("a plain '{}' array must have the shape (N, 4) (its columns named by {}), "
                                  "or be a structured array with fields t, x, y, p",
                                  printable(descr->s), option_spelling(this->options(), "--npy-columns")));
        const std::string spec = this->options().npy_columns.empty() ? "t,x,y,p" : this->options().npy_columns;
        std::size_t start = 0;
        int col = 0;
        for (;; ++col) {
            const auto comma = spec.find(',', start);
            const std::string name = spec.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
            const int role = role_of(name);
            if (role == -1 || col >= 4)
                fail(pre, option_spelling(this->options(), "--npy-columns") + " '" + spec + "' must name 4 columns, each t, x, y, p or _");
            if (role >= 0) {
                if (found[static_cast<std::size_t>(role)] >= 0) fail(pre, option_spelling(this->options(), "--npy-columns") + " '" + spec + "' names a column twice");
                found[static_cast<std::size_t>(role)] = col;
                fields_[role] = *type;
                fields_[role].offset = static_cast<std::size_t>(col * type->size);
            }
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
        if (col != 3 || std::find(found.begin(), found.end(), -1) != found.end())
            fail(pre, option_spelling(this->options(), "--npy-columns") + " '" + spec + "' must name 4 columns and each of t, x, y, p once");
        itemsize_ = static_cast<std::size_t>(4 * type->size);
        declared_ = shape->items[0].n;
        fast_ = false;
    } else if (descr->kind == Py::seq) {
        // A structured array: fields found by name.
        std::size_t offset = 0;
        for (const Py& f : descr->items) {
            if (f.kind != Py::seq || f.items.size() < 2 || f.items[0].kind != Py::str || f.items[1].kind != Py::str)
                fail(pre, "unsupported dtype: a field that is not ('name', 'type') (nested or titled fields)");
            const std::string& name = f.items[0].s;
            const std::string& ts = f.items[1].s;
            std::size_t size = 0;
            // Fields that are not events may be of any fixed-size type ('V3', 'S8', '<f8', ...).
            const auto type = parse_type(ts);
            if (type) {
                size = static_cast<std::size_t>(type->size);
            } else {
                std::size_t k = 0;
                while (k < ts.size() && !std::isdigit(static_cast<unsigned char>(ts[k]))) ++k;
                if (k == ts.size() || ts.size() - k > 6)
                    fail(pre, "unsupported dtype '" + printable(ts) + "' of field '" + printable(name) + "'");
                size = std::stoul(ts.substr(k));
                if (ts.find('U') != std::string::npos) size *= 4;  // numpy's UCS4 strings
            }
            if (f.items.size() > 2) size = 0;  // a sub-array field: not one of ours
            const int role = role_of(name);
            if (role >= 0) {
                if (f.items.size() > 2) fail(pre, "field '" + printable(name) + "' is an array; a scalar is expected");
                if (!type)
                    fail(pre, "field '" + printable(name) + "' has the unsupported type '" + printable(ts) +
                                  "' (integers, floats or bool are read)");
                if (found[static_cast<std::size_t>(role)] >= 0)
                    fail(pre, fmt::format("two fields give {} (one of them '{}')", kRoleName[role], printable(name)));
                if (role == 0 && type->kind == 'b') fail(pre, "the time field '" + printable(name) + "' is bool");
                found[static_cast<std::size_t>(role)] = 1;
                fields_[role] = *type;
                fields_[role].offset = offset;
            } else if (lower(name) == "score" && type && f.items.size() == 2) {
                score_field_ = *type;
                score_field_.offset = offset;
                has_score_ = true;
            } else if (f.items.size() > 2) {
                fail(pre, "unsupported dtype: field '" + printable(name) + "' is a sub-array");
            }
            offset += size;
        }
        for (int r = 0; r < 4; ++r)
            if (found[static_cast<std::size_t>(r)] < 0)
                fail(pre, fmt::format("the structured dtype has no {} field (looked for {})", kRoleName[r],
                                      r == 0   ? "t, ts, timestamp, time, t_us"
                                      : r == 3 ? "p, polarity, pol, on"
                                               : kRoleName[r]));
        if (shape->items.size() != 1) fail(pre, "a structured array must be one-dimensional (shape (N,))");
        itemsize_ = offset;
        declared_ = shape->items[0].n;
        // The evcorner layout (and its packed form): the copying fast path.
        const auto is = [&](int r, char kind, int size, std::size_t off) {
            return fields_[r].kind == kind && fields_[r].size == size && !fields_[r].swap && fields_[r].offset == off;
        };
        const bool int_time = unit.empty() || unit == "us";
        fast_ = (itemsize_ == 16 || itemsize_ == 13) && int_time && is(0, 'i', 8, 0) && is(1, 'u', 2, 8) &&
                is(2, 'u', 2, 10) && (is(3, 'u', 1, 12) || is(3, 'b', 1, 12)) &&
                (itemsize_ == 13 || descr->items.size() == 4 || descr->items.size() == 5);
        if (itemsize_ > 4096) fail(pre, fmt::format("records of {} bytes: larger than 4096 bytes are not read", itemsize_));
    } else {
        fail(pre, "unsupported dtype: 'descr' is neither a type string nor a list of fields");
    }
    // Time conversion.
    const bool float_time = fields_[0].kind == 'f';
    const std::string u = unit.empty() ? (float_time ? "s" : "us") : unit;
    time_scale_ = u == "s" ? 1e6 : u == "ms" ? 1e3 : u == "us" ? 1.0 : 1e-3;
    time_mul_ = u == "s" ? 1'000'000 : u == "ms" ? 1000 : 1;
    time_div_ = u == "ns" ? 1000 : 1;
    whole_time_ = float_time && (unit == "us" || unit == "ns");

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

bool NpyReader::decode() { return fast_ ? decode_fast() : decode_general(); }

bool NpyReader::decode_fast() {
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

bool NpyReader::decode_general() {
    if (read_ == declared_) return false;
    const std::size_t avail = fill(itemsize_);
    if (avail < itemsize_)
        fail(offset(), fmt::format("the file ends after {} of the {} events the header declares", read_, declared_));
    const std::size_t records =
        static_cast<std::size_t>(std::min<std::uint64_t>({avail / itemsize_, batch_room(), declared_ - read_}));
    const unsigned char* p = data();
    const std::uint64_t base = offset();
    const std::size_t stride = itemsize_;
    ct_.resize(records);
    if (has_score_) {
        cs_.resize(records);
        if (scores_.size() < batch_count() + batch_room()) scores_.resize(batch_count() + batch_room());
        with_type(score_field_, [&](auto tag) {
            using T = decltype(tag);
            const unsigned char* q = p + score_field_.offset;
            for (std::size_t i = 0; i < records; ++i)
                cs_[i] = static_cast<double>(load<T>(q + i * stride, score_field_.swap));
        });
    }
    cx_.resize(records);
    cy_.resize(records);
    cp_.resize(records);

    // Each field converted column-wise; `bad` is the first record with a value that is
    // not an event's (a fraction for x, a polarity of 5, a time out of range).
    std::size_t bad = records;
    int bad_field = -1;
    std::string why;
    const auto mark = [&](std::size_t i, int field, std::string reason) {
        if (i < bad) {
            bad = i;
            bad_field = field;
            why = std::move(reason);
        }
    };
    {
        const Field f = fields_[0];
        with_type(f, [&](auto tag) {
            using T = decltype(tag);
            const unsigned char* q = p + f.offset;
            std::int64_t* out = ct_.data();
            if constexpr (std::is_floating_point_v<T>) {
                const double scale = time_scale_;
                const bool whole = whole_time_;
                for (std::size_t i = 0; i < records; ++i) {
                    const double raw = static_cast<double>(load<T>(q + i * stride, f.swap));
                    const double v = raw * scale;
                    if (!(std::fabs(v) < 9.2e18)) [[unlikely]] {
                        mark(i, 0, fmt::format("time {} is not a finite number in range", v));
                        break;
                    }
                    if (whole && raw != static_cast<double>(static_cast<std::int64_t>(raw))) [[unlikely]] {
                        mark(i, 0, fmt::format("time {} has a fraction, but {} is {} (whole numbers: "
                                               "a float time is seconds unless the unit is given)",
                                               raw, option_spelling(this->options(), "--time-unit"),
                                               this->options().csv_time_unit));
                        break;
                    }
                    out[i] = static_cast<std::int64_t>(v + (v >= 0 ? 0.5 : -0.5));  // nearest, halves away from zero
                }
            } else {
                const std::int64_t mul = time_mul_, div = time_div_;
                for (std::size_t i = 0; i < records; ++i) {
                    const T raw = load<T>(q + i * stride, f.swap);
                    if constexpr (std::is_same_v<T, std::uint64_t>) {
                        if (raw > static_cast<std::uint64_t>(INT64_MAX)) [[unlikely]] {
                            mark(i, 0, fmt::format("time {} does not fit 63 bits", raw));
                            break;
                        }
                    }
                    const auto v = static_cast<std::int64_t>(raw);
                    if (mul > 1 && (v > INT64_MAX / mul || v < INT64_MIN / mul)) [[unlikely]] {
                        mark(i, 0, fmt::format("time {} overflows in microseconds", v));
                        break;
                    }
                    if (div > 1) {
                        // Nearest microsecond, halves away from zero.
                        const std::int64_t q = v / div, r = v % div;
                        out[i] = q + (r >= div / 2 ? 1 : r <= -div / 2 ? -1 : 0);
                    } else {
                        out[i] = v * mul;
                    }
                }
            }
        });
    }
    for (int c = 1; c <= 2; ++c) {
        const Field f = fields_[c];
        std::uint32_t* out = c == 1 ? cx_.data() : cy_.data();
        with_type(f, [&](auto tag) {
            using T = decltype(tag);
            const unsigned char* q = p + f.offset;
            for (std::size_t i = 0; i < records; ++i) {
                const T v = load<T>(q + i * stride, f.swap);
                bool ok;
                // (A cast and back, not std::floor: floor is a library call without SSE4.1.)
                if constexpr (std::is_floating_point_v<T>) ok = v >= 0 && v <= 65535 && static_cast<T>(static_cast<std::uint32_t>(v)) == v;
                else if constexpr (std::is_signed_v<T>) ok = v >= 0 && static_cast<std::int64_t>(v) <= 65535;
                else ok = static_cast<std::uint64_t>(v) <= 65535;
                if (!ok) [[unlikely]] {
                    mark(i, c, fmt::format("{} = {} is not an integer in 0..65535", kRoleName[c], v));
                    break;
                }
                out[i] = static_cast<std::uint32_t>(v);
            }
        });
    }
    {
        const Field f = fields_[3];
        with_type(f, [&](auto tag) {
            using T = decltype(tag);
            const unsigned char* q = p + f.offset;
            std::uint32_t* out = cp_.data();
            for (std::size_t i = 0; i < records; ++i) {
                const T v = load<T>(q + i * stride, f.swap);
                if (v == T(1)) out[i] = 1;
                else if (v == T(0)) out[i] = 0;
                else if (std::is_signed_v<T> && v == T(-1)) out[i] = 0;
                else [[unlikely]] {
                    mark(i, 3, fmt::format("polarity {} where 1 (ON), 0 or -1 (OFF) is expected", v));
                    break;
                }
            }
        });
    }

    std::size_t i = 0;
    while (i < bad) {
        const std::size_t at = batch_count();
        const std::size_t run = push_run(bad - i, [&](std::size_t k, Event& e) {
            const std::size_t j = i + k;
            e.t = ct_[j];
            e.x = static_cast<std::uint16_t>(cx_[j]);
            e.y = static_cast<std::uint16_t>(cy_[j]);
            e.p = static_cast<std::uint8_t>(cp_[j]);
        });
        if (has_score_) std::copy_n(cs_.begin() + static_cast<std::ptrdiff_t>(i), run, scores_.begin() + static_cast<std::ptrdiff_t>(at));
        i += run;
        if (i == bad) break;
        const std::size_t before = batch_count();
        push(ct_[i], cx_[i], cy_[i], cp_[i] != 0, base + i * stride);
        if (has_score_ && batch_count() > before) scores_[before] = cs_[i];  // not skipped
        ++i;
    }
    if (bad < records) {
        read_ += bad;
        consume(bad * stride);
        fail(base + bad * stride + fields_[bad_field].offset, why);
    }
    read_ += records;
    consume(records * stride);
    return true;
}

}  // namespace evcorner::io
