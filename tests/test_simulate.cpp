// The event-camera simulator (sim/): its results are only as good as it is, so each part is
// checked against what can be computed by hand (counts, crossing times, corner positions) or
// by a plain oracle (coverage), plus noise statistics and determinism.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <span>
#include <string>

#include "evcorner/error.hpp"
#include "evcorner/naive/coverage_naive.hpp"
#include "evcorner/sim/coverage.hpp"
#include "evcorner/sim/geometry.hpp"
#include "evcorner/sim/motion.hpp"
#include "evcorner/sim/texture.hpp"
#include "evcorner/sim/presets.hpp"
#include "evcorner/sim/random.hpp"
#include "evcorner/sim/scene.hpp"
#include "evcorner/sim/simulator.hpp"
#include "evcorner/sim/truth.hpp"

namespace evcorner::sim {
namespace {

// The issue's analytic scene: a 40x40 square of 0.1 on 0.5, edges on pixel boundaries,
// moving its own width to the right at 100 px/s; C = 0.25, sigma 0, no noise, no refractory.
const char* kSquare = R"({
  "sensor": [240, 180], "duration_s": 0.4, "seed": 7,
  "camera": {"contrast": 0.25, "contrast_sigma": 0, "refractory_us": 0, "noise_hz": 0},
  "background": 0.5,
  "objects": [{"polygon": [[60, 70], [100, 70], [100, 110], [60, 110]], "intensity": 0.1,
               "motion": {"velocity": [100, 0]}}]
})";

bool time_ordered(const std::vector<Event>& ev) {
    return std::is_sorted(ev.begin(), ev.end(), [](const Event& a, const Event& b) { return a.t < b.t; });
}

TEST(SimulateAnalytic, SquareGivesSixEventsPerSweptPixelAndNothingElse) {
    // floor(ln(0.501 / 0.101) / 0.25) = floor(6.41) = 6 crossings per pixel an edge sweeps.
    ASSERT_EQ(static_cast<int>(std::floor(std::log(0.501 / 0.101) / 0.25)), 6);
    const std::vector<Event> ev = simulate(parse_scene(kSquare, "square"));
    std::map<std::pair<int, int>, int> on, off;
    for (const Event& e : ev) (e.p ? on : off)[{e.x, e.y}]++;
    int n_on = 0, n_off = 0;
    for (const auto& [px, n] : off) {
        // The leading edge sweeps columns 100..139 of rows 70..109.
        EXPECT_TRUE(px.first >= 100 && px.first < 140 && px.second >= 70 && px.second < 110)
            << "OFF at " << px.first << "," << px.second;
        EXPECT_EQ(n, 6) << "OFF at " << px.first << "," << px.second;
        n_off += n;
    }
    for (const auto& [px, n] : on) {
        // The trailing edge sweeps columns 60..99.
        EXPECT_TRUE(px.first >= 60 && px.first < 100 && px.second >= 70 && px.second < 110)
            << "ON at " << px.first << "," << px.second;
        EXPECT_EQ(n, 6) << "ON at " << px.first << "," << px.second;
        n_on += n;
    }
    EXPECT_EQ(off.size(), 1600u);
    EXPECT_EQ(on.size(), 1600u);
    EXPECT_EQ(n_off, 9600);
    EXPECT_EQ(n_on, 9600);
    EXPECT_EQ(ev.size(), 19200u);
    EXPECT_TRUE(time_ordered(ev));
    for (const Event& e : ev) {
        EXPECT_GT(e.t, 0);
        EXPECT_LE(e.t, 400000);
    }
}

// The k-th crossing of pixel e.x in the analytic square whose edges move at `speed` px/s, s.
// A pixel x swept by an edge has coverage linear in time, so each crossing time is a closed form.
double square_crossing_s(const Event& e, int k, double speed) {
    if (e.p == 0) {
        // Leading edge at 100 + speed t covers c = edge - x of the pixel: I = 0.5 - 0.4 c.
        const double level = std::exp(std::log(0.501) - 0.25 * k) - 0.001;
        const double c = (0.5 - level) / 0.4;
        return (e.x + c - 100.0) / speed;
    }
    // Trailing edge at 60 + speed t uncovers u = edge - x: I = 0.1 + 0.4 u.
    const double level = std::exp(std::log(0.101) + 0.25 * k) - 0.001;
    const double u = (level - 0.1) / 0.4;
    return (e.x + u - 60.0) / speed;
}

