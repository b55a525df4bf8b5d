// evcorner bench and evcorner detect --threads as a user runs them.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_test_util.hpp"
#include "evcorner/registry.hpp"

namespace evcorner {
namespace {

namespace fs = std::filesystem;

using Result = test::CliResult;
using test::slurp;

class CliBench : public test::CliTest {};

TEST_F(CliBench, PrintsTheTableAndWritesJson) {
    const Result r = run("bench '" + sample_.string() +
                         "' --min-events 100000 --repeat 2 --threads 1,2 --json b.json -q");
    ASSERT_EQ(r.status, 0) << r.err;
    for (const char* what : {"CPU", "build", "efast", "harris-global", "p99.9", "Mev/s", "memory"})
        EXPECT_NE(r.out.find(what), std::string::npos) << what << " missing from:\n" << r.out;
    const auto j = nlohmann::json::parse(slurp(dir_ / "b.json"));
    EXPECT_TRUE(j.contains("cpu"));
    EXPECT_TRUE(j.contains("build_flags"));
    // Every registered detector (the default list) at 1 thread, the local ones at 2 too
    // (efast and harris at 1 and 2 threads, harris-global at 1, and any detector added since).
    std::size_t expected_rows = 0;
    for (const DetectorInfo& d : detector_infos()) expected_rows += d.local() ? 2 : 1;
    ASSERT_GE(expected_rows, 5u);
    ASSERT_EQ(j["results"].size(), expected_rows);
    for (const auto& x : j["results"]) {
        EXPECT_GE(x["events"].get<std::uint64_t>(), 100000u);
        EXPECT_EQ(x["ns_per_event"].size(), 2u);
        EXPECT_GT(x["ns_per_event_median"].get<double>(), 0.0);
        EXPECT_GT(x["memory_bytes"].get<std::uint64_t>(), 0u);
    }
    // The replayed stream gives the same corners on 1 and 2 threads.
    EXPECT_EQ(j["results"][0]["corners"], j["results"][1]["corners"]);
}

TEST_F(CliBench, UnknownDetectorIsAUsageError) {
    const Result r = run("bench '" + sample_.string() + "' -d nope --min-events 10");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("nope"), std::string::npos) << r.err;
}

TEST_F(CliBench, DetectThreadsGivesIdenticalOutputs) {
    ASSERT_EQ(run("detect '" + sample_.string() + "' -o one.txt --mask one.mask -q").status, 0);
    for (const char* j : {"2", "3", "4"}) {
        const Result r = run("detect '" + sample_.string() + "' --threads " + j + " -o many.txt --mask many.mask -q");
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(slurp(dir_ / "many.txt"), slurp(dir_ / "one.txt")) << j << " threads";
        EXPECT_EQ(slurp(dir_ / "many.mask"), slurp(dir_ / "one.mask")) << j << " threads";
    }
}

TEST_F(CliBench, DetectThreadsRefusesAGlobalDetector) {
    const Result r = run("detect '" + sample_.string() + "' -d harris-global --threads 2 -q");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace evcorner
