// The fast eFAST against the naive oracle (the definition written plainly) on seeded
// random streams, event for event, at several sensor sizes.

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "blob_stream.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/naive/efast_naive.hpp"

namespace evcorner {
namespace {

// Events clustered around drifting blobs (filled squares, so that circles see edges and
// corners), with many equal timestamps (ties) and 5 % uniform clutter, borders included.
std::vector<Event> random_stream(SensorSize s, std::size_t n, std::uint32_t seed) {
    return test::blob_stream(s, n, seed, {});
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