TEST(SimulateAnalytic, SquareEventTimesMatchTheCoverageCrossings) {
    const std::vector<Event> ev = simulate(parse_scene(kSquare, "square"));
    ASSERT_EQ(ev.size(), 19200u);
    // The k-th event of a pixel is its k-th threshold crossing. A pixel x swept by an edge
    // moving at 100 px/s has coverage linear in time, so each crossing time is a closed form.
    std::map<std::pair<int, int>, int> seen;
    double worst = 0;
    for (const Event& e : ev) {
        const int k = ++seen[{e.x, e.y}];
        worst = std::max(worst, std::abs(static_cast<double>(e.t) - square_crossing_s(e, k, 100.0) * 1e6));
    }
    // Rounding to the microsecond gives up to 0.5 us; the rest comes from the step in which an
    // edge enters a pixel (I is constant, then linear: a kink inside the step).
    EXPECT_LE(worst, 3.0);
    std::printf("[ largest |timestamp - analytic crossing| over 19200 events: %.4f us ]\n", worst);
}

// The square moving 20 times faster (2000 px/s, its width in 20 ms): a step now moves the
// edges up to 0.675 px, so a pixel's L changes by several C within one step and each edge
// pixel is sampled on its own within the steps (per-pixel refinement). The counts stay exact
// and the times within the crossing tolerance (50 us x step_fraction 0.5) plus rounding.
std::string fast_square() {
    std::string s = kSquare;
    s.replace(s.find("\"duration_s\": 0.4"), 17, "\"duration_s\": 0.02");
    s.replace(s.find("\"velocity\": [100, 0]"), 20, "\"velocity\": [2000, 0]");
    return s;
}

TEST(SimulateAnalytic, FastSquareIsRefinedPerPixelAndKeepsExactCountsAndTimes) {
    Simulator sim(parse_scene(fast_square(), "fast square"));
    std::vector<Event> ev;
    while (sim.step(ev)) {
    }
    EXPECT_GT(sim.stats().pixel_samples, 10000u);  // the refinement did the work
    EXPECT_LE(sim.stats().max_step_change, 0.5 + 1e-9);
    ASSERT_EQ(ev.size(), 19200u);
    EXPECT_TRUE(time_ordered(ev));
    std::map<std::pair<int, int>, int> seen;
    double worst = 0;
    for (const Event& e : ev) {
        const int k = ++seen[{e.x, e.y}];
        // OFF only where the leading edge sweeps (columns 100..139), ON where the trailing one does.
        EXPECT_TRUE(e.x >= (e.p ? 60 : 100) && e.x < (e.p ? 100 : 140) && e.y >= 70 && e.y < 110) << e.x << "," << e.y;
        worst = std::max(worst, std::abs(static_cast<double>(e.t) - square_crossing_s(e, k, 2000.0) * 1e6));
    }
    EXPECT_EQ(seen.size(), 3200u);
    for (const auto& [px, n] : seen) EXPECT_EQ(n, 6) << px.first << "," << px.second;
    EXPECT_LE(worst, 0.5 + 25.0);
    std::printf("[ fast square: %llu single-pixel samples; largest |timestamp - analytic crossing| over 19200 events: %.4f us ]\n",
                static_cast<unsigned long long>(sim.stats().pixel_samples), worst);
}

// Exact coverage of one pixel by the polygon at time t, by the clipping oracle.
double pixel_coverage_at(const Scene& s, double t_s, int x, int y) {
    const Object& o = s.objects[0];
    std::vector<Vec2> poly;
    const double dx = o.motion.velocity.x * t_s, dy = o.motion.velocity.y * t_s;
    for (const Vec2& v : o.pieces[0].polygon) poly.push_back({v.x + dx, v.y + dy});
    return naive::clipped_pixel_coverage(poly, x, y);
}

