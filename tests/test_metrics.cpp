// The tables' arithmetic: reduction rate, FT, medians, Table 1 cells, Table 2 pooling.

#include <gtest/gtest.h>

#include <cmath>

#include "evcorner/eval/metrics.hpp"

namespace evcorner::eval {
namespace {

TEST(Metrics, ReductionAndFt) {
    EXPECT_DOUBLE_EQ(reduction_rate(1000, 50), 95.0);
    EXPECT_DOUBLE_EQ(reduction_rate(1000, 0), 100.0);
    EXPECT_DOUBLE_EQ(reduction_rate(0, 0), 0.0);
    EXPECT_DOUBLE_EQ(ft_percent(200, 50), 25.0);
    EXPECT_DOUBLE_EQ(ft_percent(0, 0), 0.0);
}

TEST(Metrics, Median) {
    EXPECT_DOUBLE_EQ(median({3.0, 1.0, 2.0}), 2.0);
    EXPECT_DOUBLE_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);
    EXPECT_DOUBLE_EQ(median({}), 0.0);
}

TEST(Metrics, Table1HasOneCellPerSequenceAndDetector) {
    const std::vector<RunRecord> runs{{"a", "efast", 1000, 100, 25, 0.001},
                                      {"a", "harris", 1000, 50, 40, 0.01},
                                      {"b", "efast", 2000, 400, 100, 0.002}};
    const Table1 t = make_table1(runs);
    ASSERT_EQ(t.sequences, (std::vector<std::string>{"a", "b"}));
    ASSERT_EQ(t.detectors, (std::vector<std::string>{"efast", "harris"}));
    EXPECT_DOUBLE_EQ(t.cells[0][0].reduction, 90.0);
    EXPECT_DOUBLE_EQ(t.cells[0][0].ft, 25.0);
    EXPECT_DOUBLE_EQ(t.cells[0][1].reduction, 95.0);
    EXPECT_DOUBLE_EQ(t.cells[0][1].ft, 80.0);
    EXPECT_DOUBLE_EQ(t.cells[1][0].reduction, 80.0);
    EXPECT_DOUBLE_EQ(t.cells[1][0].ft, 25.0);
    EXPECT_TRUE(std::isnan(t.cells[1][1].reduction));  // harris did not run on b
}

TEST(Metrics, Table2PoolsTimeOverEvents) {
    const std::vector<RunRecord> runs{{"a", "efast", 1000, 0, 0, 0.001},
                                      {"b", "efast", 3000, 0, 0, 0.002},
                                      {"a", "harris", 4000, 0, 0, 0.040}};
    const Table2 t = make_table2(runs);
    ASSERT_EQ(t.size(), 2u);
    EXPECT_EQ(t[0].detector, "efast");
    EXPECT_EQ(t[0].events, 4000u);
    EXPECT_DOUBLE_EQ(t[0].detect_s, 0.003);
    EXPECT_NEAR(t[0].us_per_event, 0.75, 1e-12);
    EXPECT_NEAR(t[0].max_event_rate, 4000 / 0.003, 1e-6);
    EXPECT_NEAR(t[1].us_per_event, 10.0, 1e-12);
    EXPECT_NEAR(t[1].max_event_rate, 100'000.0, 1e-6);
}

}  // namespace
}  // namespace evcorner::eval
