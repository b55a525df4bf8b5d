// The evcorner tool as a user runs it: outputs, mask, summary, exit codes and messages.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "evcorner/io/open.hpp"
#include "evcorner/io/text_reader.hpp"
#include "evcorner/io/formats.hpp"
#include "cli_test_util.hpp"
#include "evcorner/registry.hpp"

namespace evcorner {
namespace {

namespace fs = std::filesystem;

using Result = test::CliResult;
using test::count_lines;
using test::slurp;

class Cli : public test::CliTest {
protected:
    fs::path golden_ = test::bundled_data() / "ecd/shapes_translation/efast.golden.idx";
};

TEST_F(Cli, DetectWritesCornersMaskAndSummary) {
    const Result r = run("detect '" + sample_.string() + "' -o corners.txt --mask mask.txt --summary-json s.json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto golden = test::read_index_file(golden_);
    EXPECT_EQ(count_lines(slurp(dir_ / "corners.txt")), golden.size());

    // The mask marks exactly the golden positions.
    std::ifstream mask(dir_ / "mask.txt");
    std::vector<std::uint64_t> marked;
    std::string line;
    std::uint64_t i = 0;
    for (; std::getline(mask, line); ++i) {
        ASSERT_TRUE(line == "0" || line == "1") << "line " << i + 1 << ": " << line;
        if (line == "1") marked.push_back(i);
    }
    EXPECT_EQ(i, 30000u);
    EXPECT_EQ(marked, golden);

    const std::string json = slurp(dir_ / "s.json");
    EXPECT_NE(json.find("\"events\": 30000"), std::string::npos) << json;
    EXPECT_NE(json.find("\"corners\": " + std::to_string(golden.size())), std::string::npos) << json;
    EXPECT_NE(json.find("\"reduction_rate\""), std::string::npos) << json;
    EXPECT_NE(json.find("\"ns_per_event\""), std::string::npos) << json;

    EXPECT_NE(r.err.find("corners      " + std::to_string(golden.size())), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("reduction"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("ns/event"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("wall time"), std::string::npos) << r.err;
}

TEST_F(Cli, CornerLinesAreTheCornerEventsOfTheInput) {
    const Result r = run("detect '" + sample_.string() + "' -q -o corners.txt");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
    const auto input = io::read_text_file(sample_.string());
    std::vector<Event> expected;
    for (const auto pos : test::read_index_file(golden_)) expected.push_back(input.at(pos));
    EXPECT_EQ(io::read_text_file((dir_ / "corners.txt").string()), expected);
    // Whole lines in the dataset's own style: 9 decimals.
    const std::string text = slurp(dir_ / "corners.txt");
    ASSERT_FALSE(text.empty());
    EXPECT_EQ(text.back(), '\n');
    EXPECT_EQ(text.substr(0, text.find('\n')).find('.'), 2u);
    EXPECT_EQ(text.find(' ') - text.find('.'), 10u);
}

TEST_F(Cli, ReadsStandardInput) {
    const Result from_file = run("detect '" + sample_.string() + "' -q");
    const Result from_stdin = run("detect - -q", sample_.string());
    ASSERT_EQ(from_stdin.status, 0) << from_stdin.err;
    EXPECT_EQ(from_stdin.out, from_file.out);
}

TEST_F(Cli, ReadsBinaryFormatsFromStandardInputToo) {
    ASSERT_EQ(run("convert '" + sample_.string() + "' events.npy -q").status, 0);
    const Result from_file = run("detect events.npy -q");
    const Result from_stdin = run("detect - -q", (dir_ / "events.npy").string());
    ASSERT_EQ(from_stdin.status, 0) << from_stdin.err;
    EXPECT_FALSE(from_file.out.empty());
    EXPECT_EQ(from_stdin.out, from_file.out);
}

TEST_F(Cli, MalformedLineStopsWithFileLineAndLeavesNoOutputFiles) {
    std::string content = slurp(sample_);
    content += "52.1 12 oops 1\n52.2 1 1 1\n";
    const std::string in = write("bad.txt", content);
    const Result good = run("detect '" + sample_.string() + "' -q");
    write("mask.txt", "old mask\n");  // an existing output is left as it was
    Result r = run("detect bad.txt -o corners.txt --mask mask.txt --summary-json s.json");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("bad.txt:30001:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("'52.1 12 oops 1'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("corners.txt, mask.txt, s.json not written"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "corners.txt"));
    EXPECT_FALSE(fs::exists(dir_ / "s.json"));
    EXPECT_EQ(slurp(dir_ / "mask.txt"), "old mask\n");
    for (const auto& entry : fs::directory_iterator(dir_))  // no temporary file left either
        EXPECT_NE(entry.path().filename().string()[0], '.') << entry.path();
    // Standard output is a stream: it has had the corners of the events before the bad line, whole.
    r = run("detect bad.txt");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.out, good.out);
    EXPECT_NE(r.err.find("corners of the 30000 events before the error went to standard output"),
              std::string::npos) << r.err;
    // --allow-damaged: the result of the events before the bad line is the output.
    r = run("detect bad.txt -o corners.txt --mask mask.txt --allow-damaged -q");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(slurp(dir_ / "corners.txt"), good.out);
    EXPECT_EQ(count_lines(slurp(dir_ / "mask.txt")), 30000u);
}

TEST_F(Cli, CutShortBinaryFileIsAnErrorUnlessAllowed) {
    ASSERT_EQ(run("convert '" + sample_.string() + "' events.npy -q").status, 0);
    std::string bytes = slurp(dir_ / "events.npy");
    bytes.resize(bytes.size() - 16 * 1000 - 5);  // the last 1000 records and part of one more
    write("cut.npy", bytes);
    const Result whole = run("detect '" + sample_.string() + "' -q -o all.txt");
    ASSERT_EQ(whole.status, 0);

    Result r = run("detect cut.npy -o corners.txt");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("cut.npy: byte "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("corners.txt not written (--allow-damaged keeps the result of the 28999 events before"),
              std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "corners.txt"));

    r = run("detect cut.npy -o corners.txt --allow-damaged --summary-json s.json");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("warning: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("cut.npy: byte "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("events       28999"), std::string::npos) << r.err;
    EXPECT_NE(slurp(dir_ / "s.json").find("\"damaged\": \""), std::string::npos);
    // The corners are those of the first 28 999 events: a prefix of the whole file's.
    const std::string all = slurp(dir_ / "all.txt");
    const std::string part = slurp(dir_ / "corners.txt");
    EXPECT_FALSE(part.empty());
    EXPECT_EQ(all.compare(0, part.size(), part), 0);

    r = run("convert cut.npy back.txt --allow-damaged");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(count_lines(slurp(dir_ / "back.txt")), 28999u);
}

TEST_F(Cli, OutsideTheSensor) {
    write("big.txt", "0.1 5 5 1\n0.2 300 10 0\n0.3 6 6 1\n");
    Result r = run("detect big.txt");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("big.txt:2:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("x=300 y=10"), std::string::npos) << r.err;

    r = run("detect big.txt --skip-invalid --mask m.txt --summary-json s.json");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("skipped      1"), std::string::npos) << r.err;
    EXPECT_EQ(slurp(dir_ / "m.txt"), "0\n0\n0\n");
    EXPECT_NE(slurp(dir_ / "s.json").find("\"skipped\": 1"), std::string::npos);

    r = run("detect big.txt --size 346x260 -q");
    EXPECT_EQ(r.status, 0) << r.err;
}

TEST_F(Cli, MissingFileAndUsageErrors) {
    Result r = run("detect no-such-file.txt");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("no-such-file.txt: cannot open"), std::string::npos) << r.err;

    r = run("detect '" + sample_.string() + "' --size 12by4");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("WxH"), std::string::npos) << r.err;

    r = run("detect '" + sample_.string() + "' -d nosuch");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("nosuch"), std::string::npos) << r.err;

