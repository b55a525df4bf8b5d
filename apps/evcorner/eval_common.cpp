#include "eval_common.hpp"

#include <cmath>
#include <stdexcept>

#include "commands.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/io/open.hpp"
#include "progress.hpp"

namespace evcorner::cli {

std::unique_ptr<io::EventReader> open_events(const std::string& path, const InputOptions& o) {
    io::ReaderOptions ropts = o.reader;
    if (!o.size.empty()) ropts.sensor = parse_sensor_size(o.size);
    return io::open_event_reader(path, ropts, o.format);
}

SensorSize sensor_of(const io::EventReader& reader) { return reader.sensor().value_or(kDavis240); }

LoadedEvents load_events(const std::string& path, const InputOptions& o, bool progress) {
    const auto reader = open_events(path, o);
    Progress bar(progress, reader->bytes_total());
    LoadedEvents out;
    out.events = io::read_all_events(
        *reader, [&](const std::vector<Event>& all) { bar.update(reader->bytes_consumed(), all.size()); });
    bar.finish();
    out.size = sensor_of(*reader);
    return out;
}

void add_load_options(CLI::App& cmd, InputOptions& o) {
    add_reader_options(cmd, o.format, o.reader);
    cmd.add_option("--size", o.size, "Sensor size WxH [default: the file's own, else 240x180]")
        ->check([](const std::string& s) {
            return parse_sensor_size(s) ? std::string() : "expected WxH with sides 1..65536, e.g. 346x260";
        });
}

void add_feature_track_options(CLI::App& cmd, eval::FeatureTrackParams& p, std::string& overlap) {
    const auto group = "Feature tracks (docs/evaluation.md)";
    cmd.add_option("--ft-inner", p.inner_radius, "Inner cylinder radius, px")->capture_default_str()->group(group);
    cmd.add_option("--ft-outer", p.outer_radius, "Outer cylinder radius, px")->capture_default_str()->group(group);
    cmd.add_option("--ft-min-inner", p.min_inner, "Corner events needed in the inner cylinder")
        ->capture_default_str()
        ->group(group);
    cmd.add_option("--ft-max-outer-ratio", p.max_outer_ratio, "Largest outer-shell to inner ratio")
        ->capture_default_str()
        ->group(group);
    cmd.add_option("--ft-max-duration", p.max_duration_us,
                   "Longest hypothesis (time between its two corner events), microseconds")
        ->capture_default_str()
        ->group(group);
    cmd.add_option("--ft-max-length", p.max_length, "Largest image distance between the two corner events, px")
        ->capture_default_str()
        ->group(group);
    cmd.add_flag("--ft-per-polarity", p.same_polarity,
                 "Pairs and cylinder contents of one polarity only [default: both polarities]")
        ->group(group);
    cmd.add_option("--ft-overlap", overlap,
                   "Tracks sharing corners: any (a corner is correct if inner to any accepted track) or "
                   "exclusive (accepted tracks claim their corners, anchors in time order)")
        ->capture_default_str()
        ->check(CLI::IsMember({"any", "exclusive"}))
        ->group(group);
}

void finish_feature_track_params(eval::FeatureTrackParams& p, const std::string& overlap) {
    p.overlap = eval::parse_track_overlap(overlap);
    eval::validate(p);
}

std::vector<Event> detect_corners(const DetectorConfig& detector, const std::vector<Event>& events, SensorSize size) {
    AnyDetector det = make_detector(detector, size, "--");
    std::vector<std::uint8_t> flags(events.size());
    std::visit([&](auto& d) { detect(d, std::span<const Event>(events), flags); }, det);
    std::vector<Event> corners;
    for (std::size_t i = 0; i < events.size(); ++i)
        if (flags[i]) corners.push_back(events[i]);
    return corners;
}

std::int64_t parse_time_option(const std::string& text, std::int64_t first_us, std::int64_t last_us) {
    if (text.empty()) throw std::invalid_argument("empty time");
    std::size_t used = 0;
    double v = 0;
    const bool rel = text[0] == '+' || text[0] == '-';
    try {
        v = std::stod(rel ? text.substr(1) : text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() - (rel ? 1 : 0) || !std::isfinite(v) || v < 0)
        throw std::invalid_argument("bad time '" + text + "' (seconds, '+S' after the start or '-S' before the end)");
    // Times are integer microseconds: 9.2e12 s (292 000 years) is the most they hold.
    constexpr double kMaxSeconds = 9.2e12;
    if (v > kMaxSeconds)
        throw std::invalid_argument("time '" + text + "' is out of range (at most 9.2e12 s: times are integer microseconds)");
    const auto us = static_cast<std::int64_t>(std::llround(v * 1e6));
    std::int64_t t = us;
    if ((text[0] == '+' && __builtin_add_overflow(first_us, us, &t)) ||
        (text[0] == '-' && __builtin_sub_overflow(last_us, us, &t)))
        throw std::invalid_argument("time '" + text + "' is out of range of the stream's clock");
    return t;
}

}  // namespace evcorner::cli