// Largest |timestamp - exact crossing| for a slanted edge, at a given step fraction.
double slanted_edge_error(double step_fraction, std::size_t& events) {
    // Edges at 27 and 23 degrees to the pixel sides: a pixel's coverage is quadratic in time
    // while a corner of the pixel is inside, so linear interpolation within a step is not exact.
    std::string text = R"({"sensor": [64, 48], "duration_s": 0.3, "seed": 1,
      "camera": {"contrast": 0.2}, "background": 0.6, "simulation": {"step_fraction": FRACTION},
      "objects": [{"polygon": [[-40, -10], [10, -10], [30, 30], [-40, 60]], "intensity": 0.15,
                   "motion": {"velocity": [80, 10]}}]})";
    text.replace(text.find("FRACTION"), 8, std::to_string(step_fraction));
    const Scene s = parse_scene(text, "slanted");
    const std::vector<Event> ev = simulate(s);
    EXPECT_GT(ev.size(), 1000u);
    std::map<std::pair<int, int>, int> seen;
    double worst = 0;
    for (const Event& e : ev) {
        const int k = ++seen[{e.x, e.y}];
        const double i0 = 0.6 * (1 - pixel_coverage_at(s, 0, e.x, e.y)) + 0.15 * pixel_coverage_at(s, 0, e.x, e.y);
        const double level_l = std::log(0.001 + i0) + (e.p ? 1 : -1) * 0.2 * k;
        // Bisection for the first time the pixel's intensity reaches the level (monotone here:
        // the object only advances over these pixels).
        auto intensity = [&](double t) {
            const double c = pixel_coverage_at(s, t, e.x, e.y);
            return std::log(0.001 + 0.6 * (1 - c) + 0.15 * c);
        };
        double lo = 0, hi = 0.3;
        for (int it = 0; it < 60; ++it) {
            const double mid = 0.5 * (lo + hi);
            const bool reached = e.p ? intensity(mid) >= level_l : intensity(mid) <= level_l;
            (reached ? hi : lo) = mid;
        }
        worst = std::max(worst, std::abs(static_cast<double>(e.t) - hi * 1e6));
    }
    events = ev.size();
    return worst;
}

TEST(SimulateAnalytic, SlantedEdgeTimesShrinkWithTheStep) {
    std::size_t n = 0;
    const double coarse = slanted_edge_error(0.5, n);  // the default
    std::printf("[ slanted edge, step_fraction 0.5: largest |timestamp - exact crossing| over %zu events: %.3f us ]\n", n, coarse);
    const double fine = slanted_edge_error(0.1, n);
    std::printf("[ slanted edge, step_fraction 0.1: largest |timestamp - exact crossing| over %zu events: %.3f us ]\n", n, fine);
    EXPECT_LE(coarse, 50.0);
    EXPECT_LE(fine, 10.0);
    EXPECT_LT(fine, coarse / 3);
}

TEST(SimulateNoise, RateWithinFivePercentAndPolaritiesBalanced) {
    const char* text = R"({"sensor": [100, 80], "duration_s": 10, "seed": 11,
      "camera": {"noise_hz": 2.0}, "background": 0.5, "objects": []})";
    const std::vector<Event> ev = simulate(parse_scene(text, "noise"));
    const double expected = 2.0 * 100 * 80 * 10;  // 160 000
    EXPECT_NEAR(static_cast<double>(ev.size()), expected, 0.05 * expected);
    const auto on = std::count_if(ev.begin(), ev.end(), [](const Event& e) { return e.p == 1; });
    EXPECT_NEAR(static_cast<double>(on), expected / 2, 0.05 * expected / 2);
    EXPECT_TRUE(time_ordered(ev));
    // Spread over the sensor: each quarter of the rows gets a quarter.
    const auto top = std::count_if(ev.begin(), ev.end(), [](const Event& e) { return e.y < 20; });
    EXPECT_NEAR(static_cast<double>(top), expected / 4, 0.05 * expected / 4);
}

TEST(SimulateNoise, HotPixelsFireAtTheirRate) {
    const char* text = R"({"sensor": [50, 40], "duration_s": 20, "seed": 3,
      "camera": {"hot_pixels": {"count": 3, "rate_hz": 200}}, "background": 0.5, "objects": []})";
    const std::vector<Event> ev = simulate(parse_scene(text, "hot"));
    std::map<std::pair<int, int>, int> per;
    for (const Event& e : ev) {
        EXPECT_EQ(e.p, 1);
        per[{e.x, e.y}]++;
    }
    ASSERT_EQ(per.size(), 3u);
    for (const auto& [px, n] : per) EXPECT_NEAR(n, 4000, 0.05 * 4000);
}

const char* kBusy = R"({"sensor": [80, 60], "duration_s": 0.5, "seed": SEED,
  "camera": {"contrast": 0.2, "contrast_sigma": 0.05, "refractory_us": 2000, "noise_hz": 1},
  "background": {"texture": {"mean": 0.5, "amplitude": 0.3, "scale_px": 8}},
  "objects": [{"polygon": [[10, 10], [40, 15], [25, 22], [30, 45]], "intensity": 0.9,
               "motion": {"velocity": [30, 5], "rotation_deg_s": 40}},
              {"checkerboard": {"origin": [45, 20], "square": 6, "cols": 4, "rows": 3},
               "intensity": [0.1, 0.8], "motion": {"rotation_deg_s": -60, "scaling_per_s": 0.2}}]})";

