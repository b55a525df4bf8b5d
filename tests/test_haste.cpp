// HASTE, one pass over many tracks (src/track/haste.cpp), against the plain per-seed
// oracle (haste_reference.hpp) on random streams, and on drawn cases.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "evcorner/track/haste.hpp"
#include "haste_reference.hpp"
#include "../src/track/haste_track.hpp"

using namespace evcorner;

namespace {

constexpr HasteMethod kMethods[] = {HasteMethod::correlation, HasteMethod::haste_correlation,
                                    HasteMethod::haste_correlation_star, HasteMethod::haste_difference,
                                    HasteMethod::haste_difference_star};

std::vector<TrackState> run(const std::vector<Event>& events, const std::vector<TrackSeed>& seeds, SensorSize size,
                            HasteParams p) {
    Haste h(size, p, seeds);
    std::vector<TrackState> out;
    for (const Event& e : events)
        for (const TrackState& s : h.process(e)) out.push_back(s);
    return out;
}

std::map<std::uint64_t, std::vector<TrackState>> by_id(const std::vector<TrackState>& v) {
    std::map<std::uint64_t, std::vector<TrackState>> m;
    for (const auto& s : v) m[s.id].push_back(s);
    return m;
}

// Events on the edges of squares drifting across the sensor (so that tracks move), mixed
// with uniform noise; times strictly increasing by 1..20 us.
std::vector<Event> drifting_squares(std::mt19937& rng, SensorSize size, int n, float vx, float vy) {
    std::uniform_real_distribution<float> u(0, 1);
    std::uniform_int_distribution<int> dt(1, 20);
    std::vector<Event> ev;
    std::int64_t t = 1000;
    const float cx0 = size.width * 0.3f, cy0 = size.height * 0.35f;
    for (int i = 0; i < n; ++i) {
        t += dt(rng);
        float x, y;
        if (u(rng) < 0.1f) {
            x = u(rng) * size.width;
            y = u(rng) * size.height;
        } else {
            const float shift = static_cast<float>(i) / n;
            const float ox = cx0 + vx * shift + (u(rng) < 0.5f ? 0 : 20), oy = cy0 + vy * shift;
            const float s = u(rng) * 14;  // along one of the square's four edges
            switch (static_cast<int>(u(rng) * 4)) {
                case 0: x = ox + s, y = oy; break;
                case 1: x = ox, y = oy + s; break;
                case 2: x = ox + s, y = oy + 14; break;
                default: x = ox + 14, y = oy + s; break;
            }
        }
        const int xi = std::clamp(static_cast<int>(x), 0, size.width - 1);
        const int yi = std::clamp(static_cast<int>(y), 0, size.height - 1);
        ev.push_back({t, static_cast<std::uint16_t>(xi), static_cast<std::uint16_t>(yi), static_cast<std::uint8_t>(u(rng) < 0.5f)});
    }
    return ev;
}

}  // namespace

TEST(Haste, MethodNamesRoundTrip) {
    for (HasteMethod m : kMethods) EXPECT_EQ(parse_haste_method(haste_method_name(m)), m);
    EXPECT_FALSE(parse_haste_method("haste_correlation"));  // the command line spells it with '-'
}

// The weights table is the golden build's; it must still be the Gaussian the doc defines
// (within the 1-3 ulp its vectorised exp moves them).
TEST(Haste, GaussianWeightsAreTheDocumentedGaussian) {
    const float c = static_cast<float>(-0.5 / ((193.0 / 6) * (193.0 / 6)));
    float raw[193], sum = 0;
    for (int k = 0; k < 193; ++k) sum += raw[k] = std::exp(c * static_cast<float>((k - 96) * (k - 96)));
    for (int k = 0; k < 193; ++k) {
        const float ours = detail::kHasteGaussianWeights[k];
        EXPECT_LE(std::fabs(ours - raw[k] / sum), 4 * (std::nextafter(ours, 1.0f) - ours)) << "k = " << k;
    }
    EXPECT_EQ(detail::kHasteGaussianWeights[0], detail::kHasteGaussianWeights[192]);
}

