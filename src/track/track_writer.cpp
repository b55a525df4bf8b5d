#include "evcorner/track/track_writer.hpp"

#include <cstring>
#include <fmt/format.h>

#include "evcorner/error.hpp"
#include "evcorner/io/npy.hpp"
#include "evcorner/io/output_file.hpp"

namespace evcorner {

namespace {

constexpr std::string_view kNpyDescr =
    "[('id', '<u8'), ('t', '<i8'), ('x', '<f4'), ('y', '<f4'), ('theta', '<f4'), ('change', '|u1')]";
constexpr std::size_t kNpyRecord = 29;

/// Seconds from microseconds, exactly: "-0.000123", "12.345678".
void append_seconds(std::string& s, std::int64_t us) {
    const bool neg = us < 0;
    const std::uint64_t a = neg ? 0 - static_cast<std::uint64_t>(us) : static_cast<std::uint64_t>(us);
    fmt::format_to(std::back_inserter(s), "{}{}.{:06d}", neg ? "-" : "", a / 1000000, a % 1000000);
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
                fmt::format_to(std::back_inserter(s), "{} ", st.id);
                append_seconds(s, st.t);
                fmt::format_to(std::back_inserter(s), " {:.6f} {:.6f}\n", st.x, st.y);
                break;
            case TrackFormat::haste:
                append_seconds(s, st.t);
                fmt::format_to(std::back_inserter(s), ",{:.6f},{:.6f},{:.6f},{}\n", st.x, st.y, st.theta, st.id);
                break;
            case TrackFormat::csv:
                fmt::format_to(std::back_inserter(s), "{},", st.id);
                append_seconds(s, st.t);
                fmt::format_to(std::back_inserter(s), ",{:.6f},{:.6f},{:.6f},{}\n", st.x, st.y, st.theta,
                               change_name(st.why));
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