    r = run("");
    EXPECT_EQ(r.status, 2);
}

TEST_F(Cli, EveryUsageErrorHasThePrefixAndTyposGetASuggestion) {
    const std::string in = "'" + sample_.string() + "'";
    struct Case {
        std::string args, says;
    };
    const Case cases[] = {
        {"detect " + in + " --nms-radus 2", "did you mean '--nms-radius'?"},
        {"detect " + in + " --thread 2", "did you mean '--threads'?"},
        {"detect " + in + " --nms-radius 2", "--nms-radius: does nothing without --nms"},
        {"detect " + in + " --nms-time 500", "--nms-time: does nothing without --nms"},
        {"eval " + in + " --nms-rule decay", "--nms-rule: does nothing without --nms or --compare-nms"},
        {"render " + in + " -o f.png --polarity 0", "--polarity applies to -k sae only (this is -k corners)"},
        {"render " + in + " -o f.png -k sae -d harris", "--detector applies to -k corners or space-time or labels only (this is -k sae)"},
        {"render " + in + " -o f.png --ft-inner 2", "--ft-inner applies to -k labels only"},
        {"render " + in + " -o f.png --at 1e20", "time '1e20' is out of range"},
        {"render " + in + " -o f.png --window 1e20", "at most 1e9"},
        {"detect", "INPUT is required"},
        {"detect " + in + " --frobnicate", "not expected: --frobnicate"},
    };
    for (const Case& c : cases) {
        const Result r = run(c.args);
        EXPECT_EQ(r.status, 2) << c.args << "\n" << r.err;
        EXPECT_EQ(r.err.rfind("evcorner: error: ", 0), 0u) << c.args << "\n" << r.err;
        EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
    }
    // --frobnicate is far from every option: no suggestion.
    EXPECT_EQ(run("detect " + in + " --frobnicate").err.find("did you mean"), std::string::npos);
    EXPECT_EQ(run("detect " + in + " --nms --nms-radius 2 -q -o /dev/null").status, 0);
}

TEST_F(Cli, AllocationsANumberDecidesAreCheckedFirst) {
    const std::string in = "'" + sample_.string() + "'";
    // 2 x (65535 x 16)^2 x 3 bytes of images: terabytes, refused before reading or drawing.
    Result r = run("render " + in + " -o f.png --size 65535x65535 --scale 16");
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("render -k corners: a 1048560x1048560 figure (65535x65535 sensor, --scale 16) needs 6.61 TB"),
              std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(lower --scale"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "f.png"));
    r = run("bench " + in + " --min-events 1099511627776 --repeat 1");
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("bench --min-events 1099511627776: 1099511640000 replayed events needs 18.7 TB"),
              std::string::npos) << r.err;
}

TEST_F(Cli, InfoFormatsListsTheFormatTable) {
    const Result r = run("info --formats");
    ASSERT_EQ(r.status, 0) << r.err;
    for (const io::InputFormat& f : io::input_formats()) {
        EXPECT_NE(r.out.find(std::string(f.name) + " "), std::string::npos) << f.name;
        EXPECT_NE(r.out.find(std::string(f.title)), std::string::npos) << f.name;
    }
    EXPECT_NE(r.out.find("options --csv-columns --time-unit"), std::string::npos) << r.out;
    EXPECT_EQ(run("info --formats '" + sample_.string() + "'").status, 2);
    EXPECT_EQ(run("info").status, 2);
}

std::vector<std::uint64_t> marked_positions(const fs::path& mask) {
    std::ifstream in(mask);
    std::vector<std::uint64_t> marked;
    std::string line;
    for (std::uint64_t i = 0; std::getline(in, line); ++i)
        if (line == "1") marked.push_back(i);
    return marked;
}

TEST_F(Cli, HarrisMatchesItsGoldenAndWritesScores) {
    Result r = run("detect '" + sample_.string() + "' -d harris -q --mask mask.txt -o corners.txt --with-score");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto golden = test::read_index_file(test::bundled_data() / "ecd/shapes_translation/harris.golden.idx");
    EXPECT_EQ(marked_positions(dir_ / "mask.txt"), golden);
    std::ifstream in(dir_ / "corners.txt");
    std::size_t lines = 0;
    for (std::string line; std::getline(in, line); ++lines) {
        std::istringstream fields(line);
        double t, x, y, p, score;
        ASSERT_TRUE(fields >> t >> x >> y >> p >> score) << line;
        EXPECT_GT(score, 8.0) << line;  // a corner scores above the threshold
    }
    EXPECT_EQ(lines, golden.size());

    r = run("detect '" + sample_.string() + "' -d harris-global --harris-n 2000 -q");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_GT(count_lines(r.out), 0u);
}

TEST_F(Cli, ParametersOutOfRangeAreRejected) {
    // Every detector has a score now (docs/scores.md): --with-score works on eFAST; the
    // NMS options are range-checked.
    Result r = run("detect '" + sample_.string() + "' --with-score -q");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_GT(count_lines(r.out), 0u);
    r = run("detect '" + sample_.string() + "' --nms --nms-radius 99");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--nms-radius"), std::string::npos) << r.err;

    r = run("detect '" + sample_.string() + "' -d harris --harris-window 3");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--harris-window"), std::string::npos) << r.err;

    r = run("detect '" + sample_.string() + "' -d harris --harris-nl 100");  // 9x9 = 81 pixels
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("nl"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("81"), std::string::npos) << r.err;

    r = run("detect '" + sample_.string() + "' -d harris-global --harris-n 0");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--harris-n"), std::string::npos) << r.err;
}

TEST_F(Cli, DetectorParametersComeFromTheRegistry) {
    // --KEY and -p KEY=VALUE set the same parameter, and it changes the result.
    ASSERT_EQ(run("detect '" + sample_.string() + "' -d harris -q -o default.txt").status, 0);
    Result r = run("detect '" + sample_.string() + "' -d harris -q -o option.txt --harris-window 7");
    ASSERT_EQ(r.status, 0) << r.err;
    r = run("detect '" + sample_.string() + "' -d harris -q -o param.txt -p harris-window=7 --summary-json s.json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(slurp(dir_ / "s.json").find("\"harris-window\": 7"), std::string::npos) << slurp(dir_ / "s.json");
    EXPECT_EQ(slurp(dir_ / "option.txt"), slurp(dir_ / "param.txt"));
    EXPECT_NE(slurp(dir_ / "option.txt"), slurp(dir_ / "default.txt"));

