// The detection pipeline as a library (pipeline/detect.hpp), without the CLI: the same
// corners as the detector run directly and as `evcorner detect`, for every registered
// detector on one thread and every local one on several; the summary; input errors
// (outputs absent after an input error, or --allow-damaged's result); the option checks.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_test_util.hpp"
#include "evcorner/error.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/text_reader.hpp"
#include "evcorner/pipeline/detect.hpp"
#include "evcorner/registry.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

namespace fs = std::filesystem;
using test::slurp;

class Pipeline : public test::CliTest {
protected:
    // The corners of `config` over the sample, the detector run directly.
    std::vector<Event> direct(const DetectorConfig& config) {
        const auto events = io::read_text_file(sample_.string());
        AnyDetector d = make_detector(config, kDavis240);
        std::vector<std::uint8_t> flags(events.size());
        detect(d, std::span<const Event>(events), flags);
        std::vector<Event> out;
        for (std::size_t i = 0; i < events.size(); ++i)
            if (flags[i]) out.push_back(events[i]);
        return out;
    }
};

TEST_F(Pipeline, EveryDetectorGivesTheCornersOfTheDetectorItself) {
    for (const DetectorInfo& info : detector_infos()) {
        const DetectorConfig config{std::string(info.name), {}};
        const std::vector<Event> expected = direct(config);
        ASSERT_GT(expected.size(), 0u) << info.name;
        for (const int threads : {1, 2, 3}) {
            if (threads > 1 && !info.local()) continue;
            SCOPED_TRACE(std::string(info.name) + ", " + std::to_string(threads) + " threads");
            const auto reader = io::open_event_reader(sample_.string());
            pipeline::CollectSink collect;
            pipeline::DetectSink* sinks[] = {&collect};
            pipeline::DetectOptions o;
            o.detector = config;
            o.threads = threads;
            o.batch = 4096;  // several batches, so that threads overlap reading
            std::uint64_t calls = 0, last_events = 0;
            const auto s = pipeline::run_detect(*reader, o, sinks, [&](const pipeline::DetectProgress& p) {
                ++calls;
                EXPECT_GE(p.events, last_events);
                last_events = p.events;
            });
            EXPECT_EQ(collect.corners, expected);
            EXPECT_EQ(s.events, 30000u);
            EXPECT_EQ(s.corners, expected.size());
            EXPECT_EQ(s.detector, info.name);
            EXPECT_EQ(s.sensor, kDavis240);
            EXPECT_EQ(s.threads, threads);
            EXPECT_TRUE(s.damaged.empty());
            EXPECT_EQ(calls, (30000u + 4095u) / 4096u);  // once per batch
            EXPECT_EQ(last_events, 30000u);
            EXPECT_NEAR(s.reduction_percent(), 100.0 * (1.0 - static_cast<double>(expected.size()) / 30000.0), 1e-9);
            EXPECT_GT(s.wall_s, 0.0);
        }
    }
}

TEST_F(Pipeline, DetectFileWritesWhatTheCliWrites) {
    for (const DetectorInfo& info : detector_infos()) {
        SCOPED_TRACE(std::string(info.name));
        const std::string name(info.name);
        const test::CliResult r = run("detect '" + sample_.string() + "' -d " + name + " -q -o cli.txt --mask cli.mask");
        ASSERT_EQ(r.status, 0) << r.err;
        pipeline::DetectFiles f;
        f.input = sample_.string();
        f.output = (dir_ / "lib.txt").string();
        f.mask = (dir_ / "lib.mask").string();
        pipeline::DetectOptions o;
        o.detector.name = name;
        const auto s = pipeline::detect_file(f, o);
        EXPECT_EQ(slurp(dir_ / "lib.txt"), slurp(dir_ / "cli.txt"));
        EXPECT_EQ(slurp(dir_ / "lib.mask"), slurp(dir_ / "cli.mask"));
        EXPECT_EQ(s.corners, test::count_lines(slurp(dir_ / "cli.txt")));
    }
    // The mask marks the golden positions (eFAST, the bundled sample).
    const auto golden = test::read_index_file(test::bundled_data() / "ecd/shapes_translation/efast.golden.idx");
    pipeline::DetectFiles f;
    f.input = sample_.string();
    f.output = "";
    f.mask = (dir_ / "golden.mask").string();
    (void)pipeline::detect_file(f, {});
    std::ifstream in(dir_ / "golden.mask");
    std::vector<std::uint64_t> marked;
    std::string line;
    for (std::uint64_t i = 0; std::getline(in, line); ++i)
        if (line == "1") marked.push_back(i);
    EXPECT_EQ(marked, golden);
}