std::string busy(int seed) {
    std::string s = kBusy;
    s.replace(s.find("SEED"), 4, std::to_string(seed));
    return s;
}

TEST(SimulateDeterminism, SameSeedSameEventsOtherSeedOtherNoise) {
    const std::vector<Event> a = simulate(parse_scene(busy(5), "a"));
    const std::vector<Event> b = simulate(parse_scene(busy(5), "b"));
    const std::vector<Event> c = simulate(parse_scene(busy(6), "c"));
    ASSERT_GT(a.size(), 1000u);
    EXPECT_EQ(a, b);
    EXPECT_NE(a, c);
    EXPECT_TRUE(time_ordered(a));
    EXPECT_TRUE(time_ordered(c));
}

// Random::skip(n) lands where n calls of next() would (each pixel's thresholds are drawn from
// its own place in the stream, when it first changes).
TEST(SimulateDeterminism, SkipEqualsDrawingInOrder) {
    for (const std::uint64_t n : {0ull, 1ull, 4ull, 172799ull, 1ull << 40}) {
        Random drawn(11, 1), skipped(11, 1);
        const std::uint64_t steps = std::min<std::uint64_t>(n, 200000);
        for (std::uint64_t i = 0; i < steps; ++i) drawn.next();
        skipped.skip(steps);
        EXPECT_EQ(drawn.next(), skipped.next()) << n;
        EXPECT_EQ(drawn.normal(), skipped.normal()) << n;
    }
}

// A pixel's thresholds are its own, whatever changes elsewhere and whenever it first changes:
// a square's events are the same with another object moving elsewhere on the sensor (which
// makes other pixels change first, and in between), with contrast_sigma > 0.
TEST(SimulateDeterminism, ThresholdsDoNotDependOnWhichPixelsChangeFirst) {
    const std::string one = R"({"sensor": [240, 180], "duration_s": 0.2, "seed": 3,
      "camera": {"contrast": 0.2, "contrast_sigma": 0.05}, "background": 0.5,
      "objects": [{"polygon": [[20, 30], [52, 34], [48, 60], [22, 58]], "intensity": 0.15,
                   "motion": {"velocity": [150, 40]}})";
    const std::string other = R"(, {"polygon": [[150, 20], [190, 25], [170, 70]], "intensity": 0.9,
                   "motion": {"velocity": [-20, 300], "rotation_deg_s": 90}})";
    const std::vector<Event> alone = simulate(parse_scene(one + "]}", "alone"));
    const std::vector<Event> both = simulate(parse_scene(one + other + "]}", "both"));
    auto left = [](const std::vector<Event>& ev) {
        std::vector<Event> out;
        for (const Event& e : ev)
            if (e.x < 110) out.push_back(e);
        return out;
    };
    ASSERT_GT(left(alone).size(), 1000u);
    ASSERT_GT(both.size(), left(both).size() + 1000);  // the other object made events of its own
    EXPECT_EQ(left(alone).size(), alone.size());        // the square stays left of x = 110
    EXPECT_EQ(left(alone), left(both));
}

TEST(SimulateStreaming, StepsComeInTimeOrderAndRespectTheRefractoryPeriod) {
    Simulator sim(parse_scene(busy(9), "busy"));
    std::vector<Event> all, step;
    std::int64_t last = 0;
    while (sim.step(step)) {
        for (const Event& e : step) {
            EXPECT_GE(e.t, last);
            last = e.t;
        }
        all.insert(all.end(), step.begin(), step.end());
        step.clear();
        EXPECT_LE(sim.stats().max_step_change, 0.5 + 1e-9);  // the step_fraction default
    }
    EXPECT_EQ(sim.time_us(), 500000.0);
    EXPECT_GT(sim.stats().refractory, 0u);
    // Signal events of one pixel are at least 2000 us apart (noise events are exempt, so
    // check it on the scene without noise).
    Scene quiet = parse_scene(busy(9), "busy");
    quiet.camera.noise_hz = 0;
    const std::vector<Event> ev = simulate(quiet);
    std::map<std::pair<int, int>, std::int64_t> prev;
    for (const Event& e : ev) {
        const auto it = prev.find({e.x, e.y});
        if (it != prev.end()) {
            EXPECT_GE(e.t - it->second, 2000) << e.x << "," << e.y;
        }
        prev[{e.x, e.y}] = e.t;
    }
}

