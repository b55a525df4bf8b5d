// Inputs the libFuzzer targets (fuzz/) found to misbehave, kept as regression tests.

#include <gtest/gtest.h>

#include <fstream>
#include <limits>

#include "evcorner/io/csv_reader.hpp"
#include "evcorner/io/npy.hpp"
#include "io_test_util.hpp"

namespace evcorner::test {
namespace {

// fuzz_aedat4: a time jump backwards by more than INT64_MAX overflowed (UB) while the
// error message computed the gap.
TEST(FuzzRegression, BackwardsGapLargerThanInt64MaxIsReportedExactly) {
    TempDir dir;
    const std::string path = dir.path("gap.npy");
    {
        io::NpyWriter w(path);
        const Event ev[2] = {{5812740453544693760, 1, 1, 1}, {-8065097694775672816, 1, 1, 0}};
        w.write(ev);
        w.close();
    }
    io::ReaderOptions o;
    o.fallback_sensor = std::nullopt;
    io::NpyReader r(path, o);
    const ReadResult res = read_all(r);
    ASSERT_TRUE(res.failed);
    EXPECT_EQ(res.events.size(), 1u);
    EXPECT_NE(res.error.find("(13877838148320366576 us before the previous event)"), std::string::npos) << res.error;
}

// fuzz_csv: a timestamp of 19 integer digits overflowed int64 (UB) before the length
// check caught it; it must be a "too large" error on its line, after the good rows.
TEST(FuzzRegression, CsvTimestampOfNineteenDigitsIsAnError) {
    TempDir dir;
    const std::string path = dir.path("long.csv");
    {
        std::ofstream f(path);
        f << "t,x,y,p\n51980787,98,52,1\n9999999999999999999,1,1,1\n";
    }
    io::ReaderOptions o;
    o.fallback_sensor = std::nullopt;
    io::CsvReader r(path, o);
    const ReadResult res = read_all(r);
    ASSERT_TRUE(res.failed);
    EXPECT_EQ(res.events.size(), 1u);
    EXPECT_NE(res.error.find(":3:"), std::string::npos) << res.error;
    EXPECT_NE(res.error.find("timestamp too large"), std::string::npos) << res.error;
}

}  // namespace
}  // namespace evcorner::test