// The one-pass tracker equals the per-seed oracle state for state, bit for bit, on random
// streams: every method, both starts, several sensor sizes and seed sets.
TEST(Haste, OnePassEqualsThePerSeedOracle) {
    for (const SensorSize size : {SensorSize{64, 48}, SensorSize{100, 80}}) {
        for (unsigned seed = 1; seed <= 3; ++seed) {
            std::mt19937 rng(seed);
            const auto events = drifting_squares(rng, size, 6000, 6.0f * seed, -3.0f);
            std::vector<TrackSeed> seeds;
            std::uniform_real_distribution<float> u(0, 1);
            for (std::uint64_t id = 0; id < 6; ++id) {
                const Event& at = events[static_cast<std::size_t>(u(rng) * 3000) + 200];
                // On an event, and beside one, with a fractional position and an angle.
                seeds.push_back({at.t, at.x + (id % 2 ? 0.25f : 0.0f), at.y + 0.0f, id % 3 ? 0.0f : 0.1f, id * 7 + 1});
            }
            for (HasteMethod m : kMethods)
                for (const bool centered : {false, true}) {
                    HasteParams p;
                    p.method = m;
                    p.init = centered ? HasteInit::centered : HasteInit::uncentered;
                    const auto fast = by_id(run(events, seeds, size, p));
                    const auto ref = by_id(reference::reference_haste(events, seeds, size, m, centered, false));
                    ASSERT_EQ(fast.size(), ref.size()) << haste_method_name(m) << " centered " << centered;
                    std::size_t states = 0;
                    for (const auto& [id, r] : ref) {
                        ASSERT_TRUE(fast.count(id));
                        ASSERT_EQ(fast.at(id), r) << haste_method_name(m) << " centered " << centered << " id " << id;
                        states += r.size();
                    }
                    if (m == HasteMethod::haste_correlation_star) {
                        EXPECT_GT(states, 2 * ref.size()) << "tracks must move";
                    }
                }
        }
    }
}

namespace {

// An L-shaped corner: two arms of `arm` pixels from (cx, cy), along +x and +y turned by
// `angle` radians; `n` events on it, in random order along the arms, 10 us apart.
void l_corner(std::vector<Event>& ev, std::mt19937& rng, float cx, float cy, float angle, int n, int arm = 12) {
    std::uniform_int_distribution<int> pick(0, 2 * arm - 1);
    std::int64_t t = ev.empty() ? 0 : ev.back().t;
    const float c = std::cos(angle), s = std::sin(angle);
    for (int i = 0; i < n; ++i) {
        const int k = pick(rng);
        const float r = static_cast<float>(k % arm);
        const float x = k < arm ? cx + r * c : cx - r * s;
        const float y = k < arm ? cy + r * s : cy + r * c;
        ev.push_back({t += 10, static_cast<std::uint16_t>(std::lround(x)), static_cast<std::uint16_t>(std::lround(y)), 1});
    }
}

HasteParams params(HasteMethod m, HasteInit init = HasteInit::uncentered) {
    HasteParams p;
    p.method = m;
    p.init = init;
    return p;
}

}  // namespace

// "one-pixel-step": the corner jumps one pixel right; every method follows it there.
TEST(Haste, FollowsACornerMovingOnePixel) {
    for (HasteMethod m : kMethods) {
        std::mt19937 rng(7);
        std::vector<Event> ev;
        l_corner(ev, rng, 30, 30, 0, 400);
        l_corner(ev, rng, 31, 30, 0, 800);
        const auto states = run(ev, {{0, 30, 30, 0, 5}}, {64, 64}, params(m));
        ASSERT_FALSE(states.empty()) << haste_method_name(m);
        EXPECT_EQ(states.front().why, TrackChange::initialised);
        EXPECT_EQ(states.front().x, 30.0f);
        EXPECT_EQ(states.back().x, 31.0f) << haste_method_name(m);
        EXPECT_EQ(states.back().y, 30.0f) << haste_method_name(m);
        EXPECT_EQ(states.back().theta, 0.0f) << haste_method_name(m);
        EXPECT_EQ(states.back().id, 5u);
    }
}

// "one-step-turn": the corner turns by HASTE's angle step about its tip; the track turns
// by exactly that step, positive toward +y, and stays put.
TEST(Haste, FollowsACornerTurningOneStep) {
    std::mt19937 rng(3);
    std::vector<Event> ev;
    l_corner(ev, rng, 30, 30, 0, 400, 15);
    l_corner(ev, rng, 30, 30, detail::kHasteDTheta, 1200, 15);
    const auto states = run(ev, {{0, 30, 30, 0, 1}}, {64, 64}, params(HasteMethod::haste_correlation_star));
    ASSERT_FALSE(states.empty());
    EXPECT_EQ(states.back().theta, detail::kHasteDTheta);
    EXPECT_EQ(states.back().x, 30.0f);
    EXPECT_EQ(states.back().y, 30.0f);
}

