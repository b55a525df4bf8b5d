#pragma once
// The paper's figures (Mueggler et al., BMVC 2017) drawn from events and corner events.
// Every figure is a pure function of its inputs: events in time order, a time `at`
// (microseconds, the same clock as the events) or an interval, and a style.
//
//   render_sae            Fig. 2b: the SAE of one polarity, grey, newest bright.
//   render_recent_corners Fig. 6:  events of the last 33 ms grey; corner events of the last
//                                  33 ms bright and of the last 100 ms dark, green = ON, red = OFF.
//   render_space_time     Fig. 1b / 5b: events and corner events over [t0, t1] in an oblique
//                                  projection, time upwards; corners coloured by polarity, or
//                                  by label (green on a feature track, red off it).
//   render_tracks         feature tracks as trails over the events of the last 33 ms, one
//                                  colour per track id, a dot at each track's latest sample.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/render/image.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/track_point.hpp"

namespace evcorner::render {

inline constexpr Rgb kOnBright{40, 230, 40}, kOnDark{0, 110, 0};
inline constexpr Rgb kOffBright{240, 40, 40}, kOffDark{120, 0, 0};
inline constexpr Rgb kOnTrack{0, 170, 0}, kOffTrack{220, 0, 0};

/// Fig. 2b: pixel value 255 (1 - (at - t) / window) for the newest event of `polarity`
/// at or before `at`, 0 for older ones and pixels that never fired. One image pixel per
/// sensor pixel.
RgbImage render_sae(std::span<const Event> events, SensorSize size, int polarity, std::int64_t at,
                    std::int64_t window_us);

struct RecentCornersStyle {
    std::int64_t events_window_us = 33'000;  ///< grey events of (at - this, at]
    std::int64_t recent_us = 33'000;         ///< bright corners of (at - this, at]
    std::int64_t older_us = 100'000;         ///< dark corners of (at - this, at - recent]
    int corner_side = 3;                     ///< corner dot side, sensor pixels
};

/// Fig. 6 on black; one image pixel per sensor pixel.
RgbImage render_recent_corners(std::span<const Event> events, std::span<const Event> corners, SensorSize size,
                               std::int64_t at, const RecentCornersStyle& style = {});

struct SpaceTimeStyle {
    int scale = 2;            ///< image pixels per sensor pixel
    int time_height = 360;    ///< image pixels (before scale) for the time axis
    double depth = 0.5;       ///< image pixels per pixel of y, drawn up and to the right
    int corner_side = 2;      ///< image pixels per corner dot, before scale
};

/// The oblique projection of render_space_time: x to the right, y into the page (up and
/// to the right by `depth` per pixel), time upwards.
struct SpaceTimeLayout {
    SensorSize size;
    SpaceTimeStyle style;
    int margin = 0;             ///< blank image pixels around the box
    int width = 0, height = 0;  ///< the image's size

    /// Image position of sensor point (x, y) at relative time tau (0 = t0, 1 = t1).
    void project(double x, double y, double tau, int& u, int& v) const noexcept;
};
/// Throws std::invalid_argument for a scale or time height < 1.
SpaceTimeLayout space_time_layout(SensorSize size, const SpaceTimeStyle& style);

/// Fig. 1b (labels empty: corners green ON / red OFF) and Fig. 5b (labels given, one per
/// corner: green on a track, red off it). Events and corners outside [t0, t1] are left out.
/// White background; sensor box edges at t0 and t1 in grey.
RgbImage render_space_time(std::span<const Event> events, std::span<const Event> corners,
                           std::span<const std::uint8_t> labels, SensorSize size, std::int64_t t0,
                           std::int64_t t1, const SpaceTimeStyle& style = {});

struct TracksStyle {
    std::int64_t events_window_us = 33'000;  ///< grey events of (at - this, at], as in Fig. 6
    std::int64_t trail_us = 100'000;         ///< track samples of (at - this, at] are drawn
    int scale = 2;                           ///< image pixels per sensor pixel
    int line_width = 1;                      ///< trail width, sensor pixels
    int dot_side = 3;                        ///< side of the dot at a track's latest sample, sensor pixels
};

/// The colour of track `id`: a fixed palette of saturated colours (none grey), cycled by id.
Rgb track_colour(std::uint64_t id) noexcept;
/// How many colours track_colour cycles through.
inline constexpr std::size_t kTrackPaletteSize = 10;

/// Feature tracks on black, `style.scale` image pixels per sensor pixel: the events of
/// (at - events_window_us, at] grey (as Fig. 6 draws them, then upscaled); for each track
/// id, its samples of (at - trail_us, at] joined in time order (ties in the given order)
/// by a line of track_colour(id), and a dot of that colour at the latest of them. A
/// sample's (x, y) is in the pixel-index convention, the centre of sensor pixel (x, y):
/// image point ((x + 0.5) scale, (y + 0.5) scale). Samples are in any order; their time is
/// seconds on the events' clock. Throws std::invalid_argument for a scale, line width or
/// dot side < 1.
RgbImage render_tracks(std::span<const Event> events, std::span<const TrackPoint> tracks, SensorSize size,
                       std::int64_t at, const TracksStyle& style = {});
/// The ids render_tracks draws (those with a sample in (at - trail_us, at]), ascending, once each.
std::vector<std::uint64_t> drawn_track_ids(std::span<const TrackPoint> tracks, std::int64_t at,
                                           const TracksStyle& style = {});

}  // namespace evcorner::render
