#include "evcorner/track/track_file.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <string_view>

#include "evcorner/error.hpp"
#include "evcorner/io/decompress.hpp"
#include "evcorner/io/input_file.hpp"
#include "evcorner/io/line_source.hpp"

namespace evcorner {

namespace {

bool parse_real(std::string_view f, double& v) {
    const char* b = f.data();
    const char* e = b + f.size();
    if (b < e && *b == '+') ++b;
    const auto r = std::from_chars(b, e, v);
    return r.ec == std::errc{} && r.ptr == e && std::isfinite(v);
}

bool parse_id(std::string_view f, std::uint64_t& id) {
    const auto r = std::from_chars(f.data(), f.data() + f.size(), id);
    if (r.ec == std::errc{} && r.ptr == f.data() + f.size()) return true;
    // "3.000000": a whole number written as a float (the HASTE app prints ids so)
    double v;
    if (!parse_real(f, v) || v < 0 || v != std::floor(v) || v >= 1.8e19) return false;
    id = static_cast<std::uint64_t>(v);
    return true;
}

// Splits [b, e) at any run of `sep` characters (spaces and tabs, or one comma) into at most
// 8 fields; returns the count (9 when there are more).
int split(const char* b, const char* e, bool commas, std::string_view* f) {
    int n = 0;
    if (commas) {
        const char* s = b;
        for (const char* c = b;; ++c) {
            if (c == e || *c == ',') {
                std::string_view v(s, static_cast<std::size_t>(c - s));
                while (!v.empty() && (v.front() == ' ' || v.front() == '\t')) v.remove_prefix(1);
                while (!v.empty() && (v.back() == ' ' || v.back() == '\t')) v.remove_suffix(1);
                if (n == 8) return 9;
                f[n++] = v;
                if (c == e) break;
                s = c + 1;
            }
        }
        return n;
    }
    const char* p = b;
    for (;;) {
        while (p < e && (*p == ' ' || *p == '\t')) ++p;
        if (p == e) return n;
        const char* s = p;
        while (p < e && *p != ' ' && *p != '\t') ++p;
        if (n == 8) return 9;
        f[n++] = std::string_view(s, static_cast<std::size_t>(p - s));
    }
}

std::vector<TrackPoint> read_text(io::InputFile file, bool csv) {
    io::LineSource src(std::move(file));
    std::vector<TrackPoint> out;
    const char *b, *e;
    enum class Layout { unknown, ddft, haste } layout = Layout::unknown;
    bool header = csv;
    std::string_view f[8];
    while (src.next(b, e)) {
        const char* s = b;
        while (s < e && (*s == ' ' || *s == '\t')) ++s;
        if (s == e || *s == '#') continue;
        if (header) {
            if (std::string_view(s, static_cast<std::size_t>(e - s)).substr(0, 21) != "id,t,x,y,theta,change")
                src.fail(b, e, "a track CSV starts with the header id,t,x,y,theta,change");
            header = false;
            continue;
        }
        const bool commas = std::memchr(s, ',', static_cast<std::size_t>(e - s)) != nullptr;
        TrackPoint p{};
        if (csv) {
            if (split(s, e, true, f) != 6) src.fail(b, e, "a track CSV row has 6 fields: id,t,x,y,theta,change");
            if (!parse_id(f[0], p.id)) src.fail(b, e, "the id must be a whole number >= 0");
            if (!parse_real(f[1], p.t) || !parse_real(f[2], p.x) || !parse_real(f[3], p.y))
                src.fail(b, e, "t, x and y must be finite numbers");
            out.push_back(p);
            continue;
        }
        const Layout here = commas ? Layout::haste : Layout::ddft;
        if (layout == Layout::unknown) layout = here;
        if (here != layout)
            src.fail(b, e, layout == Layout::ddft ? "an earlier line had the `id t x y` layout; this one has commas"
                                                   : "an earlier line had the `t,x,y,theta,id` layout; this one has none");
        if (here == Layout::ddft) {
            if (split(s, e, false, f) != 4) src.fail(b, e, "a track row is `id t x y` (4 fields)");
            if (!parse_id(f[0], p.id)) src.fail(b, e, "the id must be a whole number >= 0");
            if (!parse_real(f[1], p.t) || !parse_real(f[2], p.x) || !parse_real(f[3], p.y))
                src.fail(b, e, "t, x and y must be finite numbers");
        } else {
            if (split(s, e, true, f) != 5) src.fail(b, e, "a HASTE track row is `t,x,y,theta,id` (5 fields)");
            double theta;
            if (!parse_real(f[0], p.t) || !parse_real(f[1], p.x) || !parse_real(f[2], p.y) || !parse_real(f[3], theta))
                src.fail(b, e, "t, x, y and theta must be finite numbers");
            if (!parse_id(f[4], p.id)) src.fail(b, e, "the id must be a whole number >= 0");
        }
        out.push_back(p);
    }
    return out;
}

constexpr std::string_view kNpyDescr =
    "{'descr': [('id', '<u8'), ('t', '<i8'), ('x', '<f4'), ('y', '<f4'), ('theta', '<f4'), ('change', '|u1')], "
    "'fortran_order': False, 'shape': (";
constexpr std::size_t kNpyRecord = 29;

std::vector<TrackPoint> read_npy(io::InputFile file) {
    const std::string name = file.name();
    std::string bytes;
    char buf[1 << 16];
    for (std::size_t n; (n = file.read(buf)) > 0;) bytes.append(buf, n);
    const auto bad = [&](std::uint64_t at, const std::string& why) {
        return InputError(name, InputError::Unit::byte, at, why);
    };
    if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0) throw bad(0, "not a .npy file");
    std::size_t header_len = 0, start = 0;
    if (bytes[6] == 1) {
        header_len = static_cast<unsigned char>(bytes[8]) | static_cast<std::size_t>(static_cast<unsigned char>(bytes[9])) << 8;
        start = 10;
    } else {
        if (bytes.size() < 12) throw bad(0, "the .npy header is cut short");
        header_len = 0;
        for (int i = 3; i >= 0; --i) header_len = header_len << 8 | static_cast<unsigned char>(bytes[8 + i]);
        start = 12;
    }
    if (bytes.size() < start + header_len) throw bad(start, "the .npy header is cut short");
    const std::string_view header(bytes.data() + start, header_len);
    if (header.substr(0, kNpyDescr.size()) != kNpyDescr)
        throw bad(start, "not a track array: the header must declare the record [('id','<u8'), ('t','<i8'), ('x','<f4'), "
                         "('y','<f4'), ('theta','<f4'), ('change','|u1')], one-dimensional, C order");
    std::uint64_t count = 0;
    const char* cb = header.data() + kNpyDescr.size();
    const auto r = std::from_chars(cb, header.data() + header.size(), count);
    if (r.ec != std::errc{} || r.ptr >= header.data() + header.size() || *r.ptr != ',')
        throw bad(start, "the .npy shape must be (N,)");
    const std::size_t data = start + header_len;
    const std::uint64_t have = (bytes.size() - data) / kNpyRecord;
    if (have != count || (bytes.size() - data) % kNpyRecord != 0)
        throw bad(data, "the header declares " + std::to_string(count) + " records; the file holds " +
                            std::to_string(bytes.size() - data) + " bytes of data (" + std::to_string(kNpyRecord) +
                            " per record)");
    std::vector<TrackPoint> out(count);
    for (std::uint64_t i = 0; i < count; ++i) {
        const char* rec = bytes.data() + data + i * kNpyRecord;
        std::int64_t t;
        float x, y;
        std::memcpy(&out[i].id, rec, 8);
        std::memcpy(&t, rec + 8, 8);
        std::memcpy(&x, rec + 16, 4);
        std::memcpy(&y, rec + 20, 4);
        out[i].t = static_cast<double>(t) / 1e6;
        out[i].x = x;
        out[i].y = y;
    }
    return out;
}

bool ends_with(std::string_view s, std::string_view x) {
    return s.size() >= x.size() && s.substr(s.size() - x.size()) == x;
}

}  // namespace

std::vector<TrackPoint> read_track_points(const std::string& path) {
    io::InputFile file(path);
    if (const auto c = io::compression_from_magic(file.peek(8))) file.decompress(*c);
    std::string_view stem = path;
    for (std::string_view z : {".gz", ".zst", ".xz", ".bz2"})
        if (ends_with(stem, z)) stem.remove_suffix(z.size());
    if (ends_with(stem, ".npy")) return read_npy(std::move(file));
    return read_text(std::move(file), ends_with(stem, ".csv"));
}

}  // namespace evcorner