    r = run("detect '" + sample_.string() + "' -d efast --harris-window 7 -q");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("detector 'efast' takes no parameter --harris-window"), std::string::npos) << r.err;
    r = run("detect '" + sample_.string() + "' -d harris -p harris-n=5 -q");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("harris-n"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("it takes: --harris-window"), std::string::npos) << r.err;
    r = run("detect '" + sample_.string() + "' -d harris -p no-such-key=5 -q");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("unknown parameter no-such-key"), std::string::npos) << r.err;
    r = run("detect '" + sample_.string() + "' -d harris -p harris-window=eleven -q");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("harris-window takes an integer"), std::string::npos) << r.err;
    r = run("detect '" + sample_.string() + "' -d harris --harris-window 7 -p harris-window=9 -q");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("given twice"), std::string::npos) << r.err;

    // --help lists every detector and every parameter key of the registry.
    r = run("detect --help");
    ASSERT_EQ(r.status, 0);
    for (const DetectorInfo& d : detector_infos()) {
        EXPECT_NE(r.out.find(std::string(d.name)), std::string::npos) << d.name;
        for (const ParamInfo& p : d.params) EXPECT_NE(r.out.find("--" + std::string(p.key)), std::string::npos) << p.key;
    }
    EXPECT_NE(r.out.find("-p,--param"), std::string::npos) << r.out;
}

