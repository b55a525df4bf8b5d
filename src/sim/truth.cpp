#include "evcorner/sim/truth.hpp"

#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <filesystem>
#include <fstream>

#include "evcorner/error.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/sim/geometry.hpp"
#include "evcorner/sim/motion.hpp"

namespace evcorner::sim {

std::string_view to_string(CornerState s) noexcept {
    switch (s) {
        case CornerState::visible: return "visible";
        case CornerState::occluded: return "occluded";
        case CornerState::outside: return "outside";
    }
    return "?";
}

void corners_at(const Scene& scene, std::int64_t t_us, std::vector<TruthCorner>& out) {
    const double t_s = static_cast<double>(t_us) / 1e6;
    // Every object's pieces where they are at t, for the occlusion tests.
    std::vector<std::vector<std::vector<Vec2>>> placed(scene.objects.size());
    std::vector<Pose> poses;
    poses.reserve(scene.objects.size());
    for (std::size_t o = 0; o < scene.objects.size(); ++o) {
        const Object& obj = scene.objects[o];
        poses.emplace_back(obj.motion, t_s, scene.duration_s);
        for (const Piece& p : obj.pieces) {
            std::vector<Vec2> poly;
            poly.reserve(p.polygon.size());
            for (const Vec2& v : p.polygon) poly.push_back(poses.back().apply(v));
            placed[o].push_back(std::move(poly));
        }
    }
    for (std::size_t o = 0; o < scene.objects.size(); ++o) {
        const Object& obj = scene.objects[o];
        for (std::size_t c = 0; c < obj.corners.size(); ++c) {
            TruthCorner tc;
            tc.t_us = t_us;
            tc.object = static_cast<int>(o);
            tc.corner = static_cast<int>(c);
            const Vec2 p = poses[o].apply(obj.corners[c].position);
            const Vec2 v = poses[o].velocity(obj.corners[c].position);
            tc.x = p.x;
            tc.y = p.y;
            tc.vx = v.x;
            tc.vy = v.y;
            tc.angle_deg = obj.corners[c].angle_deg;
            if (!(p.x >= 0 && p.y >= 0 && p.x < scene.sensor.width && p.y < scene.sensor.height)) {
                tc.state = CornerState::outside;
            } else {
                for (std::size_t f = o + 1; f < scene.objects.size() && tc.state == CornerState::visible; ++f)
                    for (const auto& poly : placed[f])
                        if (inside(poly, p)) {
                            tc.state = CornerState::occluded;
                            break;
                        }
            }
            out.push_back(tc);
        }
    }
}

TruthWriter::TruthWriter(const std::string& path) : out_(std::make_unique<io::OutputFile>(path)) {
    out_->write(kTruthHeader);
    out_->write("\n");
}

TruthWriter::~TruthWriter() = default;

void TruthWriter::write(std::span<const TruthCorner> rows) {
    std::string line;
    for (const TruthCorner& r : rows) {
        line.clear();
        fmt::format_to(std::back_inserter(line), "{},{},{},{:.6f},{:.6f},{:.4f},{:.4f},{:.4f},{:.4f},{},{}\n", r.t_us,
                       r.object, r.corner, r.x, r.y, r.angle_deg, r.vx, r.vy, std::hypot(r.vx, r.vy),
                       r.state == CornerState::visible ? 1 : 0, to_string(r.state));
        out_->write(line);
    }
    rows_ += rows.size();
}

void TruthWriter::close() { out_->close(); }

namespace {

template <class T>
T field(std::string_view s, const std::string& path, std::uint64_t line, const char* name) {
    T v{};
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size() || s.empty())
        throw InputError(path, InputError::Unit::line, line, std::string("field ") + name + " is not a number");
    if constexpr (std::is_floating_point_v<T>)
        if (!std::isfinite(v)) throw InputError(path, InputError::Unit::line, line, std::string("field ") + name + " is not finite");
    return v;
}

}  // namespace

