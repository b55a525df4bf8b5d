// evcorner bench and evcorner detect --threads as a user runs them.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_test_util.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/track/tracker.hpp"

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

TEST_F(CliBench, ReportsColdAndReplayedFigures) {
    // The sample has 30 000 events; replayed to 70 000 the stream holds three copies.
    const Result r = run("bench '" + sample_.string() + "' -d efast,harris --min-events 70000 --repeat 2 "
                         "--no-latency --json b.json -q");
    ASSERT_EQ(r.status, 0) << r.err;
    for (const char* what : {"cold", "cold/rep", "replayed ns/event"})
        EXPECT_NE(r.out.find(what), std::string::npos) << what << " missing from:\n" << r.out;
    EXPECT_EQ(r.out.find("x yard"), std::string::npos) << "no yardstick column unless asked:\n" << r.out;
    const auto j = nlohmann::json::parse(slurp(dir_ / "b.json"));
    EXPECT_TRUE(j["yardstick"].is_null());
    ASSERT_EQ(j["results"].size(), 2u);
    for (const auto& x : j["results"]) {
        const auto file_events = x["file_events"].get<std::uint64_t>();
        EXPECT_EQ(x["cold_events"].get<std::uint64_t>(), file_events);
        EXPECT_GT(x["events"].get<std::uint64_t>(), 2 * file_events);  // replayed
        EXPECT_EQ(x["cold_ns_per_event"].size(), 2u);
        EXPECT_GT(x["cold_ns_per_event_median"].get<double>(), 0.0);
        EXPECT_GT(x["cold_vs_replayed"].get<double>(), 0.0);
        EXPECT_FALSE(x.contains("yardstick_ratio"));
        // One pass over the file finds fewer corners than three replayed copies, and some.
        EXPECT_GT(x["cold_corners"].get<std::uint64_t>(), 0u);
        EXPECT_LT(x["cold_corners"].get<std::uint64_t>(), x["corners"].get<std::uint64_t>());
    }
}

TEST_F(CliBench, ReplayGapSeparatesCopiesByMoreThanTheFilterWindow) {
    // By default each replayed copy starts 100 ms after the previous one ends, so Arc*'s 50 ms
    // filter meets every copy as it meets the file's start; back to back (--replay-gap 0) the
    // sample (46 ms long) repeats within 50 ms at every pixel it touches, and the filter
    // rejects events the gap lets through. eFAST has no time window: the gap only
    // shifts time, so its corners stay the same.
    auto corners = [&](const std::string& extra, const std::string& json) {
        const Result r = run("bench '" + sample_.string() + "' -d efast,arcstar --min-events 90000 --repeat 1 "
                             "--no-latency -q --json " + json + extra);
        EXPECT_EQ(r.status, 0) << r.err;
        const auto j = nlohmann::json::parse(slurp(dir_ / json));
        std::map<std::string, std::uint64_t> c;
        for (const auto& x : j["results"]) c[x["detector"].get<std::string>()] = x["corners"].get<std::uint64_t>();
        c["gap"] = j["replay_gap_us"].get<std::uint64_t>();
        return c;
    };
    const auto gap = corners("", "gap.json");
    const auto none = corners(" --replay-gap 0", "none.json");
    EXPECT_EQ(gap.at("gap"), 100000u);
    EXPECT_EQ(none.at("gap"), 0u);
    EXPECT_EQ(gap.at("efast"), none.at("efast"));
    EXPECT_GT(gap.at("arcstar"), none.at("arcstar"));
}

TEST_F(CliBench, YardstickIsAPlainEfastTimedInTheSameRun) {
    const Result r = run("bench '" + sample_.string() + "' -d efast,harris --min-events 1 --repeat 2 "
                         "--no-latency --yardstick --json b.json -q");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("x yard"), std::string::npos) << r.out;
    const auto j = nlohmann::json::parse(slurp(dir_ / "b.json"));
    ASSERT_TRUE(j["yardstick"].is_string());
    ASSERT_EQ(j["results"].size(), 2u);
    const auto& efast = j["results"][0];
    ASSERT_EQ(efast["detector"], "efast");
    // The yardstick computes eFAST: on the file it finds exactly eFAST's corners.
    EXPECT_EQ(efast["yardstick_corners"].get<std::uint64_t>(), efast["cold_corners"].get<std::uint64_t>());
    EXPECT_GT(efast["yardstick_corners"].get<std::uint64_t>(), 0u);
    for (const auto& x : j["results"]) {
        const double yard = x["yardstick_ns_per_event_median"].get<double>();
        const double cold = x["cold_ns_per_event_median"].get<double>();
        EXPECT_GT(yard, 0.0);
        EXPECT_DOUBLE_EQ(x["yardstick_ratio"].get<double>(), yard / cold);
    }
    // The same yardstick figure for every detector of an input.
    EXPECT_EQ(j["results"][0]["yardstick_ns_per_event_median"], j["results"][1]["yardstick_ns_per_event_median"]);
}