TEST_F(Cli, ThreadsForEveryLocalDetectorGiveOneThreadsOutput) {
    for (const DetectorInfo& d : detector_infos()) {
        const std::string name(d.name);
        const Result one = run("detect '" + sample_.string() + "' -d " + name + " -q -o one.txt --mask one.mask");
        ASSERT_EQ(one.status, 0) << one.err;
        const Result two = run("detect '" + sample_.string() + "' -d " + name + " -q --threads 3 -o two.txt --mask two.mask");
        if (!d.local()) {
            EXPECT_EQ(two.status, 2) << name;
            EXPECT_NE(two.err.find(std::string(d.not_local)), std::string::npos) << two.err;
            continue;
        }
        ASSERT_EQ(two.status, 0) << name << ": " << two.err;
        EXPECT_EQ(slurp(dir_ / "two.txt"), slurp(dir_ / "one.txt")) << name;
        EXPECT_EQ(slurp(dir_ / "two.mask"), slurp(dir_ / "one.mask")) << name;
    }
}

TEST_F(Cli, CornersInOtherFormatsReadBackToTheSameEvents) {
    const Result text = run("detect '" + sample_.string() + "' -q -o corners.txt");
    ASSERT_EQ(text.status, 0) << text.err;
    const auto expected = io::read_text_file((dir_ / "corners.txt").string());
    for (const std::string out : {"corners.npy", "corners.csv"}) {
        const Result r = run("detect '" + sample_.string() + "' -q -o " + out);
        ASSERT_EQ(r.status, 0) << r.err;
        auto reader = io::open_event_reader((dir_ / out).string());
        std::vector<Event> got, buf(4096);
        while (const std::size_t n = reader->read(buf)) got.insert(got.end(), buf.begin(), buf.begin() + n);
        EXPECT_EQ(got, expected) << out;
    }
}

TEST_F(Cli, Aedat2RecordingsMatchTheirGoldens) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const char* name : {"IMU_rotDisk", "IMU_translBoxes"}) {
        const fs::path in = test::shared_data() / "real/davis240c-imu-pyaedattools" / (std::string(name) + ".aedat");
        const Result r = run("detect '" + in.string() + "' -q -o /dev/null --mask mask.txt");
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(marked_positions(dir_ / "mask.txt"),
                  test::read_index_file(test::shared_data() / "golden" /
                                        ("davis240c-imu-pyaedattools." + std::string(name) + ".efast.idx")))
            << name;
    }
}

TEST_F(Cli, HelpHasAnExample) {
    const Result r = run("detect --help");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("Examples:"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--summary-json"), std::string::npos) << r.out;
    EXPECT_NE(run("--help").out.find("detect"), std::string::npos);
}

}  // namespace
}  // namespace evcorner
