// evcorner render: the paper's figures as PNG images, or SVG / PDF.
//
//   sae         Fig. 2b: SAE of one polarity, grey, newest bright
//   corners     Fig. 6:  events of the last 33 ms grey, corners of the last 33 / 100 ms
//   space-time  Fig. 1b: events and corner events over an interval, time upwards
//   labels      Fig. 5b: corner events in space-time, green on a feature track, red off
//   tracks      the tracks of a track file (--tracks) as trails over the last 33 ms of events
//
// The input is streamed: every batch goes through the detector (its state needs the whole
// past up to --at), and only the events and corner events the figure can draw are kept.
// When --at counts from the end (absent, or "-S"), the end is unknown until it comes, so
// the kept events are the trailing span the figure could need, trimmed batch by batch.
// Memory follows the drawn window, never the stream's length; the one exception is
// --ft-overlap exclusive for labels, whose claims chain from the stream's start, so its
// corner events (not its events) are kept from the start.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <span>
#include <filesystem>
#include <fmt/format.h>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "detector_options.hpp"
#include "eval_common.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/error.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/render/figures.hpp"
#include "evcorner/render/frame.hpp"
#include "evcorner/state_memory.hpp"
#include "evcorner/track/track_file.hpp"
#include "progress.hpp"

namespace evcorner::cli {

namespace {

constexpr std::size_t kBatch = 1 << 16;
// The default space-time window: the time the last kAutoEvents events before --at span,
// rounded down to two significant digits, at most kAutoMaxUs. About 20 000 events trace the
// moving edges as tubes and sheets on the box; a whole 52 s recording or even one second of
// it merges into a grey block, and a few thousand leave scattered dots. The
// window follows the event rate: the 650 k events/s sample gets 30 ms, a sparse recording at
// most half a second. Bounded by a count, it also bounds what streaming keeps.
constexpr std::size_t kAutoEvents = 20'000;
constexpr std::int64_t kAutoMaxUs = 500'000;
constexpr std::int64_t kNoBound = std::numeric_limits<std::int64_t>::min() / 4;

struct RenderOptions {
    std::string input;
    std::string output;
    std::string kind = "corners";
    std::string detector = "efast";
    ParamValues detector_params;
    std::string corners_file;
    std::string tracks_file;
    std::string at;
    double window_ms = 0;  // 0: the kind's default
    int scale = 2;
    int polarity = 1;
    int time_height = 360;
    bool no_frame = false;
    bool no_progress = false;
    InputOptions in;
    eval::FeatureTrackParams params;
    std::string overlap = "any";
};

std::string seconds(std::int64_t us) { return fmt::format("{:.6f} s", static_cast<double>(us) * 1e-6); }

std::string duration(std::int64_t us) {
    auto trim = [](std::string s) {
        if (s.find('.') != std::string::npos) {
            while (s.back() == '0') s.pop_back();
            if (s.back() == '.') s.pop_back();
        }
        return s;
    };
    if (us < 1000) return fmt::format("{} us", us);
    if (us < 10'000'000) return trim(fmt::format("{:.3f}", static_cast<double>(us) / 1e3)) + " ms";
    return trim(fmt::format("{:.6f}", static_cast<double>(us) / 1e6)) + " s";
}

// `us` rounded to two significant digits, down or up (at least 1).
std::int64_t round_two_digits(std::int64_t us, bool up) {
    if (us <= 1) return 1;
    std::int64_t p = 1;
    while (us / p >= 100) p *= 10;
    const std::int64_t down = us / p * p;
    return up && down < us ? down + p : down;
}

// What the figure shows of the input, by time; events.txt shows as "folder/events.txt"
// so that the sequences of a data set tell apart.
std::string shown_name(const std::string& path) {
    if (path == "-") return "<stdin>";
    const std::filesystem::path p(path);
    const auto parent = p.parent_path().filename();
    return parent.empty() ? p.filename().string() : (parent / p.filename()).string();
}

// The span of the stream a figure needs, relative to the time drawn (`at`).
struct Need {
    std::int64_t events_before = 0;   // events of [at - this, at]
    std::int64_t corners_before = 0;  // corner events of [at - this, at + corners_after]
    std::int64_t corners_after = 0;
    bool corners = true;              // any corner events at all
    bool corners_from_start = false;  // every corner event up to at + corners_after
    bool auto_window = false;         // space-time window from the event rate
};

std::int64_t window_us(double ms) { return static_cast<std::int64_t>(std::llround(ms * 1000.0)); }

Need need_for(const RenderOptions& o) {
    Need n;
    const std::int64_t w = o.window_ms > 0 ? window_us(o.window_ms) : 0;
    if (o.kind == "sae") {
        n.events_before = w > 0 ? w : 50'000;
        n.corners = false;
    } else if (o.kind == "corners") {
        const render::RecentCornersStyle style;
        n.events_before = style.events_window_us;
        n.corners_before = w > 0 ? w : style.older_us;
    } else if (o.kind == "tracks") {
        n.events_before = render::TracksStyle{}.events_window_us;
        n.corners = false;
    } else {
        n.auto_window = w == 0;
        n.events_before = w > 0 ? w : kAutoMaxUs;
        n.corners_before = n.events_before;
        if (o.kind == "labels") {
            // A corner's label depends on the corners within max_duration of it ("any");
            // under "exclusive", claims made earlier change later ones, from the start.
            n.corners_before += o.params.max_duration_us;
            n.corners_after = o.params.max_duration_us;
            n.corners_from_start = o.params.overlap == eval::TrackOverlap::exclusive;
        }
    }
    return n;
}

// Events in time order, dropped from the front: a ring that doubles when full (so at
// most twice what it holds), made contiguous once at the end for the figure.
class Trail {
public:
    void push_back(const Event& e) {
        if (count_ == ring_.size()) grow();
        ring_[(head_ + count_) & (ring_.size() - 1)] = e;
        ++count_;
    }
    [[nodiscard]] bool empty() const noexcept { return count_ == 0; }
    [[nodiscard]] std::size_t size() const noexcept { return count_; }
    [[nodiscard]] const Event& front() const noexcept { return ring_[head_]; }
    void pop_front() noexcept {
        head_ = (head_ + 1) & (ring_.size() - 1);
        --count_;
    }
    /// The events, oldest first, in one span (rotates the ring in place).
    std::span<const Event> span() {
        if (count_ == 0) return {};
        std::rotate(ring_.begin(), ring_.begin() + static_cast<std::ptrdiff_t>(head_), ring_.end());
        head_ = 0;
        return {ring_.data(), count_};
    }
    void assign(std::vector<Event> v) {
        count_ = v.size();
        head_ = 0;
        ring_ = std::move(v);
        std::size_t cap = 1;
        while (cap < ring_.size()) cap *= 2;
        ring_.resize(cap);
    }

private:
    void grow() {
        std::vector<Event> bigger(std::max<std::size_t>(1024, ring_.size() * 2));
        for (std::size_t i = 0; i < count_; ++i) bigger[i] = ring_[(head_ + i) & (ring_.size() - 1)];
        ring_ = std::move(bigger);
        head_ = 0;
    }
    std::vector<Event> ring_;  // size: a power of two (or 0)
    std::size_t head_ = 0, count_ = 0;
};

// What streaming the input keeps.
struct Kept {
    SensorSize size;
    std::int64_t first = 0, last = 0;  // of the events read
    std::uint64_t events_read = 0;
    std::int64_t at = 0;
    Trail events;
    Trail corners;
    bool events_trimmed_before_at = false;  // some event <= at was dropped as too old
};

// The figure's images (the sensor-sized drawing, its upscaled copy and the framed figure),
// 3 bytes a pixel, before anything is allocated: --size and --scale decide them.
void require_figure_fits(const RenderOptions& o, SensorSize size) {
    const auto w = static_cast<std::uint64_t>(size.width), h = static_cast<std::uint64_t>(size.height);
    const auto s = static_cast<std::uint64_t>(o.scale);
    std::uint64_t body_w = w * s, body_h = h * s, need = 0;
    if (o.kind == "sae" || o.kind == "corners" || o.kind == "tracks") {
        need = w * h * 3 + 2 * body_w * body_h * 3;
    } else {
        render::SpaceTimeStyle style;
        style.scale = o.scale;
        style.time_height = o.time_height;
        const render::SpaceTimeLayout layout = render::space_time_layout(size, style);
        body_w = static_cast<std::uint64_t>(layout.width);
        body_h = static_cast<std::uint64_t>(layout.height);
        need = 2 * body_w * body_h * 3;
    }
    require_memory_fits(fmt::format("render -k {}: a {}x{} figure ({}x{} sensor, --scale {})", o.kind, body_w, body_h,
                                    size.width, size.height, o.scale),
                        need, " (lower --scale, or --time-height for space-time figures)");
}

// Reads the input batch by batch, detects, keeps what `need` asks for.
Kept stream_input(const RenderOptions& o, const Need& need, bool detect_here) {
    const auto reader = open_events(o.input, o.in);
    Kept k;
    k.size = sensor_of(*reader);
    require_figure_fits(o, k.size);
    std::optional<AnyDetector> detector;
    if (detect_here) detector = make_detector(DetectorConfig{o.detector, o.detector_params}, k.size, "--");
    // --at known from the first event on (seconds, "+S"), or only at the end (absent, "-S").
    const bool at_from_end = o.at.empty() || o.at[0] == '-';
    const std::int64_t back_from_end =
        o.at.empty() ? 0 : (at_from_end ? -parse_time_option(o.at, 0, 0) : 0);  // S of "-S"
    std::optional<std::int64_t> at;
    Progress progress(!o.no_progress, reader->bytes_total());
    std::vector<Event> batch(kBatch);
    std::vector<std::uint8_t> flags(kBatch);
    bool stop = false, before_start = false;
    while (!stop) {
        const std::size_t n = reader->read(batch);
        if (n == 0) {
            if (reader->skipped_in_batch().empty()) break;
            continue;
        }
        const std::span<const Event> b(batch.data(), n);
        if (k.events_read == 0) {
            k.first = b.front().t;
            if (!at_from_end) {
                at = parse_time_option(o.at, k.first, k.first);
                // Before the stream: the error names the stream's range, so read on to its end.
                before_start = *at < k.first;
                if (before_start) detector.reset();
            }
        }
        if (before_start) {
            k.events_read += n;
            k.last = b.back().t;
            progress.update(reader->bytes_consumed(), k.events_read);
            continue;
        }
        if (detector) std::visit([&](auto& d) { detect(d, b, flags); }, *detector);
        for (std::size_t i = 0; i < n; ++i) {
            const Event& e = b[i];
            if (at && e.t > *at + need.corners_after) {
                stop = true;  // nothing later is drawn or needed
                break;
            }
            if (!at || e.t <= *at) k.events.push_back(e);
            if (detector && flags[i]) k.corners.push_back(e);
        }
        k.events_read += n;
        k.last = b.back().t;
        // Trim what no figure can need any more.
        const std::int64_t at_bound = at ? *at : k.last - back_from_end;  // the latest --at can be
        const std::int64_t ev_lo = at_bound - need.events_before;
        while (!k.events.empty() && k.events.front().t < ev_lo) {
            k.events_trimmed_before_at |= k.events.front().t <= at_bound;
            k.events.pop_front();
        }
        // The default window needs only the last kAutoEvents events before --at.
        if (need.auto_window && (at || back_from_end == 0))
            while (k.events.size() > kAutoEvents) {
                k.events.pop_front();
                k.events_trimmed_before_at = true;
            }
        if (!need.corners_from_start) {
            const std::int64_t c_lo = at_bound - need.corners_before;
            while (!k.corners.empty() && k.corners.front().t < c_lo) k.corners.pop_front();
        }
        progress.update(reader->bytes_consumed(), k.events_read);
    }
    progress.finish();
    if (k.events_read == 0) throw InputError(o.input, "no events to draw (the input holds none)");
    const std::int64_t t = at ? *at : (o.at.empty() ? k.last : parse_time_option(o.at, k.first, k.last));
    if (t < k.first || (!stop && t > k.last))
        throw std::invalid_argument(fmt::format("--at {}: {} is outside the stream, which runs from {} to {}", o.at,
                                                seconds(t), seconds(k.first), seconds(k.last)));
    k.at = t;
    return k;
}

// Corner events from a file, streamed: those of [lo, hi].
std::vector<Event> stream_corners_file(const RenderOptions& o, std::int64_t lo, std::int64_t hi) {
    const auto reader = open_events(o.corners_file, o.in);
    std::vector<Event> out;
    std::vector<Event> batch(kBatch);
    for (;;) {
        const std::size_t n = reader->read(batch);
        if (n == 0) {
            if (reader->skipped_in_batch().empty()) break;
            continue;
        }
        for (std::size_t i = 0; i < n; ++i) {
            if (batch[i].t > hi) return out;
            if (batch[i].t >= lo) out.push_back(batch[i]);
        }
    }
    return out;
}

std::string detector_text(const RenderOptions& o) {
    if (!o.corners_file.empty()) return "corner events from " + shown_name(o.corners_file);
    std::string s = "detector " + o.detector;
    for (const auto& [key, value] : o.detector_params) s += " " + key + "=" + format_param_value(value);
    return s;
}

// The figure's format from its name: *.png, *.svg or *.pdf; a device or pipe that already
// exists (/dev/null, a FIFO) gets a PNG: those have no name to mislead.
render::FigureFormat check_output_name(const std::string& path) {
    std::error_code ec;
    const auto st = std::filesystem::status(path, ec);
    if (!ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st) &&
        !std::filesystem::is_directory(st))
        return render::FigureFormat::png;
    const std::string ext = std::filesystem::path(path).extension().string();
    const auto f = ext.size() == 4 ? render::figure_format_of(ext) : std::nullopt;
    if (!f)
        throw std::invalid_argument("-o " + path +
                                    ": render writes PNG, SVG or PDF images only; give a name ending in .png, .svg "
                                    "or .pdf");
    return *f;
}

void run_render(RenderOptions& o) {
    finish_feature_track_params(o.params, o.overlap);
    const render::FigureFormat format = check_output_name(o.output);
    io::check_output_paths({{"INPUT", o.input}, {"--corners", o.corners_file}, {"--tracks", o.tracks_file}},
                           {{"-o", o.output}});
    io::check_outputs_creatable({{"-o", o.output}});
    if (!o.at.empty()) (void)parse_time_option(o.at, 0, 0);  // its syntax, before reading anything
    const Need need = need_for(o);
    const bool from_file = !o.corners_file.empty();
    // Parameters are checked before reading anything, and refused where nothing is detected.
    if (!o.detector_params.empty() && (!need.corners || from_file))
        throw std::invalid_argument("detector parameters given, but this figure runs no detector (" +
                                    std::string(from_file ? "--corners" : "-k " + o.kind) + ")");
    if (need.corners && !from_file) check_detector_config(DetectorConfig{o.detector, o.detector_params}, "--");
    // The track file before the events: a malformed one fails before the stream is read.
    std::vector<TrackPoint> tracks;
    if (o.kind == "tracks") tracks = read_track_points(o.tracks_file);
    Kept k = stream_input(o, need, need.corners && !from_file);
    const std::int64_t at = k.at;

    // The window drawn; for the default space-time window, from the event rate.
    std::int64_t window = need.events_before;
    if (need.auto_window) {
        std::size_t before = 0;  // kept events at or before --at
        const std::span<const Event> kept = k.events.span();
        for (const Event& e : kept) before += e.t <= at;
        std::int64_t span = 0;
        if (before >= kAutoEvents) {
            std::size_t i = 0;
            for (const Event& e : kept)
                if (e.t <= at && ++i == before - kAutoEvents + 1) {
                    span = at - e.t;
                    break;
                }
            window = round_two_digits(span, false);
        } else {
            window = k.events_trimmed_before_at ? kAutoMaxUs : round_two_digits(at - k.first, true);
        }
        window = std::clamp<std::int64_t>(window, 1, kAutoMaxUs);
    }
    if (from_file) {
        const std::int64_t lo = need.corners_from_start
                                    ? kNoBound
                                    : at - (need.auto_window ? window + (need.corners_before - kAutoMaxUs)
                                                             : need.corners_before);
        k.corners.assign(stream_corners_file(o, lo, at + need.corners_after));
    }
    const std::span<const Event> events = k.events.span(), corners = k.corners.span();
    const std::string file = shown_name(o.input);
    const std::string det = detector_text(o);

    render::FigureFrame frame;
    std::string what;
    render::RgbImage img;                   // the figure alone (--no-frame)
    std::optional<render::Canvas> framed;  // the figure in its frame
    if (o.kind == "sae" || o.kind == "corners" || o.kind == "tracks") {
        render::RgbImage body;
        if (o.kind == "sae") {
            const std::string pol = o.polarity ? "ON" : "OFF";
            body = render::upscale(render::render_sae(events, k.size, o.polarity, at, window), o.scale);
            frame.title = {fmt::format("SAE of the {} events (Fig. 2b): {}", pol, file),
                           fmt::format("t = {}; no detector (the SAE is the detectors' input)", seconds(at))};
            frame.grey_ramp = true;
            frame.ramp = {"age of the newest " + pol + " event:", "0", duration(window) + " or never"};
            what = fmt::format("at t = {}, fading over {}", seconds(at), duration(window));
        } else if (o.kind == "corners") {
            render::RecentCornersStyle style;
            style.older_us = window = need.corners_before;
            body = render::upscale(render::render_recent_corners(events, corners, k.size, at, style), o.scale);
            const std::string recent = duration(style.recent_us), older = duration(style.older_us);
            frame.title = {fmt::format("Corner events (Fig. 6): {}", file),
                           fmt::format("{}; t = {}", det, seconds(at)),
                           fmt::format("events of the last {}; corners of the last {} (bright), {} (dark)",
                                       duration(style.events_window_us), recent, older)};
            frame.legend = {{{150, 150, 150}, "event, last " + duration(style.events_window_us)},
                            {render::kOnBright, "ON corner, last " + recent},
                            {render::kOnDark, "ON corner, " + recent + " to " + older},
                            {render::kOffBright, "OFF corner, last " + recent},
                            {render::kOffDark, "OFF corner, " + recent + " to " + older}};
            what = fmt::format("at t = {}, corners of the last {}", seconds(at), older);
        } else {
            render::TracksStyle style;
            style.scale = o.scale;
            if (o.window_ms > 0) style.trail_us = window_us(o.window_ms);
            window = style.trail_us;
            body = render::render_tracks(events, tracks, k.size, at, style);
            const std::vector<std::uint64_t> ids = render::drawn_track_ids(tracks, at, style);
            const std::string trail = duration(window);
            const std::string count = fmt::format("{} track{}", ids.size(), ids.size() == 1 ? "" : "s");
            frame.title = {fmt::format("Feature tracks: {}", file),
                           fmt::format("tracks from {}; t = {}", shown_name(o.tracks_file), seconds(at)),
                           fmt::format("events of the last {}; trails of the last {}, a dot at each track's latest "
                                       "sample; {}",
                                       duration(style.events_window_us), trail, count)};
            frame.legend = {{{150, 150, 150}, "event, last " + duration(style.events_window_us)}};
            constexpr std::size_t kLegendTracks = 8;  // a legend for hundreds of tracks says nothing
            for (std::size_t i = 0; i < ids.size() && i < kLegendTracks; ++i)
                frame.legend.push_back({render::track_colour(ids[i]), fmt::format("track {}", ids[i])});
            if (ids.size() > kLegendTracks)
                frame.title.back() += fmt::format(" (legend: the first {})", kLegendTracks);
            what = fmt::format("at t = {}, trails of the last {}, {}", seconds(at), trail, count);
        }
        if (o.no_frame)
            img = std::move(body);
        else
            framed = render::frame_sensor_figure(body, k.size, o.scale, frame).figure;
    } else {
        const std::int64_t t0 = at - window;
        render::SpaceTimeStyle style;
        style.scale = o.scale;
        style.time_height = o.time_height;
        std::vector<std::uint8_t> labels;
        const bool labelled = o.kind == "labels";
        if (labelled) labels = eval::label_feature_tracks(corners, o.params).on_track;
        const render::RgbImage body = render::render_space_time(events, corners, labels, k.size, t0, at, style);
        std::size_t drawn_events = 0, drawn_corners = 0;
        for (const Event& e : events) drawn_events += e.t >= t0 && e.t <= at;
        for (const Event& e : corners) drawn_corners += e.t >= t0 && e.t <= at;
        const std::string span = fmt::format("window {}{}: t0 = {} to t1 = {}", duration(window),
                                             need.auto_window ? " (default)" : "", seconds(t0), seconds(at));
        if (labelled) {
            frame.title = {fmt::format("Corner events labelled by feature tracks (Fig. 5b): {}", file),
                           fmt::format("{}; {}", det, span),
                           fmt::format("{} events, {} corner events; tracks: inner {} px, outer {} px, {} inner "
                                       "needed, overlap {}",
                                       drawn_events, drawn_corners, o.params.inner_radius, o.params.outer_radius,
                                       o.params.min_inner, eval::to_string(o.params.overlap))};
            frame.legend = {{{185, 185, 185}, "event"},
                            {render::kOnTrack, "corner event on a feature track"},
                            {render::kOffTrack, "corner event on no track"}};
        } else {
            frame.title = {fmt::format("Events and corner events in space-time (Fig. 1b): {}", file),
                           fmt::format("{}; {}", det, span),
                           fmt::format("{} events, {} corner events", drawn_events, drawn_corners)};
            frame.legend = {{{185, 185, 185}, "event"},
                            {render::kOnBright, "ON corner event"},
                            {render::kOffBright, "OFF corner event"}};
        }
        what = fmt::format("{} from t0 = {} to {}, {} events, {} corner events", duration(window), seconds(t0),
                           seconds(at), drawn_events, drawn_corners);
        if (o.no_frame)
            img = body;
        else
            framed = render::frame_space_time_figure(body, k.size, t0, at, style, frame).figure;
    }
    if (!framed && format == render::FigureFormat::png)
        render::write_png(o.output, img);
    else
        (framed ? *framed : framed.emplace(img)).write(o.output, format);
    const int width = framed ? framed->width() : img.width(), height = framed ? framed->height() : img.height();
    fmt::print(stderr, "render: {} {}x{}, {} -> {}\n", o.kind, width, height, what, o.output);
}

}  // namespace