TEST_F(CliBench, CpuTimeClock) {
    const Result r = run("bench '" + sample_.string() + "' -d efast --min-events 1 --repeat 1 --no-latency "
                         "--cpu-time --json b.json -q");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("thread CPU time"), std::string::npos) << r.out;
    const auto j = nlohmann::json::parse(slurp(dir_ / "b.json"));
    EXPECT_EQ(j["clock"], "thread CPU time");
    EXPECT_GT(j["results"][0]["cold_ns_per_event_median"].get<double>(), 0.0);
    // One thread's CPU time cannot time a split over several.
    const Result bad = run("bench '" + sample_.string() + "' -d efast --min-events 1 --cpu-time --threads 1,2 -q");
    EXPECT_EQ(bad.status, 2);
    EXPECT_NE(bad.err.find("--cpu-time"), std::string::npos) << bad.err;
}

TEST_F(CliBench, UnknownDetectorIsAUsageError) {
    const Result r = run("bench '" + sample_.string() + "' -d nope --min-events 10");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("nope"), std::string::npos) << r.err;
}

// Three seeds on the sample's shapes (HASTE's 't,x,y,theta,id' tokens, t in seconds), at
// corner events eFAST finds there.
constexpr const char* kSampleSeeds = "51.983,61,109,0,0\n51.983,17,103,0,1\n52.0,104,36,0,2\n";

TEST_F(CliBench, TimesEveryTrackerBesideEfast) {
    write("seeds.txt", kSampleSeeds);
    const Result r = run("bench '" + sample_.string() + "' --tracker all --seeds seeds.txt --init uncentered "
                         "--repeat 2 --json b.json -q");
    ASSERT_EQ(r.status, 0) << r.err;
    for (const char* what : {"CPU", "ns/event", "ns/update", "x efast", "live"})
        EXPECT_NE(r.out.find(what), std::string::npos) << what << " missing from:\n" << r.out;
    // One row per registered tracker (all of them, any added since included), in the
    // registry's order; no detector rows.
    const auto j = nlohmann::json::parse(slurp(dir_ / "b.json"));
    EXPECT_TRUE(j["results"].empty());
    EXPECT_EQ(j["init"], "uncentered");
    ASSERT_EQ(j["trackers"].size(), tracker_registry().size());
    std::size_t with_updates = 0;
    for (std::size_t i = 0; i < tracker_registry().size(); ++i) {
        const auto& x = j["trackers"][i];
        const std::string name(tracker_registry()[i].name);
        EXPECT_EQ(x["tracker"], name);
        EXPECT_NE(r.out.find(name), std::string::npos) << name << " missing from:\n" << r.out;
        EXPECT_EQ(x["events"].get<std::uint64_t>(), 30000u) << name;
        EXPECT_EQ(x["tracks_started"].get<std::uint64_t>(), 3u) << name;
        EXPECT_EQ(x["ns_per_event"].size(), 2u) << name;
        EXPECT_EQ(x["efast_ns_per_event"].size(), 2u) << name;
        EXPECT_GT(x["efast_ns_per_event_median"].get<double>(), 0.0) << name;
        EXPECT_GT(x["efast_ratio_median"].get<double>(), 0.0) << name;
        for (std::size_t k = 0; k < 2; ++k)  // the ratio is per round, to that round's eFAST pass
            EXPECT_DOUBLE_EQ(x["efast_ratio"][k].get<double>(),
                             x["ns_per_event"][k].get<double>() / x["efast_ns_per_event"][k].get<double>())
                << name;
        if (x["updates"].get<std::uint64_t>() > 0) {
            ++with_updates;
            EXPECT_GT(x["ns_per_update_median"].get<double>(), 0.0) << name;
            EXPECT_EQ(x["ns_per_update"].size(), 2u) << name;
        } else {
            EXPECT_TRUE(x["ns_per_update_median"].is_null()) << name;
        }
    }
    EXPECT_GT(with_updates, 0u);  // the HASTE trackers meet events around the seeds
    // eFAST is timed once per round, the same figure in every row of the input.
    EXPECT_EQ(j["trackers"][0]["efast_ns_per_event"], j["trackers"].back()["efast_ns_per_event"]);
}

TEST_F(CliBench, TrackerSeededByADetector) {
    const Result r = run("bench '" + sample_.string() + "' --tracker " + std::string(tracker_registry()[0].name) +
                         " -d efast --repeat 1 --json b.json -q");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(slurp(dir_ / "b.json"));
    ASSERT_EQ(j["trackers"].size(), 1u);
    EXPECT_EQ(j["seeding"], "corners of efast");
    EXPECT_GT(j["trackers"][0]["corners"].get<std::uint64_t>(), 0u);
    EXPECT_GT(j["trackers"][0]["tracks_started"].get<std::uint64_t>(), 0u);
    // One detector seeds: a list is a usage error, and so are both seedings or none.
    write("seeds.txt", kSampleSeeds);
    for (const char* bad : {" -d efast,harris", " -d efast --seeds seeds.txt", ""}) {
        const Result b = run("bench '" + sample_.string() + "' --tracker all --repeat 1 -q" + bad);
        EXPECT_EQ(b.status, 2) << bad;
    }
}

TEST_F(CliBench, UnknownTrackerIsAUsageError) {
    write("seeds.txt", kSampleSeeds);
    const Result r = run("bench '" + sample_.string() + "' --tracker nope --seeds seeds.txt --repeat 1");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("nope"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(tracker_registry()[0].name), std::string::npos) << "names the trackers there are:\n" << r.err;
    const Result seeds_alone = run("bench '" + sample_.string() + "' --seeds seeds.txt --min-events 10");
    EXPECT_EQ(seeds_alone.status, 2);
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