TEST_F(Pipeline, ScoresAndParametersReachTheSinks) {
    pipeline::DetectOptions o;
    o.detector.name = "harris";
    o.detector.params.set("harris-window", std::int64_t{7});
    o.with_score = true;
    const auto reader = io::open_event_reader(sample_.string());
    pipeline::CollectSink collect;
    pipeline::DetectSink* sinks[] = {&collect};
    const auto s = pipeline::run_detect(*reader, o, sinks);
    EXPECT_EQ(collect.corners, direct(o.detector));
    ASSERT_EQ(collect.scores.size(), collect.corners.size());
    for (const double v : collect.scores) EXPECT_GT(v, 8.0);  // a corner scores above the threshold
    EXPECT_EQ(s.corners, collect.corners.size());
}

TEST_F(Pipeline, AnInputErrorLeavesNoOutputsOrEndsTheInput) {
    // 500 good lines, then a malformed one.
    std::ifstream sample(sample_);
    std::string text, line;
    for (int i = 0; i < 500 && std::getline(sample, line); ++i) text += line + "\n";
    text += "1.0 x y 1\n";
    const std::string bad = write("bad.txt", text);
    pipeline::DetectFiles f;
    f.input = bad;
    f.output = (dir_ / "c.txt").string();
    f.mask = (dir_ / "m.txt").string();
    pipeline::DetectOptions o;
    o.batch = 128;
    std::uint64_t seen = 0;
    try {
        (void)pipeline::detect_file(f, o, [&](const pipeline::DetectProgress& p) { seen = p.events; });
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(":501:"), std::string::npos) << e.what();
    }
    EXPECT_EQ(seen, 500u);
    EXPECT_FALSE(std::filesystem::exists(dir_ / "c.txt"));  // absent, not a partial result
    EXPECT_FALSE(std::filesystem::exists(dir_ / "m.txt"));
    o.allow_damaged = true;
    o.threads = 2;
    const auto s = pipeline::detect_file(f, o);
    EXPECT_EQ(s.events, 500u);
    EXPECT_NE(s.damaged.find(":501:"), std::string::npos) << s.damaged;
    EXPECT_EQ(test::count_lines(slurp(dir_ / "m.txt")), 500u);
}

TEST_F(Pipeline, OptionsAreCheckedBeforeReading) {
    auto message = [&](const pipeline::DetectOptions& o) {
        try {
            pipeline::check_detect_options(o);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("(accepted)");
    };
    pipeline::DetectOptions o;
    EXPECT_EQ(message(o), "(accepted)");
    o.with_score = true;  // every detector has a score (docs/scores.md), on one thread
    EXPECT_EQ(message(o), "(accepted)");
    o.threads = 2;
    EXPECT_NE(message(o).find("needs one thread"), std::string::npos);
    o.threads = 1;
    o.with_score = false;
    o.detector.name = "harris-global";
    o.threads = 2;
    const std::string m = message(o);
    EXPECT_NE(m.find("not local"), std::string::npos) << m;
    EXPECT_NE(m.find(std::string(detector_info("harris-global").not_local)), std::string::npos) << m;
    o.detector.name = "nope";
    EXPECT_NE(message(o).find("unknown detector 'nope'"), std::string::npos);
    o.detector.name = "efast";
    o.threads = 1;
    o.detector.params.set("harris-window", std::int64_t{9});
    EXPECT_NE(message(o).find("takes no parameter"), std::string::npos);
    o.detector.params = {};
    o.batch = 0;
    EXPECT_NE(message(o).find("batch"), std::string::npos);
    // detect_file refuses an output onto its input before opening anything.
    pipeline::DetectFiles f;
    f.input = sample_.string();
    f.output = sample_.string();
    EXPECT_THROW((void)pipeline::detect_file(f, {}), std::invalid_argument);
}

}  // namespace
}  // namespace evcorner
