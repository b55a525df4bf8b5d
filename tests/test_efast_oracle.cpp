// The fast eFAST against the naive oracle (the definition written plainly) on seeded
// random streams, event for event, at several sensor sizes.

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "evcorner/efast.hpp"
#include "evcorner/naive/efast_naive.hpp"

namespace evcorner {
namespace {

// Events clustered around drifting blobs (so that circles see structure), with many
// equal timestamps (ties) and a share of events on the border.
std::vector<Event> random_stream(SensorSize s, std::size_t n, std::uint32_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> spread(0.0, 3.0);
    struct Blob {
        double x, y, vx, vy;
    };
    std::vector<Blob> blobs(4);
    for (auto& b : blobs)
        b = {unit(rng) * s.width, unit(rng) * s.height, unit(rng) - 0.5, unit(rng) - 0.5};
    std::vector<Event> ev;
    ev.reserve(n);
    std::int64_t t = 1000;
    for (std::size_t i = 0; i < n; ++i) {
        t += static_cast<std::int64_t>(rng() % 3);  // 0: same timestamp as before
        int x, y;
        if (unit(rng) < 0.05) {  // uniform clutter, borders included
            x = static_cast<int>(rng() % static_cast<unsigned>(s.width));
            y = static_cast<int>(rng() % static_cast<unsigned>(s.height));
        } else {
            Blob& b = blobs[rng() % blobs.size()];
            b.x += b.vx * 0.05;
            b.y += b.vy * 0.05;
            if (b.x < 0 || b.x >= s.width) b.vx = -b.vx;
            if (b.y < 0 || b.y >= s.height) b.vy = -b.vy;
            // A blob is a filled square: its edges and corners move with it.
            x = static_cast<int>(b.x + spread(rng));
            y = static_cast<int>(b.y + spread(rng));
            x = std::clamp(x, 0, s.width - 1);
            y = std::clamp(y, 0, s.height - 1);
        }
        ev.push_back({t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                      static_cast<std::uint8_t>(rng() & 1)});
    }
    return ev;
}

class EFastVsOracle : public ::testing::TestWithParam<SensorSize> {};

TEST_P(EFastVsOracle, SameCornersEventForEvent) {
    const SensorSize s = GetParam();
    std::size_t corners = 0, total = 0;
    for (std::uint32_t seed = 1; seed <= 3; ++seed) {
        const auto events = random_stream(s, 60000, seed * 7919 + static_cast<std::uint32_t>(s.width));
        EFast fast(s);
        naive::EFastNaive oracle(s);
        for (std::size_t i = 0; i < events.size(); ++i) {
            const bool f = fast.process(events[i]);
            const bool o = oracle.process(events[i]);
            ASSERT_EQ(f, o) << "seed " << seed << " event " << i << " at (" << events[i].x << ","
                            << events[i].y << ") t=" << events[i].t;
            corners += o;
        }
        total += events.size();
    }
    // The streams must produce corners and non-corners, or the comparison is empty.
    if (s.width > 8 && s.height > 8) {
        EXPECT_GT(corners, 0u);
    }
    EXPECT_LT(corners, total);
}

INSTANTIATE_TEST_SUITE_P(Sizes, EFastVsOracle,
                         ::testing::Values(SensorSize{8, 8}, SensorSize{9, 9}, SensorSize{17, 11},
                                           SensorSize{64, 64}, SensorSize{128, 128},
                                           SensorSize{240, 180}, SensorSize{346, 260},
                                           SensorSize{640, 480}, SensorSize{1280, 720}),
                         [](const auto& info) {
                             return std::to_string(info.param.width) + "x" +
                                    std::to_string(info.param.height);
                         });

}  // namespace
}  // namespace evcorner
