#include "evcorner/track/track_writer.hpp"

#include <charconv>
#include <cmath>
#include <cstring>

#include "evcorner/error.hpp"
#include "evcorner/io/npy.hpp"
#include "evcorner/io/output_file.hpp"

namespace evcorner {

namespace {

constexpr std::string_view kNpyDescr =
    "[('id', '<u8'), ('t', '<i8'), ('x', '<f4'), ('y', '<f4'), ('theta', '<f4'), ('change', '|u1')]";
constexpr std::size_t kNpyRecord = 29;

/// Longest field: an id (20 digits), or a float in %.6f (39 integer digits, sign, point, 6).
constexpr std::size_t kField = 48;

template <class T>
void append_int(std::string& s, T v) {
    char b[kField];
    s.append(b, std::to_chars(b, b + kField, v).ptr);
}

/// n / 1e6 with six decimals: "12.000345".
void append_millionths(std::string& s, std::uint64_t n) {
    append_int(s, n / 1000000);
    char frac[7] = {'.', '0', '0', '0', '0', '0', '0'};
    for (std::uint64_t f = n % 1000000, i = 6; f > 0; f /= 10, --i) frac[i] = static_cast<char>('0' + f % 10);
    s.append(frac, 7);
}

/// As printf's "%.6f": the exact decimal value, rounded to 6 places, ties to even. A float
/// times 1e6 is exact in a double (24 + 14 significant bits), so below 2^53 / 1e6 the rounded
/// product is the answer; beyond, and for NaN and infinities, to_chars' fixed form (specified
/// as printf's).
void append_fixed6(std::string& s, float v) {
    const double scaled = static_cast<double>(v) * 1e6;
    if (!(std::fabs(scaled) < 0x1p53)) {
        char b[kField];
        s.append(b, std::to_chars(b, b + kField, v, std::chars_format::fixed, 6).ptr);
        return;
    }
    const auto micro = static_cast<std::uint64_t>(std::nearbyint(std::fabs(scaled)));  // the default mode: ties to even
    if (std::signbit(v)) s += '-';
    append_millionths(s, micro);
}

/// Seconds from microseconds, exactly: "-0.000123", "12.345678".
void append_seconds(std::string& s, std::int64_t us) {
    const bool neg = us < 0;
    const std::uint64_t a = neg ? 0 - static_cast<std::uint64_t>(us) : static_cast<std::uint64_t>(us);
    if (neg) s += '-';
    append_millionths(s, a);
}

/// A time in microseconds, written as seconds.
struct Micros {
    std::int64_t us;
};

void append_field(std::string& s, std::uint64_t v) { append_int(s, v); }
void append_field(std::string& s, Micros t) { append_seconds(s, t.us); }
void append_field(std::string& s, float v) { append_fixed6(s, v); }
void append_field(std::string& s, const char* v) { s += v; }

/// The fields joined by `sep`, then a newline.
template <class First, class... Rest>
void append_row(std::string& s, char sep, const First& first, const Rest&... rest) {
    append_field(s, first);
    ((s += sep, append_field(s, rest)), ...);
    s += '\n';
}

}  // namespace

struct TrackWriter::Out {
    explicit Out(const std::string& path) : file(path) {}
    io::OutputFile file;
    std::string buf;
};

std::optional<TrackFormat> parse_track_format(std::string_view name) noexcept {
    if (name == "ddft") return TrackFormat::ddft;
    if (name == "haste") return TrackFormat::haste;
    if (name == "csv") return TrackFormat::csv;
    if (name == "npy") return TrackFormat::npy;
    return std::nullopt;
}

TrackFormat track_format_for(std::string_view path) noexcept {
    const auto ends = [&](std::string_view ext) {
        return path.size() >= ext.size() && path.substr(path.size() - ext.size()) == ext;
    };
    if (ends(".npy")) return TrackFormat::npy;
    if (ends(".csv")) return TrackFormat::csv;
    return TrackFormat::ddft;
}

TrackWriter::TrackWriter(const std::string& path, TrackFormat format) : format_(format) {
    if (format == TrackFormat::npy && path == "-")
        throw OutputError("<stdout>", "a .npy track file cannot go to standard output (its header holds the count)");
    out_ = std::make_unique<Out>(path);
    if (format == TrackFormat::csv) out_->file.write("id,t,x,y,theta,change\n");
    if (format == TrackFormat::npy) out_->file.write(io::npy_header(kNpyDescr, 0));
}

TrackWriter::~TrackWriter() = default;

void TrackWriter::write(std::span<const TrackState> states) {
    std::string& s = out_->buf;
    s.clear();
    for (const TrackState& st : states) {
        switch (format_) {
            case TrackFormat::ddft:
                append_row(s, ' ', st.id, Micros{st.t}, st.x, st.y);
                break;
            case TrackFormat::haste:
                append_row(s, ',', Micros{st.t}, st.x, st.y, st.theta, st.id);
                break;
            case TrackFormat::csv:
                append_row(s, ',', st.id, Micros{st.t}, st.x, st.y, st.theta, change_name(st.why));
                break;
            case TrackFormat::npy: {
                char r[kNpyRecord];
                std::memcpy(r, &st.id, 8);
                std::memcpy(r + 8, &st.t, 8);
                std::memcpy(r + 16, &st.x, 4);
                std::memcpy(r + 20, &st.y, 4);
                std::memcpy(r + 24, &st.theta, 4);
                r[28] = static_cast<char>(st.why);
                s.append(r, kNpyRecord);
                break;
            }
        }
    }
    out_->file.write(s);
    rows_ += states.size();
}

void TrackWriter::close() {
    if (closed_) return;
    if (format_ == TrackFormat::npy) out_->file.write_at(0, io::npy_header(kNpyDescr, rows_));
    out_->file.close();
    closed_ = true;
}

}  // namespace evcorner
