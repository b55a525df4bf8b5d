// The linear-time arc test against the definition, on random circles with many ties.

#include <gtest/gtest.h>

#include <array>
#include <random>

#include "evcorner/arc_test.hpp"

namespace evcorner {
namespace {

template <int N, int Lmin, int Lmax>
void compare_on_random_circles(int value_range, int trials, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> value(0, value_range - 1);
    int fired = 0;
    for (int trial = 0; trial < trials; ++trial) {
        std::array<std::int64_t, N> t;
        for (auto& v : t) v = value(rng);
        const bool naive = arc_fires_naive<N, Lmin, Lmax>(t);
        ASSERT_EQ((arc_fires<N, Lmin, Lmax>(t)), naive) << "trial " << trial;
        fired += naive;
    }
    // Both outcomes must have been exercised, or the comparison proves little.
    EXPECT_GT(fired, 0);
    EXPECT_LT(fired, trials);
}

TEST(ArcTest, MatchesDefinitionRadius3ManyTies) { compare_on_random_circles<16, 3, 6>(4, 200000, 1); }
TEST(ArcTest, MatchesDefinitionRadius3FewTies) { compare_on_random_circles<16, 3, 6>(1000, 200000, 2); }
TEST(ArcTest, MatchesDefinitionRadius4ManyTies) { compare_on_random_circles<20, 4, 8>(5, 200000, 3); }
TEST(ArcTest, MatchesDefinitionRadius4FewTies) { compare_on_random_circles<20, 4, 8>(1000, 200000, 4); }

// Structured circles: an arc of new pixels of every length at every start, with the
// rest old; fires exactly when the length is in range.
template <int N, int Lmin, int Lmax>
void arcs_of_every_length() {
    for (int len = 1; len < N; ++len) {
        for (int start = 0; start < N; ++start) {
            std::array<std::int64_t, N> t;
            t.fill(10);
            // All equal inside, so no shorter sub-arc is strictly newer than the rest.
            for (int i = 0; i < len; ++i) t[(start + i) % N] = 20;
            const bool expected = len >= Lmin && len <= Lmax;
            EXPECT_EQ((arc_fires<N, Lmin, Lmax>(t)), expected) << "len " << len << " start " << start;
            EXPECT_EQ((arc_fires_naive<N, Lmin, Lmax>(t)), expected) << "len " << len << " start " << start;
        }
    }
}
TEST(ArcTest, EveryLengthAndStartRadius3) { arcs_of_every_length<16, 3, 6>(); }
TEST(ArcTest, EveryLengthAndStartRadius4) { arcs_of_every_length<20, 4, 8>(); }

TEST(ArcTest, ArcTiedWithTheRestDoesNotFire) {
    std::array<std::int64_t, 16> t;
    t.fill(5);
    t[3] = t[4] = t[5] = 9;
    t[6] = 7;  // arc 3..6 has oldest 7
    t[12] = 7;  // the rest ties with it: 3..6 does not fire; 3..5 is newer than all (9 > 7)
    EXPECT_TRUE((arc_fires<16, 3, 6>(t)));
    t[12] = 9;  // now a pixel outside ties with the arc's newest: nothing of length 3..6 fires
    EXPECT_FALSE((arc_fires<16, 3, 6>(t)));
    EXPECT_FALSE((arc_fires_naive<16, 3, 6>(t)));
}

TEST(ArcTest, AllEqualNeverFires) {
    std::array<std::int64_t, 20> t;
    t.fill(INT64_MIN);
    EXPECT_FALSE((arc_fires<20, 4, 8>(t)));
    t.fill(42);
    EXPECT_FALSE((arc_fires<20, 4, 8>(t)));
}

TEST(ArcTest, ArcAcrossTheWrapFires) {
    std::array<std::int64_t, 16> t;
    t.fill(0);
    t[14] = t[15] = t[0] = t[1] = 100;  // 4 pixels across index 0
    EXPECT_TRUE((arc_fires<16, 3, 6>(t)));
}

}  // namespace
}  // namespace evcorner
