// Feature-track labelling on synthetic corner streams whose labels are known by
// construction: straight and oblique tracks are found, clutter is rejected, a track
// with too many corner events in its outer shell is rejected.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <stdexcept>
#include <vector>

#include "evcorner/eval/feature_tracks.hpp"
#include "feature_tracks_reference.hpp"
#include "evcorner/io/text_reader.hpp"

#include <filesystem>
#include <string>

namespace evcorner::eval {
namespace {

struct Stream {
    std::vector<Event> corners;
    std::vector<std::uint8_t> truth;  // 1: generated on an accepted track
};

struct Track {
    double x0, y0;  // px at t0
    double vx, vy;  // px per ms
    std::int64_t t0_us;
    int count;
    std::int64_t step_us;
};

Event at(double x, double y, std::int64_t t, int p = 1) {
    return Event{t, static_cast<std::uint16_t>(std::lround(x)), static_cast<std::uint16_t>(std::lround(y)),
                 static_cast<std::uint8_t>(p)};
}

// Corner events along a track, with +-1 px jitter (the detectors' localisation noise).
void add_track(Stream& s, const Track& tr, std::uint8_t label, std::mt19937& rng, int jitter = 1, int polarity = 1) {
    std::uniform_int_distribution<int> j(-jitter, jitter);
    for (int i = 0; i < tr.count; ++i) {
        const std::int64_t t = tr.t0_us + i * tr.step_us;
        const double ms = static_cast<double>(t - tr.t0_us) / 1000.0;
        s.corners.push_back(at(tr.x0 + tr.vx * ms + j(rng), tr.y0 + tr.vy * ms + j(rng), t, polarity));
        s.truth.push_back(label);
    }
}

// Uniform clutter over 240x180 and [0, span). Clutter is rejected by construction only
// when no hypothesis can reach a track: a clutter event is kept only if it lies more than
// max_length + outer radius (25 px) from every track event within the longest hypothesis
// (100 ms). Nearer, a pair (track event, clutter event) whose axis follows the track and
// leaves it after the track ends is a legitimate feature track of the method.
void add_clutter(Stream& s, int count, std::int64_t span_us, std::mt19937& rng) {
    std::uniform_int_distribution<int> x(0, 239), y(0, 179), p(0, 1);
    std::uniform_int_distribution<std::int64_t> t(0, span_us - 1);
    const std::vector<Event> track_events = s.corners;
    while (count > 0) {
        const Event e = at(x(rng), y(rng), t(rng), p(rng));
        if (std::any_of(track_events.begin(), track_events.end(), [&](const Event& k) {
                return std::abs(k.t - e.t) <= 100'000 && std::hypot(k.x - e.x, k.y - e.y) <= 25.0;
            }))
            continue;
        s.corners.push_back(e);
        s.truth.push_back(0);
        --count;
    }
}

std::size_t count_labelled(const FeatureTrackResult& r, std::size_t begin, std::size_t end) {
    return static_cast<std::size_t>(std::count(r.on_track.begin() + static_cast<std::ptrdiff_t>(begin),
                                               r.on_track.begin() + static_cast<std::ptrdiff_t>(end), 1));
}

TEST(FeatureTracks, StraightTrackIsFound) {
    std::mt19937 rng(1);
    Stream s;
    add_track(s, {100, 80, 0.0, 0.0, 0, 40, 1000}, 1, rng);  // a corner that does not move
    const auto r = label_feature_tracks(s.corners);
    EXPECT_EQ(r.on_track, s.truth);
    EXPECT_EQ(r.labelled, 40u);
    EXPECT_DOUBLE_EQ(r.ft_percent(), 100.0);
    EXPECT_GT(r.accepted, 0u);
}

TEST(FeatureTracks, ObliqueTracksAreFound) {
    std::mt19937 rng(2);
    Stream s;
    add_track(s, {30, 40, 0.5, 0.2, 0, 60, 1000}, 1, rng);     // 30 px in 60 ms
    add_track(s, {200, 150, -0.3, -0.6, 5000, 50, 600}, 1, rng);
    add_track(s, {60, 160, 2.0, -1.0, 0, 45, 200}, 1, rng);    // fast: 20 px in 9 ms
    const auto r = label_feature_tracks(s.corners);
    EXPECT_EQ(count_labelled(r, 0, 60), 60u);
    EXPECT_EQ(count_labelled(r, 60, 110), 50u);
    EXPECT_EQ(count_labelled(r, 110, 155), 45u);
}

TEST(FeatureTracks, ClutterIsRejected) {
    std::mt19937 rng(3);
    Stream s;
    add_clutter(s, 2000, 100'000, rng);
    const auto r = label_feature_tracks(s.corners);
    EXPECT_EQ(r.labelled, 0u);
    EXPECT_EQ(r.accepted, 0u);
}

TEST(FeatureTracks, TooFewEventsIsNoTrack) {
    std::mt19937 rng(4);
    Stream s;
    add_track(s, {100, 80, 0.3, 0.1, 0, 29, 1000}, 0, rng, 0);  // one short of 30
    EXPECT_EQ(label_feature_tracks(s.corners).labelled, 0u);
    s = {};
    add_track(s, {100, 80, 0.3, 0.1, 0, 30, 1000}, 1, rng, 0);  // exactly 30
    EXPECT_EQ(label_feature_tracks(s.corners).labelled, 30u);
}

TEST(FeatureTracks, CrowdedOuterShellIsRejected) {
    // 40 corner events on the axis and 40 on a ring of radius 4 px around it: outer/inner
    // is 1, far above 25 %; the same track with 5 ring events (12.5 %) is accepted.
    for (const int ring : {40, 5}) {
        std::mt19937 rng(5);
        Stream s;
        const Track tr{120, 90, 0.2, 0.1, 0, 40, 1000};
        add_track(s, tr, ring == 5, rng, 0);
        for (int i = 0; i < ring; ++i) {
            const double angle = 2.39996 * i;  // golden angle: spread all round
            const std::int64_t t = 500 + static_cast<std::int64_t>(i) * 39'000 / ring;
            const double ms = t / 1000.0;
            s.corners.push_back(at(tr.x0 + tr.vx * ms + 4.2 * std::cos(angle), tr.y0 + tr.vy * ms + 4.2 * std::sin(angle), t));
            s.truth.push_back(0);
        }
        const auto r = label_feature_tracks(s.corners);
        if (ring == 40) {
            EXPECT_EQ(r.labelled, 0u) << "a track with a crowded outer shell must be rejected";
        } else {
            EXPECT_EQ(count_labelled(r, 0, 40), 40u);
            EXPECT_EQ(r.on_track, s.truth);
        }
    }
}

TEST(FeatureTracks, TracksAmidClutterInAnyOrder) {
    std::mt19937 rng(6);
    Stream s;
    const std::vector<Track> tracks{{40, 40, 0.4, 0.0, 0, 50, 1000},
                                    {180, 60, 0.0, 0.5, 10'000, 40, 800},
                                    {120, 150, -0.3, -0.3, 20'000, 60, 900}};
    for (const auto& tr : tracks) add_track(s, tr, 1, rng);
    add_clutter(s, 800, 100'000, rng);
    // Shuffle: the labeller must not depend on the input order.
    std::vector<std::size_t> perm(s.corners.size());
    for (std::size_t i = 0; i < perm.size(); ++i) perm[i] = i;
    std::shuffle(perm.begin(), perm.end(), rng);
    Stream shuffled;
    for (const auto i : perm) {
        shuffled.corners.push_back(s.corners[i]);
        shuffled.truth.push_back(s.truth[i]);
    }
    const auto r = label_feature_tracks(shuffled.corners);
    EXPECT_EQ(r.on_track, shuffled.truth);
    EXPECT_EQ(r.labelled, 150u);
    EXPECT_NEAR(r.ft_percent(), 100.0 * 150 / 950, 1e-9);
    // exclusive: no clutter either; a track's tail shorter than 30 events after its claimed
    // segments may stay unlabelled, so only most of each track is required.
    FeatureTrackParams p;
    p.overlap = TrackOverlap::exclusive;
    const auto x = label_feature_tracks(shuffled.corners, p);
    std::size_t on_tracks = 0;
    for (std::size_t i = 0; i < x.on_track.size(); ++i) {
        if (!shuffled.truth[i]) {
            EXPECT_EQ(x.on_track[i], 0) << "clutter labelled at " << i;
        }
        on_tracks += x.on_track[i] & shuffled.truth[i];
    }
    EXPECT_GE(on_tracks, 135u);
}

TEST(FeatureTracks, PolarityChoice) {
    // One corner whose events alternate in polarity: 40 in all, 20 of each.
    Stream s;
    for (int i = 0; i < 40; ++i) s.corners.push_back(at(100 + i / 4, 90, i * 1000, i % 2));
    EXPECT_EQ(label_feature_tracks(s.corners).labelled, 40u);
    FeatureTrackParams per;
    per.same_polarity = true;
    EXPECT_EQ(label_feature_tracks(s.corners, per).labelled, 0u);
}

TEST(FeatureTracks, DurationLimitsTheCylinder) {
    // 40 events over 390 ms: within any 100 ms at most 11 of them.
    std::mt19937 rng(7);
    Stream s;
    add_track(s, {100, 80, 0.02, 0.0, 0, 40, 10'000}, 1, rng, 0);
    EXPECT_EQ(label_feature_tracks(s.corners).labelled, 0u);
    FeatureTrackParams p;
    p.max_duration_us = 400'000;
    EXPECT_EQ(label_feature_tracks(s.corners, p).labelled, 40u);
}

TEST(FeatureTracks, LengthLimitsTheCylinder) {
    // 40 events 1 px apart along x: no 20-px stretch holds 30 of them.
    Stream s;
    for (int i = 0; i < 40; ++i) s.corners.push_back(at(50 + i, 90, i * 1000));
    EXPECT_EQ(label_feature_tracks(s.corners).labelled, 0u);
    FeatureTrackParams p;
    p.max_length = 40;
    EXPECT_EQ(label_feature_tracks(s.corners, p).labelled, 40u);
}

TEST(FeatureTracks, EmptyInputAndBadParameters) {
    const auto r = label_feature_tracks({});
    EXPECT_TRUE(r.on_track.empty());
    EXPECT_EQ(r.ft_percent(), 0.0);
    FeatureTrackParams p;
    p.outer_radius = 2;
    EXPECT_THROW(validate(p), std::invalid_argument);
    p = {};
    p.min_inner = 1;
    EXPECT_THROW(validate(p), std::invalid_argument);
    p = {};
    p.max_duration_us = 0;
    EXPECT_THROW(validate(p), std::invalid_argument);
    EXPECT_THROW(parse_track_overlap("some"), std::invalid_argument);
    EXPECT_EQ(parse_track_overlap("exclusive"), TrackOverlap::exclusive);
}


// The labeller against the implementation it replaced (tests/feature_tracks_reference.hpp):
// the same labels and the same hypothesis and acceptance counts, on every code path this
// CPU runs, for both overlap modes, per polarity or not, on streams with tracks crossing
// each other, clutter near them (so hypotheses leave the tracks), ties in time, and
// corners at the sensor's edges.
void expect_same_as_reference(const std::vector<Event>& corners, const FeatureTrackParams& p, const std::string& what) {
    const FeatureTrackResult ref = label_feature_tracks_reference(corners, p);
    for (const std::string& path : feature_track_code_paths()) {
        const FeatureTrackResult r = label_feature_tracks_on_path(path, corners, p);
        EXPECT_EQ(r.on_track, ref.on_track) << what << " on " << path;
        EXPECT_EQ(r.labelled, ref.labelled) << what << " on " << path;
        EXPECT_EQ(r.hypotheses, ref.hypotheses) << what << " on " << path;
        EXPECT_EQ(r.accepted, ref.accepted) << what << " on " << path;
    }
}

std::vector<Event> busy_stream(unsigned seed) {
    std::mt19937 rng(seed);
    Stream s;
    std::uniform_real_distribution<double> px(0, 239), py(0, 179), v(-1.0, 1.0);
    std::uniform_int_distribution<int> count(20, 70), step(200, 1500), pol(0, 1);
    for (int k = 0; k < 25; ++k) {
        const Track tr{px(rng), py(rng), v(rng), v(rng), static_cast<std::int64_t>(k) * 7000, count(rng),
                       static_cast<std::int64_t>(step(rng))};
        Stream t;
        add_track(t, tr, 1, rng, 1, pol(rng));
        for (Event e : t.corners) {
            e.x = static_cast<std::uint16_t>(std::min<int>(e.x, 239));
            e.y = static_cast<std::uint16_t>(std::min<int>(e.y, 179));
            s.corners.push_back(e);
        }
    }
    // Clutter anywhere, also beside the tracks, and exact time ties.
    std::uniform_int_distribution<int> x(0, 239), y(0, 179);
    std::uniform_int_distribution<std::int64_t> t(0, 250'000);
    for (int k = 0; k < 1500; ++k) s.corners.push_back(at(x(rng), y(rng), t(rng), pol(rng)));
    for (int k = 0; k < 200; ++k) {
        Event e = s.corners[static_cast<std::size_t>(k) * 7 % s.corners.size()];
        e.x = static_cast<std::uint16_t>(std::min(239, e.x + 2));
        s.corners.push_back(e);  // same time as another corner, 2 px away
    }
    std::shuffle(s.corners.begin(), s.corners.end(), rng);
    return s.corners;
}

TEST(FeatureTracks, SameAsTheReferenceOnEveryCodePath) {
    ASSERT_FALSE(feature_track_code_paths().empty());
    EXPECT_EQ(std::string(feature_track_code_path()), feature_track_code_paths().front());
    EXPECT_THROW(label_feature_tracks_on_path("no-such-path", {}), std::invalid_argument);
    for (unsigned seed = 1; seed <= 4; ++seed) {
        const std::vector<Event> corners = busy_stream(seed);
        FeatureTrackParams p;
        const FeatureTrackResult ref = label_feature_tracks_reference(corners, p);
        EXPECT_GT(ref.accepted, 0u) << "tracks to find";
        EXPECT_LT(ref.labelled, corners.size()) << "clutter to reject";
        expect_same_as_reference(corners, p, "defaults, seed " + std::to_string(seed));
        p.overlap = TrackOverlap::exclusive;
        expect_same_as_reference(corners, p, "exclusive, seed " + std::to_string(seed));
        p = {};
        p.same_polarity = true;
        p.min_inner = 10;
        expect_same_as_reference(corners, p, "per polarity, 10 inner, seed " + std::to_string(seed));
        p = {};
        p.inner_radius = 2.5;
        p.outer_radius = 6.5;  // a margin that is not a whole number
        p.max_length = 33;
        p.max_outer_ratio = 0.5;
        p.min_inner = 12;
        p.cell_size = 5;
        expect_same_as_reference(corners, p, "other radii, seed " + std::to_string(seed));
    }
}

TEST(FeatureTracks, SameAsTheReferenceOnRealCorners) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(EVCORNER_SHARED_DIR) / "data/real/ecd-stppp";
    const fs::path golden = fs::path(EVCORNER_SHARED_DIR) / "data/golden";
    if (!fs::is_directory(dir)) GTEST_SKIP() << "no " << dir << " (the shared data folder)";
    for (const std::string seq : {"shapes_rotation", "shapes_translation", "dynamic_translation"}) {
        for (const std::string det : {"efast", "harris"}) {
            const std::vector<Event> events = io::read_text_file((dir / seq / "events.txt").string());
            std::vector<Event> corners;
            std::ifstream idx(golden / ("ecd-stppp." + seq + "." + det + ".idx"));
            for (std::size_t i; idx >> i;) corners.push_back(events.at(i));
            ASSERT_FALSE(corners.empty()) << seq << " " << det;
            FeatureTrackParams p;
            expect_same_as_reference(corners, p, seq + " " + det);
            p.overlap = TrackOverlap::exclusive;
            expect_same_as_reference(corners, p, seq + " " + det + " exclusive");
        }
    }
}

}  // namespace
}  // namespace evcorner::eval