// A full render at the simulator's time: background, then every object composited with
// polygon_coverage().
std::vector<double> full_render(const Scene& s, double t_us) {
    std::vector<double> img = background_image(s.background, s.sensor, s.seed);
    const double t_s = t_us / 1e6;
    for (const Object& o : s.objects) {
        const Pose pose(o.motion, t_s, s.duration_s);
        std::vector<double> b(img.size(), 0.0), sum(img.size(), 0.0);
        for (const Piece& p : o.pieces) {
            std::vector<Vec2> poly;
            for (const Vec2& v : p.polygon) poly.push_back(pose.apply(v));
            const std::vector<double> c = polygon_coverage(poly, s.sensor);
            for (std::size_t i = 0; i < c.size(); ++i) {
                b[i] += c[i];
                sum[i] += c[i] * p.intensity;
            }
        }
        for (std::size_t i = 0; i < img.size(); ++i) img[i] = img[i] * (1 - b[i]) + sum[i];
    }
    return img;
}

double largest_difference(std::span<const double> a, const std::vector<double>& b) {
    double worst = 0;
    for (std::size_t i = 0; i < b.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
    return worst;
}

// The image the simulator keeps (recomputed only at the pixels the moving edges touch before
// or after a step) against a full render at the same time.
TEST(SimulateStreaming, ImageNearEdgesOnlyEqualsAFullRender) {
    const Scene s = parse_scene(busy(4), "busy");
    Simulator sim(s);
    std::vector<Event> sink;
    int checked = 0;
    for (int k = 0; sim.step(sink); ++k) {
        if (k % 37 != 0) continue;
        EXPECT_LT(largest_difference(sim.image(), full_render(s, sim.time_us())), 1e-9) << "at " << sim.time_us() << " us";
        ++checked;
    }
    EXPECT_GT(checked, 10);
}

// The same at every step of a scene made to find a pixel the dirty set could miss: horizontal
// and vertical edges on pixel lines at t = 0 (a rectangle moving straight down, its top and
// bottom edges horizontal), an object leaving the sensor over its left and top borders, a
// still object under and over moving ones, a turning, growing checkerboard and a thin sliver.
constexpr const char* kEdgeCases = R"({
  "sensor": [64, 48], "duration_s": 0.25, "background": 0.3,
  "objects": [
    {"polygon": [[10, 8], [30, 8], [30, 20], [10, 20]], "intensity": 0.9,
     "motion": {"velocity": [0, 37]}},
    {"polygon": [[20, 30], [44, 26], [36, 44]], "intensity": 0.6},
    {"polygon": [[4, 3], [14, 5], [6, 12]], "intensity": 0.05,
     "motion": {"velocity": [-90, -60], "rotation_deg_s": 200}},
    {"checkerboard": {"origin": [34, 6], "square": 5, "cols": 3, "rows": 3}, "intensity": [0.1, 0.8],
     "motion": {"rotation_deg_s": 90, "scaling_per_s": 0.8}},
    {"polygon": [[5, 40], [60, 41.5], [5, 40.2]], "intensity": 1.0,
     "motion": {"velocity": [0, -20], "rotation_deg_s": -15}},
    {"polygon": [[40, 34], [50, 34], [50, 44], [40, 44]], "intensity": 0.45}
  ]
})";

TEST(SimulateStreaming, ImageEqualsAFullRenderAtEveryStepOfTheEdgeCases) {
    const Scene s = parse_scene(kEdgeCases, "edge cases");
    Simulator sim(s);
    EXPECT_LT(largest_difference(sim.image(), full_render(s, 0.0)), 1e-9);
    std::vector<Event> events;
    int steps = 0;
    double worst = 0;
    while (sim.step(events)) {
        worst = std::max(worst, largest_difference(sim.image(), full_render(s, sim.time_us())));
        ++steps;
    }
    EXPECT_LT(worst, 1e-9);
    EXPECT_GT(steps, 100);
    EXPECT_GT(events.size(), 1000u);
}