void add_render_command(CLI::App& app) {
    auto o = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render",
        "Draw the paper's figures as PNG, SVG or PDF (by -o's extension): SAE, corners,\n"
        "space-time view, labelled corners, feature tracks.\n"
        "Kinds: sae (Fig. 2b), corners (Fig. 6: events of the last 33 ms, corner events of the\n"
        "last 33 ms bright and 100 ms dark, green ON / red OFF), space-time (Fig. 1b), labels\n"
        "(Fig. 5b: green on a feature track, red off it) and tracks (the tracks of --tracks FILE\n"
        "over the events of the last 33 ms: each track's samples of the last 100 ms as a trail\n"
        "in a colour per id, a dot at its latest). Each figure gets a title (file, detector,\n"
        "time and window), axes in sensor pixels (and time), and a legend; --no-frame draws\n"
        "the figure alone. The input is streamed: memory follows the window drawn, not the\n"
        "length of the input.");
    cmd->add_option("INPUT", o->input, "Event file (any format evcorner reads)")->required();
    cmd->add_option("-o,--output", o->output, "Figure to write: .png, .svg or .pdf (the frame as vector graphics, the figure in it a "
                    "raster), or an existing device or FIFO (PNG)")->required();
    cmd->add_option("-k,--kind", o->kind, "sae, corners, space-time, labels or tracks")
        ->capture_default_str()
        ->check(CLI::IsMember({"sae", "corners", "space-time", "labels", "tracks"}));
    add_detector_option(*cmd, o->detector, "Detector for the corner events:" + detectors_help());
    add_param_options(*cmd, o->detector_params);
    cmd->add_option("--corners", o->corners_file, "Take the corner events from this file instead of detecting");
    cmd->add_option("--tracks", o->tracks_file,
                    "tracks: the track file to draw (what `evcorner track` writes: `id t x y`, haste, .csv "
                    "or .npy; t in seconds on the events' clock, x y pixel indices)");
    cmd->add_option("--at", o->at,
                    "Time drawn (end of the interval): seconds on the stream's clock, +S after the first "
                    "event, -S before the last; it must lie within the stream [default: the last event]");
    cmd->add_option("--window", o->window_ms,
                    "Milliseconds, > 0: sae: age that fades to black [50]; corners: dark-corner span [100]; "
                    "tracks: trail span [100]; "
                    "space-time/labels: interval before --at [the time the last 20 000 events before --at "
                    "span, rounded down to two significant digits, at most 500 ms]")
        ->check([](const std::string& s) {
            try {
                const double v = std::stod(s);
                if (std::isfinite(v) && v > 0 && v <= 1e9) return std::string();
            } catch (const std::exception&) {
            }
            return "must be a number of milliseconds > 0 and at most 1e9 (11.6 days), not '" + s + "'";
        });
    cmd->add_option("--scale", o->scale, "Image pixels per sensor pixel")->capture_default_str()->check(CLI::Range(1, 16));
    cmd->add_option("--polarity", o->polarity, "sae: polarity shown, 1 = ON, 0 = OFF")
        ->capture_default_str()
        ->check(CLI::Range(0, 1));
    cmd->add_option("--time-height", o->time_height, "space-time/labels: height of the time axis, pixels before --scale")
        ->capture_default_str()
        ->check(CLI::Range(16, 4096));
    cmd->add_flag("--no-frame", o->no_frame, "The figure alone: no title, axes or legend");
    cmd->add_flag("--no-progress", o->no_progress, "No progress bar (drawn only when standard error is a terminal)");
    add_load_options(*cmd, o->in);
    add_feature_track_options(*cmd, o->params, o->overlap);
    cmd->footer(
        "Examples:\n"
        "  evcorner render events.txt -k corners -o fig6.png --at +0.04\n"
        "  evcorner render events.txt -k labels -d harris -o fig5b.png\n"
        "  evcorner render events.txt -k sae --polarity 0 --window 30 -o sae.png\n"
        "  evcorner render events.txt -k space-time -o fig1b.pdf           (for a paper)\n"
        "  evcorner render events.txt -k tracks --tracks tracks.txt -o tracks.png  (from evcorner track -d efast)");
    cmd->callback([o, cmd] {
        // An option that changes nothing in the figure asked for is a usage error.
        auto only_for = [&](const char* option, std::initializer_list<const char*> kinds) {
            if (cmd->count(option) == 0) return;
            std::string list;
            for (const char* k : kinds) {
                if (o->kind == k) return;
                list += (list.empty() ? "-k " : " or ") + std::string(k);  // "-k corners or space-time"
            }
            throw std::invalid_argument(std::string(option) + " applies to " + list + " only (this is -k " + o->kind +
                                        ")");
        };
        only_for("--polarity", {"sae"});
        only_for("--tracks", {"tracks"});
        if (o->kind == "tracks" && cmd->count("--tracks") == 0)
            throw std::invalid_argument("-k tracks needs --tracks FILE: the track file to draw");
        only_for("--corners", {"corners", "space-time", "labels"});
        only_for("--detector", {"corners", "space-time", "labels"});
        if (cmd->count("--detector") && cmd->count("--corners"))
            throw std::invalid_argument("--detector with --corners: the corner events come from the file, nothing is "
                                        "detected");
        only_for("--time-height", {"space-time", "labels"});
        for (const char* ft : {"--ft-inner", "--ft-outer", "--ft-min-inner", "--ft-max-outer-ratio", "--ft-max-duration",
                               "--ft-max-length", "--ft-per-polarity", "--ft-overlap"})
            only_for(ft, {"labels"});
        run_render(*o);
    });
}

}  // namespace evcorner::cli