struct TruthReader::Impl {
    std::ifstream in;
    std::string text;
    std::vector<std::string_view> f;
};

TruthReader::TruthReader(const std::string& path) : path_(path), in_(std::make_unique<Impl>()) {
    in_->in.open(path, std::ios::binary);
    if (!in_->in) throw InputError(path, "cannot open");
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    total_ = ec ? 0 : static_cast<std::uint64_t>(size);
    std::string& text = in_->text;
    if (!std::getline(in_->in, text)) throw InputError(path, "empty file: expected the header " + std::string(kTruthHeader));
    ++line_no_;
    consumed_ += text.size() + 1;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (text != kTruthHeader) throw InputError(path, InputError::Unit::line, 1, "expected the header " + std::string(kTruthHeader));
}

TruthReader::~TruthReader() = default;

bool TruthReader::read_row(TruthCorner& r) {
    std::string& text = in_->text;
    std::vector<std::string_view>& f = in_->f;
    const std::string& path = path_;
    for (;;) {
        if (!std::getline(in_->in, text)) {
            if (in_->in.bad()) throw InputError(path, "read failed");
            return false;
        }
        ++line_no_;
        consumed_ += text.size() + 1;
        if (!text.empty() && text.back() == '\r') text.pop_back();
        if (!text.empty()) break;
    }
    const std::uint64_t line_no = line_no_;
    f.clear();
    std::size_t start = 0;
    for (;;) {
        const std::size_t comma = text.find(',', start);
        f.emplace_back(std::string_view(text).substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    if (f.size() != 11)
        throw InputError(path, InputError::Unit::line, line_no, "expected 11 fields, got " + std::to_string(f.size()));
    r.t_us = field<std::int64_t>(f[0], path, line_no, "t_us");
    r.object = field<int>(f[1], path, line_no, "object");
    r.corner = field<int>(f[2], path, line_no, "corner");
    r.x = field<double>(f[3], path, line_no, "x");
    r.y = field<double>(f[4], path, line_no, "y");
    r.angle_deg = field<double>(f[5], path, line_no, "angle_deg");
    r.vx = field<double>(f[6], path, line_no, "vx");
    r.vy = field<double>(f[7], path, line_no, "vy");
    (void)field<double>(f[8], path, line_no, "speed");
    const int vis = field<int>(f[9], path, line_no, "visible");
    if (f[10] == "visible") r.state = CornerState::visible;
    else if (f[10] == "occluded") r.state = CornerState::occluded;
    else if (f[10] == "outside") r.state = CornerState::outside;
    else throw InputError(path, InputError::Unit::line, line_no, "state must be visible, occluded or outside");
    if (vis != (r.state == CornerState::visible ? 1 : 0))
        throw InputError(path, InputError::Unit::line, line_no, "visible disagrees with state");
    if (r.object < 0 || r.corner < 0) throw InputError(path, InputError::Unit::line, line_no, "negative index");
    if (r.t_us < last_t_) throw InputError(path, InputError::Unit::line, line_no, "rows out of time order");
    last_t_ = r.t_us;
    return true;
}

bool TruthReader::next_sample(std::vector<TruthCorner>& rows) {
    rows.clear();
    if (!has_pending_ && !read_row(pending_)) return false;
    has_pending_ = false;
    rows.push_back(pending_);
    TruthCorner r;
    while (read_row(r)) {
        if (r.t_us != rows.front().t_us) {
            pending_ = r;
            has_pending_ = true;
            break;
        }
        rows.push_back(r);
    }
    return true;
}

std::vector<TruthCorner> read_truth_csv(const std::string& path) {
    TruthReader reader(path);
    std::vector<TruthCorner> all, rows;
    while (reader.next_sample(rows)) all.insert(all.end(), rows.begin(), rows.end());
    return all;
}

}  // namespace evcorner::sim