// Every single-pixel sample the refinement takes (at its own time within a step) against a
// full render at that time, on the busy scene and the edge cases.
TEST(SimulateStreaming, EverySinglePixelSampleEqualsAFullRender) {
    for (const std::string& text : {busy(4), std::string(kEdgeCases)}) {
        const Scene s = parse_scene(text, "scene");
        Simulator sim(s);
        std::vector<Simulator::PixelSample> samples;
        sim.record_samples(&samples);
        std::vector<Event> sink;
        std::map<double, std::vector<double>> renders;
        double worst = 0;
        std::size_t checked = 0;
        while (sim.step(sink)) {
            for (std::size_t i = 0; i < samples.size(); ++i) {
                const Simulator::PixelSample& x = samples[i];
                auto it = renders.find(x.t_us);
                if (it == renders.end()) it = renders.emplace(x.t_us, full_render(s, x.t_us)).first;
                worst = std::max(worst, std::abs(it->second[x.pixel] - x.value));
                ++checked;
            }
            samples.clear();
            renders.clear();
        }
        EXPECT_LT(worst, 1e-9);
        EXPECT_GT(checked, 100u);
    }
}

// Random simple polygons, convex or not: star-shaped around a centre.
std::vector<Vec2> random_polygon(Random& rng, double cx, double cy, double radius) {
    const int n = 3 + static_cast<int>(rng.below(8));
    std::vector<Vec2> p;
    for (int k = 0; k < n; ++k) {
        const double a = 2 * std::numbers::pi * (k + 0.1 + 0.8 * rng.uniform()) / n;
        const double r = radius * (0.2 + 0.8 * rng.uniform());
        p.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
    }
    return p;
}

TEST(SimulateCoverage, MatchesTheClippingOracleExactlyAndTheSupersampledOne) {
    Random rng(42);
    const SensorSize size{24, 20};
    double worst_clip = 0, worst_ss = 0;
    for (int trial = 0; trial < 60; ++trial) {
        // Some polygons reach past the sensor's sides.
        std::vector<Vec2> poly = random_polygon(rng, -4 + 32 * rng.uniform(), -4 + 28 * rng.uniform(), 3 + 12 * rng.uniform());
        ASSERT_FALSE(first_self_intersection(poly));
        if (signed_area(poly) < 0) std::reverse(poly.begin(), poly.end());
        const std::vector<double> cov = polygon_coverage(poly, size);
        for (int y = 0; y < size.height; ++y)
            for (int x = 0; x < size.width; ++x) {
                const double c = cov[static_cast<std::size_t>(y * size.width + x)];
                worst_clip = std::max(worst_clip, std::abs(c - naive::clipped_pixel_coverage(poly, x, y)));
                if (trial < 15) worst_ss = std::max(worst_ss, std::abs(c - naive::supersampled_pixel_coverage(poly, x, y, 64)));
            }
    }
    EXPECT_LT(worst_clip, 1e-9);
    EXPECT_LT(worst_ss, 0.03);  // 64 x 64 samples: about 1.5 px of edge / 64
}

// One pixel's coverage from the edges alone (what the simulator samples between steps)
// against the clipping oracle, at pixels inside, across and around random polygons,
// including pixels off a sensor (negative coordinates).
TEST(SimulateCoverage, PixelCoverageMatchesTheClippingOracle) {
    Random rng(43);
    double worst = 0;
    int partial = 0;
    for (int trial = 0; trial < 200; ++trial) {
        const std::vector<Vec2> poly = random_polygon(rng, 20 * rng.uniform() - 5, 20 * rng.uniform() - 5, 2 + 8 * rng.uniform());
        for (int y = -16; y < 26; ++y)
            for (int x = -16; x < 26; ++x) {
                const double want = naive::clipped_pixel_coverage(poly, x, y);
                worst = std::max(worst, std::abs(pixel_coverage(poly, x, y) - want));
                partial += want > 1e-6 && want < 1 - 1e-6;
            }
    }
    EXPECT_LT(worst, 1e-9);
    EXPECT_GT(partial, 1000);
}

TEST(SimulateCoverage, SumsToTheAreaAndOrientationDoesNotMatterAfterLoading) {
    const std::vector<Vec2> l = {{2.3, 1.7}, {9.1, 1.7}, {9.1, 4.2}, {5.5, 4.2}, {5.5, 11.9}, {2.3, 11.9}};
    const std::vector<double> cov = polygon_coverage(l, {16, 16});
    double sum = 0;
    for (double c : cov) sum += c;
    EXPECT_NEAR(sum, signed_area(l), 1e-9);
    EXPECT_NEAR(cov[5 * 16 + 3], 1.0, 1e-12);  // inside
    EXPECT_NEAR(cov[5 * 16 + 7], 0.0, 1e-12);  // in the notch of the L
    EXPECT_NEAR(cov[1 * 16 + 2], 0.7 * 0.3, 1e-12);
}

