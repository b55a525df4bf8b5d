// The "corners" tracker: drawn cases (a corner moving a pixel at a time, two corners, a gap,
// the cap, a track leaving the sensor, two tracks meeting) and the grid against the plain
// oracle on random corner streams.
#include <gtest/gtest.h>

#include <random>

#include "corner_tracker_reference.hpp"
#include "evcorner/track/tracker.hpp"

namespace evcorner {
namespace {

TrackerConfig front_end(float radius = 4, std::int64_t idle_us = 50000, double separation = 0) {
    TrackerConfig c;
    c.seed_from_corners = true;
    c.seed_radius = radius;
    c.stop.max_idle_us = idle_us;
    c.stop.min_separation = separation;
    return c;
}

std::vector<TrackState> feed(Tracker& t, const std::vector<std::pair<Event, bool>>& stream) {
    std::vector<TrackState> all;
    for (const auto& [e, c] : stream)
        for (const TrackState& s : t.process(e, c)) all.push_back(s);
    return all;
}

Event ev(std::int64_t t, int x, int y) { return {t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1}; }

// A corner stepping one pixel to the right every millisecond (1000 px/s), with other events
// between: one track, which learns the velocity and ends within a pixel of the corner.
//   t/ms  0  1  2  3 ... 29
//   x    10 11 12 13 ... 39      (y = 20)
TEST(CornerTracker, FollowsACornerMovingOnePixelAtATime) {
    auto t = tracker_entry("corners").make({64, 48}, front_end());
    std::vector<std::pair<Event, bool>> s;
    for (int k = 0; k < 30; ++k) {
        s.push_back({ev(k * 1000, 10 + k, 20), true});
        s.push_back({ev(k * 1000 + 500, 50, 40), false});  // not a corner: changes nothing
    }
    const auto states = feed(*t, s);
    ASSERT_EQ(states.size(), 30u);
    EXPECT_EQ(states.front().why, TrackChange::initialised);
    for (const auto& st : states) EXPECT_EQ(st.id, 0u);
    EXPECT_NEAR(states.back().x, 39.f, 1.0f);
    EXPECT_FLOAT_EQ(states.back().y, 20.f);
    EXPECT_EQ(t->stats().live, 1u);
}

// Two corners 20 px apart, each its own track; a gap of 60 ms (> 50 ms) stops both at the
// next sweep, and the corner seen again starts a new id.
TEST(CornerTracker, TwoCornersTwoTracksAndAGapEndsThem) {
    auto t = tracker_entry("corners").make({64, 48}, front_end());
    std::vector<std::pair<Event, bool>> s = {{ev(0, 10, 10), true}, {ev(0, 30, 10), true},
                                             {ev(1000, 11, 10), true}, {ev(1000, 31, 10), true},
                                             {ev(61001, 5, 5), false}, {ev(62000, 11, 10), true}};
    const auto states = feed(*t, s);
    ASSERT_EQ(states.size(), 7u);
    EXPECT_EQ(states[2].id, 0u);
    EXPECT_EQ(states[3].id, 1u);
    EXPECT_EQ(states[4].why, TrackChange::stopped);
    EXPECT_EQ(states[5].why, TrackChange::stopped);
    EXPECT_EQ(states[4].t, 61001);
    EXPECT_EQ(states[6].why, TrackChange::initialised);
    EXPECT_EQ(states[6].id, 2u);  // ids are never reused
}

TEST(CornerTracker, TheCapLimitsLiveTracks) {
    TrackerConfig c = front_end();
    c.max_tracks = 2;
    auto t = tracker_entry("corners").make({64, 48}, c);
    const auto states = feed(*t, {{ev(0, 5, 5), true}, {ev(0, 25, 5), true}, {ev(0, 45, 5), true}});
    EXPECT_EQ(states.size(), 2u);
}

// A track moving left at 1000 px/s stops once its position leaves the sensor: the corner
// events stay at x = 0 (the sensor's edge) while the prediction goes on past it.
TEST(CornerTracker, ATrackLeavingTheSensorStops) {
    auto t = tracker_entry("corners").make({64, 48}, front_end(4));
    std::vector<std::pair<Event, bool>> s;
    for (int k = 0; k <= 12; ++k) s.push_back({ev(k * 1000, std::max(12 - k, 0), 20), true});
    const auto states = feed(*t, s);
    ASSERT_FALSE(states.empty());
    EXPECT_EQ(states.back().why, TrackChange::stopped);
    EXPECT_LT(states.back().x, 0.f);
    EXPECT_EQ(t->stats().live, 0u);
}

// Two tracks walking toward each other; within min_separation the younger (id 1) stops.
TEST(CornerTracker, TwoTracksMeetingKeepTheOlder) {
    auto t = tracker_entry("corners").make({64, 48}, front_end(3, 50000, 3));
    std::vector<std::pair<Event, bool>> s;
    for (int k = 0; k < 10; ++k) {
        s.push_back({ev(k * 1000, 10 + k, 20), true});
        s.push_back({ev(k * 1000, 30 - k, 20), true});
    }
    const auto states = feed(*t, s);
    bool stopped1 = false, stopped0 = false;
    for (const auto& st : states) {
        stopped0 = stopped0 || (st.id == 0 && st.why == TrackChange::stopped);
        stopped1 = stopped1 || (st.id == 1 && st.why == TrackChange::stopped);
    }
    EXPECT_TRUE(stopped1);
    EXPECT_FALSE(stopped0);
}

TEST(CornerTracker, SeedsStartTracksThatCornersThenMove) {
    TrackerConfig c = front_end();
    c.seed_from_corners = false;
    c.seeds = {{500, 20.f, 20.f, 0.f, 7}};
    auto t = tracker_entry("corners").make({64, 48}, c);
    const auto states = feed(*t, {{ev(0, 20, 20), true}, {ev(600, 1, 1), false}, {ev(700, 21, 20), true},
                                  {ev(800, 50, 40), true}});
    ASSERT_EQ(states.size(), 2u);  // the corner before the seed and the far one start nothing
    EXPECT_EQ(states[0].id, 7u);
    EXPECT_EQ(states[0].t, 600);
    EXPECT_EQ(states[1].why, TrackChange::moved);
    EXPECT_FLOAT_EQ(states[1].x, 20.5f);  // halfway to the measurement (alpha 0.5)
}

TEST(CornerTracker, GridAgreesWithThePlainOracleOnRandomStreams) {
    std::mt19937_64 rng(7);
    for (int trial = 0; trial < 20; ++trial) {
        const int w = 40 + static_cast<int>(rng() % 60), h = 30 + static_cast<int>(rng() % 50);
        const float radius = 1.5f + static_cast<float>(rng() % 120) / 10.f;  // up to 13.4: reach 8 .. 14
        const std::int64_t idle = 2000 + static_cast<std::int64_t>(rng() % 20000);
        const double sep = trial % 3 == 0 ? 0.0 : 1.0 + static_cast<double>(rng() % 30) / 10.0;
        TrackerConfig c = front_end(radius, idle, sep);
        c.max_tracks = 5 + rng() % 40;
        c.seeds = {{0, static_cast<float>(w / 2), static_cast<float>(h / 2), 0.f, 3}};
        auto fast = tracker_entry("corners").make({w, h}, c);
        test::CornerTrackerReference ref{w, h, radius, idle, sep, true, c.max_tracks, c.seeds, {}};
        // corners random-walking around a few moving centres, and noise
        std::vector<std::pair<double, double>> centre(6);
        for (auto& p : centre) p = {static_cast<double>(rng() % w), static_cast<double>(rng() % h)};
        std::int64_t tt = 0;
        for (int i = 0; i < 4000; ++i) {
            tt += static_cast<std::int64_t>(rng() % 200);
            auto& p = centre[rng() % centre.size()];
            p.first = std::clamp(p.first + (static_cast<double>(rng() % 21) - 10) / 10, 0.0, w - 1.0);
            p.second = std::clamp(p.second + (static_cast<double>(rng() % 21) - 10) / 10, 0.0, h - 1.0);
            const bool noise = rng() % 4 == 0;
            const int x = noise ? static_cast<int>(rng() % w) : static_cast<int>(p.first + 0.5);
            const int y = noise ? static_cast<int>(rng() % h) : static_cast<int>(p.second + 0.5);
            const Event e = ev(tt, std::min(x, w - 1), std::min(y, h - 1));
            const bool corner = rng() % 3 != 0;
            const auto got = fast->process(e, corner);
            const auto want = ref.process(e, corner);
            ASSERT_EQ(std::vector<TrackState>(got.begin(), got.end()), want) << "trial " << trial << " event " << i;
        }
    }
}

}  // namespace
}  // namespace evcorner