// "leaving-the-margin": the corner walks left off the sensor; the track stops at the
// first state whose patch no longer fits (x < 15), reported as stopped, and takes no
// more events.
TEST(Haste, StopsWhenThePatchLeavesTheSensor) {
    std::mt19937 rng(5);
    std::vector<Event> ev;
    l_corner(ev, rng, 20, 30, 0, 400);
    for (int x = 19; x >= 8; --x) l_corner(ev, rng, static_cast<float>(x), 30, 0, 400);
    const auto states = run(ev, {{0, 20, 30, 0, 0}}, {64, 64}, params(HasteMethod::haste_correlation_star));
    ASSERT_GE(states.size(), 2u);
    EXPECT_EQ(states.back().why, TrackChange::stopped);
    EXPECT_EQ(states.back().x, 14.0f);
    for (std::size_t i = 0; i + 1 < states.size(); ++i) EXPECT_NE(states[i].why, TrackChange::stopped);
}

// "two-tracks-meet": two seeds 1 px apart on one corner that then moves; with a
// separation of 3 px the younger stops at the first move; without it both live on.
TEST(Haste, TheYoungerOfTwoMeetingTracksStops) {
    std::mt19937 rng(11);
    std::vector<Event> ev;
    l_corner(ev, rng, 30, 30, 0, 400);
    l_corner(ev, rng, 31, 30, 0, 800);
    const std::vector<TrackSeed> seeds{{0, 30, 30, 0, 1}, {0, 31, 30, 0, 2}};
    HasteParams p = params(HasteMethod::haste_correlation_star);
    const auto apart = by_id(run(ev, seeds, {64, 64}, p));
    ASSERT_EQ(apart.size(), 2u);
    EXPECT_NE(apart.at(2).back().why, TrackChange::stopped);
    ASSERT_GT(apart.at(2).size() + apart.at(1).size(), 2u) << "a track must move";
    p.stop.min_separation = 3;
    const auto met = by_id(run(ev, seeds, {64, 64}, p));
    ASSERT_EQ(met.size(), 2u);
    EXPECT_EQ(met.at(2).back().why, TrackChange::stopped);
    EXPECT_NE(met.at(1).back().why, TrackChange::stopped);
}

// No state change for max_idle_us: the track stops, at the time the rule fired.
TEST(Haste, AnIdleTrackStops) {
    std::mt19937 rng(13);
    std::vector<Event> ev;
    l_corner(ev, rng, 30, 30, 0, 300);
    l_corner(ev, rng, 31, 30, 0, 300);
    const std::int64_t quiet_from = ev.back().t;
    ev.push_back({quiet_from + 500000, 5, 5, 1});  // far away, half a second later
    HasteParams p = params(HasteMethod::haste_correlation_star);
    p.stop.max_idle_us = 100000;
    const auto states = run(ev, {{0, 30, 30, 0, 1}}, {64, 64}, p);
    ASSERT_FALSE(states.empty());
    EXPECT_EQ(states.back().why, TrackChange::stopped);
    EXPECT_EQ(states.back().t, quiet_from + 500000);
}

TEST(Haste, CenteredStartUsesTheEventsBeforeTheSeed) {
    std::mt19937 rng(17);
    std::vector<Event> ev;
    l_corner(ev, rng, 30, 30, 0, 300);
    const std::int64_t seed_t = ev[200].t;
    const auto centered = run(ev, {{seed_t, 30, 30, 0, 1}}, {64, 64}, params(HasteMethod::haste_correlation_star, HasteInit::centered));
    ASSERT_FALSE(centered.empty());
    EXPECT_EQ(centered.front().t, seed_t);  // the window's middle is the seed's own event
    // Uncentered, 193 events from the seed on are needed: 100 are not enough.
    const auto uncentered = run(ev, {{seed_t, 30, 30, 0, 1}}, {64, 64}, params(HasteMethod::haste_correlation_star));
    EXPECT_TRUE(uncentered.empty());
    // Centered with fewer than 96 events before the seed: skipped.
    Haste h({64, 64}, params(HasteMethod::haste_correlation_star, HasteInit::centered), {{ev[50].t, 30, 30, 0, 1}});
    for (const Event& e : ev) h.process(e);
    EXPECT_EQ(h.skipped_seeds(), 1u);
}

TEST(Haste, RefusesBadInput) {
    EXPECT_THROW(Haste({64, 64}, HasteParams{}, {{0, 70, 3, 0, 1}}), std::invalid_argument);
    EXPECT_THROW(Haste({64, 64}, HasteParams{}, {{0, 3, 3, 0, 1}, {5, 4, 4, 0, 1}}), std::invalid_argument);
    Haste h({64, 64}, HasteParams{});
    h.process({100, 1, 1, 1});
    EXPECT_THROW(h.process({99, 1, 1, 1}), std::invalid_argument);
    EXPECT_THROW(h.process({200, 64, 1, 1}), InvalidEvent);
    EXPECT_NO_THROW(h.process({100, 2, 2, 0}));
}