TEST(SimulateTruth, VerticesWhereTheMotionPutsThem) {
    const char* text = R"({"sensor": [200, 100], "duration_s": 1, "objects": [
      {"polygon": [[10, 10], [30, 10], [10, 40]], "intensity": 0.9, "motion": {"velocity": [50, 20]}},
      {"polygon": [[100, 40], [120, 40], [120, 60], [100, 60]], "intensity": 0.2,
       "motion": {"rotation_deg_s": 90, "center": [110, 50]}}]})";
    const Scene s = parse_scene(text, "truth");
    std::vector<TruthCorner> c;
    corners_at(s, 400000, c);
    ASSERT_EQ(c.size(), 7u);
    // The triangle moved by (20, 8); its angles sum to 180.
    EXPECT_NEAR(c[0].x, 30, 1e-9);
    EXPECT_NEAR(c[0].y, 18, 1e-9);
    EXPECT_NEAR(c[1].x, 50, 1e-9);
    EXPECT_NEAR(c[2].y, 48, 1e-9);
    EXPECT_NEAR(c[0].angle_deg, 90, 1e-9);
    EXPECT_NEAR(c[0].angle_deg + c[1].angle_deg + c[2].angle_deg, 180, 1e-9);
    EXPECT_NEAR(c[1].vx, 50, 1e-9);
    EXPECT_NEAR(c[1].vy, 20, 1e-9);
    // The square turned by 36 degrees (positive: from +x towards +y) about its centre.
    const double a = 36 * std::numbers::pi / 180;
    const double dx = -10, dy = -10;  // the vertex (100, 40) from the centre
    EXPECT_NEAR(c[3].x, 110 + std::cos(a) * dx - std::sin(a) * dy, 1e-9);
    EXPECT_NEAR(c[3].y, 50 + std::sin(a) * dx + std::cos(a) * dy, 1e-9);
    // Speed of a vertex at r = 10 sqrt 2 turning at pi/2 rad/s.
    EXPECT_NEAR(std::hypot(c[3].vx, c[3].vy), 10 * std::sqrt(2.0) * std::numbers::pi / 2, 1e-9);
    for (const TruthCorner& t : c) EXPECT_EQ(t.state, CornerState::visible);
    // At 4 s (past the scene's end still defined) the triangle has left the sensor at the right.
    c.clear();
    corners_at(s, 4000000, c);
    EXPECT_EQ(c[1].state, CornerState::outside);
}

TEST(SimulateTruth, OccludedByAnObjectInFrontNotBehind) {
    const char* text = R"({"sensor": [100, 100], "duration_s": 1, "objects": [
      {"polygon": [[10, 10], [40, 10], [40, 40], [10, 40]], "intensity": 0.9},
      {"polygon": [[30, 30], [60, 30], [60, 60], [30, 60]], "intensity": 0.2, "motion": {"velocity": [0, 20]}}]})";
    const Scene s = parse_scene(text, "occ");
    std::vector<TruthCorner> c;
    corners_at(s, 0, c);
    ASSERT_EQ(c.size(), 8u);
    EXPECT_EQ(c[2].state, CornerState::occluded);  // (40, 40) lies inside the square in front
    EXPECT_EQ(c[0].state, CornerState::visible);
    EXPECT_EQ(c[4].state, CornerState::visible);  // (30, 30) of the front square: nothing covers it
    // After 1 s the front square has moved down by 20 and no longer covers (40, 40).
    c.clear();
    corners_at(s, 1000000, c);
    EXPECT_EQ(c[2].state, CornerState::visible);
}

TEST(SimulateTruth, CheckerboardCornersAreItsGridPoints) {
    const char* text = R"({"sensor": [100, 100], "duration_s": 1, "objects": [
      {"checkerboard": {"origin": [20, 30], "square": 10, "cols": 3, "rows": 2}, "intensity": [0.1, 0.9]}]})";
    const Scene s = parse_scene(text, "cb");
    std::vector<TruthCorner> c;
    corners_at(s, 0, c);
    ASSERT_EQ(c.size(), 12u);
    EXPECT_NEAR(c[5].x, 30, 1e-12);  // row 1, column 1
    EXPECT_NEAR(c[5].y, 40, 1e-12);
    EXPECT_EQ(s.objects[0].pieces.size(), 6u);
}

void expect_scene_error(const std::string& text, const std::string& fragment) {
    try {
        (void)parse_scene(text, "bad.json");
        ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).rfind("bad.json: ", 0), 0u) << e.what();
    }
}

TEST(SimulateScene, ErrorsNameTheFileAndTheKey) {
    expect_scene_error("{\"sensor\": [240, 180], \"duration_s\": 1, \"objects\": [}", "byte ");
    expect_scene_error(R"({"duration_s": 1, "objects": []})", "/: missing key \"sensor\"");
    expect_scene_error(R"({"sensor": [240], "duration_s": 1, "objects": []})", "/sensor: expected 2 elements");
    expect_scene_error(R"({"sensor": [240, 0], "duration_s": 1, "objects": []})", "/sensor/1: 0 is out of range");
    expect_scene_error(R"({"sensor": [24, 18], "duration_s": 1, "camera": {"contrst": 0.2}, "objects": []})",
                       "/camera/contrst: unknown key");
    expect_scene_error(R"({"sensor": [24, 18], "duration_s": 1, "objects": [{"polygon": [[0, 0], [1, 1]], "intensity": 0.5}]})",
                       "/objects/0/polygon: expected at least 3 elements");
    expect_scene_error(
        R"({"sensor": [24, 18], "duration_s": 1, "objects": [{"polygon": [[0, 0], [6, 4], [6, 0], [0, 5]], "intensity": 0.5}]})",
        "/objects/0/polygon: is not simple");
    expect_scene_error(R"({"sensor": [24, 18], "duration_s": 1, "objects": [{"polygon": [[0, 0], [4, 0], [0, 4]], "intensity": 1.5}]})",
                       "/objects/0/intensity: 1.5 is out of range [0, 1]");
    expect_scene_error(
        R"({"sensor": [24, 18], "duration_s": 1, "objects": [{"polygon": [[0, 0], [4, 0], [0, 4]], "intensity": 0.5,
            "motion": {"velocity": ["fast", 0]}}]})",
        "/objects/0/motion/velocity/0: expected a number, got string");
    expect_scene_error(
        R"({"sensor": [24, 18], "duration_s": 1, "objects": [{"polygon": [[0, 0], [4, 0], [0, 4]], "intensity": 0.5,
            "motion": {"scaling_per_s": -2}}]})",
        "/objects/0/motion/scaling_per_s: shrinks the object");
    expect_scene_error(R"({"sensor": [24, 18], "duration_s": 1, "objects": [{"intensity": 0.5}]})",
                       "/objects/0: needs exactly one of \"polygon\" and \"checkerboard\"");
    expect_scene_error(R"({"sensor": [24, 18], "duration_s": 1, "objects": [], "background": {"texture": {"mean": 0.5}}})",
                       "/background/texture: missing key \"amplitude\"");
    expect_scene_error("{\"sensor\": [24, 18], \"duration_s\": 1, \"objects\": [], \"b\\u0001d\": 1}", "/b\\x01d: unknown key");
}

TEST(SimulateScene, EveryPresetParsesAndTheSuiteHasTheIssuesScenes) {
    int suite = 0;
    for (const PresetInfo& p : presets()) {
        const Scene s = parse_scene(preset_scene_json(p.name), p.name);
        if (!p.in_suite) continue;
        ++suite;
        EXPECT_GE(s.duration_s, 5.0) << p.name;
        EXPECT_LE(s.duration_s, 10.0) << p.name;
    }
    EXPECT_EQ(suite, 6);
    EXPECT_EQ(parse_scene(preset_scene_json("hd"), "hd").sensor, (SensorSize{1280, 720}));
    EXPECT_THROW(preset_scene_json("nope"), std::invalid_argument);
    // The ramp scene's fastest corner reaches about 1000 px/s at the end.
    const Scene ramp = parse_scene(preset_scene_json("ramp"), "ramp");
    std::vector<TruthCorner> c;
    corners_at(ramp, ramp.duration_us(), c);
    double fastest = 0;
    for (const TruthCorner& t : c) fastest = std::max(fastest, std::hypot(t.vx, t.vy));
    EXPECT_GT(fastest, 900);
    EXPECT_LT(fastest, 1100);
}

}  // namespace
}  // namespace evcorner::sim
