// evcorner label, eval and render as a user runs them, on the bundled sample.

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_test_util.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/event.hpp"
#include "evcorner/io/text_reader.hpp"

namespace evcorner {
namespace {

namespace fs = std::filesystem;

using test::slurp;

// Width and height from a PNG's IHDR chunk; (0, 0) when it is not a PNG.
std::pair<unsigned, unsigned> png_size(const fs::path& p) {
    const std::string b = slurp(p);
    if (b.size() < 24 || b.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 || b.compare(12, 4, "IHDR") != 0) return {0, 0};
    auto be32 = [&](std::size_t o) {
        return (unsigned(static_cast<unsigned char>(b[o])) << 24) | (unsigned(static_cast<unsigned char>(b[o + 1])) << 16) |
               (unsigned(static_cast<unsigned char>(b[o + 2])) << 8) | unsigned(static_cast<unsigned char>(b[o + 3]));
    };
    return {be32(16), be32(20)};
}

class CliEval : public test::CliTest {
protected:
    // The exit status of "evcorner ARGS"; its standard error into *err when given.
    int run_status(const std::string& args, std::string* err = nullptr) {
        const test::CliResult r = run(args);
        if (err) *err = r.err;
        return r.status;
    }
};

TEST_F(CliEval, LabelWritesOneLabelPerCornerAndTheFtShare) {
    ASSERT_EQ(run_status("detect '" + sample_.string() + "' -q -o corners.txt"), 0);
    const std::size_t corners = test::read_index_file(test::bundled_data() / "ecd/shapes_translation/efast.golden.idx").size();
    std::string err;
    ASSERT_EQ(run_status("label corners.txt -o labels.txt --json l.json", &err), 0) << err;
    std::ifstream in(dir_ / "labels.txt");
    std::size_t lines = 0, ones = 0;
    for (std::string l; std::getline(in, l); ++lines) {
        ASSERT_TRUE(l == "0" || l == "1") << l;
        ones += l == "1";
    }
    EXPECT_EQ(lines, corners);
    EXPECT_GT(ones, 0u);
    EXPECT_LT(ones, corners);
    // The printed and JSON FT are the share of ones in the label file.
    const std::string json = slurp(dir_ / "l.json");
    EXPECT_NE(json.find("\"on_track\": " + std::to_string(ones)), std::string::npos) << json;
    // With the labels in a file, the FT line goes to standard output.
    const std::string out = slurp(dir_ / "out.stdout");
    EXPECT_NE(out.find(std::to_string(ones) + " of " + std::to_string(corners)), std::string::npos) << out;
}

TEST_F(CliEval, EvalWritesBothTablesAndTheReport) {
    std::string err;
    ASSERT_EQ(run_status("eval '" + (test::bundled_data() / "ecd").string() + "' -d efast,harris --repeat 1 -q --report rep",
                  &err),
              0)
        << err;
    const std::string t1 = slurp(dir_ / "rep/table1.csv");
    const std::string t2 = slurp(dir_ / "rep/table2.csv");
    // Reduction rate from the goldens' corner counts, not from the code.
    auto reduction = [](std::size_t corners) { return 100.0 * (1.0 - static_cast<double>(corners) / 30000.0); };
    const auto efast = test::read_index_file(test::bundled_data() / "ecd/shapes_translation/efast.golden.idx").size();
    const auto harris = test::read_index_file(test::bundled_data() / "ecd/shapes_translation/harris.golden.idx").size();
    for (const auto& [name, corners] : {std::pair{std::string("efast"), efast}, {std::string("harris"), harris}}) {
        const std::string prefix = "shapes_translation," + name + ",30000," + std::to_string(corners) + ",";
        const auto at = t1.find(prefix);
        ASSERT_NE(at, std::string::npos) << t1;
        std::istringstream row(t1.substr(at + prefix.size()));
        std::string on_track, red;
        std::getline(row, on_track, ',');
        std::getline(row, red, ',');
        EXPECT_NEAR(std::stod(red), reduction(corners), 1e-3) << name;
        EXPECT_NE(t2.find("\n" + name + ",30000,"), std::string::npos) << t2;
    }
    EXPECT_FALSE(slurp(dir_ / "rep/report.md").empty());
    EXPECT_NE(slurp(dir_ / "rep/results.json").find("\"ft_percent\""), std::string::npos);
    bool some_png = false;
    for (const auto& f : fs::directory_iterator(dir_ / "rep/figures")) some_png |= png_size(f.path()).first > 0;
    EXPECT_TRUE(some_png);
}

// Without -d, eval runs every registered detector: a Table 1 row and a Table 2 row each,
// side by side in the report; each with the corners `evcorner detect -d NAME` finds.
TEST_F(CliEval, EvalRunsEveryRegisteredDetectorByDefault) {
    std::string err;
    ASSERT_EQ(run_status("eval '" + sample_.string() + "' --repeat 1 -q --no-figures --report rep", &err), 0) << err;
    const std::string t1 = slurp(dir_ / "rep/table1.csv");
    const std::string t2 = slurp(dir_ / "rep/table2.csv");
    const std::string md = slurp(dir_ / "rep/report.md");
    for (const DetectorInfo& d : detector_infos()) {
        const std::string name(d.name);
        ASSERT_EQ(run_status("detect '" + sample_.string() + "' -d " + name + " -q -o c-" + name + ".txt", &err), 0) << err;
        const std::size_t corners = test::count_lines(slurp(dir_ / ("c-" + name + ".txt")));
        EXPECT_NE(t1.find("," + name + ",30000," + std::to_string(corners) + ","), std::string::npos) << name << "\n" << t1;
        EXPECT_NE(t2.find("\n" + name + ",30000,"), std::string::npos) << name << "\n" << t2;
        EXPECT_NE(md.find(" " + name + " Red. | " + name + " FT |"), std::string::npos) << name;
    }
    // -d all is the same list; a parameter reaches the detectors that take it, and one
    // that none of them takes is refused.
    ASSERT_EQ(run_status("eval '" + sample_.string() + "' -d all --harris-window 7 --repeat 1 -q --no-figures --report rep7", &err), 0)
        << err;
    ASSERT_EQ(run_status("detect '" + sample_.string() + "' -d harris --harris-window 7 -q -o h7.txt", &err), 0) << err;
    EXPECT_NE(slurp(dir_ / "rep7/table1.csv").find(",harris,30000," + std::to_string(test::count_lines(slurp(dir_ / "h7.txt"))) + ","),
              std::string::npos);
    EXPECT_EQ(run_status("eval '" + sample_.string() + "' -d efast --harris-window 7 --repeat 1 -q", &err), 2);
    EXPECT_NE(err.find("--harris-window"), std::string::npos) << err;
}

TEST_F(CliEval, RenderEveryKindAsPng) {
    for (const std::string kind : {"sae", "corners", "space-time", "labels"}) {
        std::string err;
        ASSERT_EQ(run_status("render '" + sample_.string() + "' -k " + kind + " -o " + kind + ".png", &err), 0) << kind << err;
        const auto [w, h] = png_size(dir_ / (kind + ".png"));
        EXPECT_GT(w, 0u) << kind;
        EXPECT_GT(h, 0u) << kind;
        if (kind == "sae" || kind == "corners") {  // the sensor at the default scale of 2, framed
            EXPECT_GT(w, 480u) << kind;
            EXPECT_GT(h, 360u) << kind;
        }
    }
    std::string err;
    EXPECT_NE(run_status("render '" + sample_.string() + "' -k nonsense -o x.png", &err), 0);
    EXPECT_NE(run_status("render no-such-file.txt -o x.png", &err), 0);
    EXPECT_NE(err.find("no-such-file.txt"), std::string::npos) << err;
}


// The rows of table1.csv: sequence -> "detector,events,corners,on_track,..." lines.
std::vector<std::string> csv_rows(const std::string& csv) {
    std::vector<std::string> rows;
    std::istringstream in(csv);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) rows.push_back(line);
    return rows;
}

// Inputs of one name (two folders' events.txt) are two Table 1 rows, two sets of figures
// and two CSV rows that tell them apart.
TEST_F(CliEval, InputsOfOneNameStayApart) {
    for (const char* d : {"a/shapes_translation", "b/shapes_translation"}) {
        fs::create_directories(dir_ / d);
        fs::copy_file(sample_, dir_ / d / "events.txt");
    }
    fs::copy_file(sample_, dir_ / "a/x.txt");
    fs::copy_file(sample_, dir_ / "b/x.txt");
    std::string err;
    ASSERT_EQ(run_status("eval a/shapes_translation/events.txt b/shapes_translation a/shapes_translation/events.txt "
                         "a/x.txt b/x.txt -d efast --repeat 1 -q --report rep",
                         &err),
              0)
        << err;
    const auto rows = csv_rows(slurp(dir_ / "rep/table1.csv"));
    ASSERT_EQ(rows.size(), 5u) << slurp(dir_ / "rep/table1.csv");
    const char* names[] = {"a/shapes_translation", "b/shapes_translation", "a/shapes_translation#2", "a/x.txt",
                           "b/x.txt"};
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(rows[i].substr(0, rows[i].find(',')), names[i]) << rows[i];
    // One figure set per input, none overwritten; the paper's row for every shapes_translation.
    for (const char* stem : {"a_shapes_translation", "b_shapes_translation", "a_shapes_translation#2", "a_x.txt",
                             "b_x.txt"}) {
        EXPECT_GT(png_size(dir_ / "rep/figures" / (std::string(stem) + ".efast.labels.png")).first, 0u) << stem;
        EXPECT_GT(png_size(dir_ / "rep/figures" / (std::string(stem) + ".sae.png")).first, 0u) << stem;
    }
    const std::string md = slurp(dir_ / "rep/report.md");
    for (const char* n : {"| a/shapes_translation | 91.7 |", "| b/shapes_translation | 91.7 |",
                          "| a/shapes_translation#2 | 91.7 |"})
        EXPECT_NE(md.find(n), std::string::npos) << n << "\n" << md;
    // A name whose figure stem meets another's ("a/x.txt" and "a_x.txt", named apart from
    // "a_x.npy") keeps its figures apart.
    fs::copy_file(sample_, dir_ / "a_x.txt");
    ASSERT_EQ(run_status("convert a_x.txt a_x.npy", &err), 0) << err;
    ASSERT_EQ(run_status("eval a/x.txt b/x.txt a_x.txt a_x.npy -d efast --repeat 1 -q --report rep2", &err), 0) << err;
    EXPECT_GT(png_size(dir_ / "rep2/figures/a_x.txt.sae.png").first, 0u);
    EXPECT_GT(png_size(dir_ / "rep2/figures/a_x.txt#2.sae.png").first, 0u);
}

// A folder of event files (not the dataset's layout) is evaluated file by file; report.md
// compares with the paper only the sequences the paper has.
TEST_F(CliEval, FolderOfEventFilesAndNoPaperRows) {
    fs::create_directories(dir_ / "rec");
    fs::copy_file(sample_, dir_ / "rec/one.txt");
    ASSERT_EQ(run_status("convert '" + sample_.string() + "' rec/two.npy"), 0);
    ASSERT_EQ(run_status("convert '" + sample_.string() + "' rec/three.aedat4"), 0);
    write("rec/README.md", "not events\n");
    std::string err;
    ASSERT_EQ(run_status("eval rec -d efast --repeat 1 --report rep --no-figures", &err), 0) << err;
    EXPECT_NE(err.find("README.md: skipped"), std::string::npos) << err;
    const auto rows = csv_rows(slurp(dir_ / "rep/table1.csv"));
    ASSERT_EQ(rows.size(), 3u);
    // Sorted by file name; the same events in three formats give the same row.
    const std::string tail = rows[0].substr(rows[0].find(','));
    EXPECT_EQ(rows[0], "one" + tail);
    EXPECT_EQ(rows[1], "three" + tail);
    EXPECT_EQ(rows[2], "two" + tail);
    const std::string md = slurp(dir_ / "rep/report.md");
    EXPECT_EQ(md.find("(paper)"), std::string::npos) << md;
    EXPECT_NE(md.find("nothing to set beside it"), std::string::npos) << md;
    // A folder with no event file at all is still a usage error, naming it.
    fs::create_directories(dir_ / "empty");
    write("empty/notes.md", "x\n");
    EXPECT_EQ(run_status("eval empty -q", &err), 2);
    EXPECT_NE(err.find("empty: no <sequence>/events.txt folder, no rosbag2 folder (metadata.yaml) and no event file"),
              std::string::npos)
        << err;
}

std::string le32(std::uint32_t v) {
    std::string b(4, '\0');
    for (int i = 0; i < 4; ++i) b[i] = static_cast<char>(v >> (8 * i));
    return b;
}

// A MAT 5 file (little-endian, uncompressed) with one N x 4 double matrix "events" of
// columns x, y, p, t (microseconds).
std::string mat5_events(const std::vector<Event>& ev) {
    std::string head(128, ' ');
    const std::string text = "MATLAB 5.0 MAT-file, written by test_cli_eval";
    head.replace(0, text.size(), text);
    std::fill(head.begin() + 116, head.end(), '\0');
    head[125] = '\1';
    head[126] = 'I';
    head[127] = 'M';
    const auto n = static_cast<std::uint32_t>(ev.size());
    std::string body = le32(6) + le32(8) + le32(6) + le32(0);  // array flags: double
    body += le32(5) + le32(8) + le32(n) + le32(4);             // dimensions N x 4
    body += le32(1) + le32(6) + std::string("events\0\0", 8);  // name
    body += le32(9) + le32(n * 32);                            // real part, column by column
    for (int col = 0; col < 4; ++col)
        for (const Event& e : ev) {
            const double v = col == 0 ? e.x : col == 1 ? e.y : col == 2 ? e.p : static_cast<double>(e.t);
            body += std::string(reinterpret_cast<const char*>(&v), 8);
        }
    return head + le32(14) + le32(static_cast<std::uint32_t>(body.size())) + body;
}

// ATIS .bin records: x, y, then polarity and the 23-bit time (microseconds).
std::string atis_events(const std::vector<Event>& ev) {
    std::string out;
    for (const Event& e : ev) {
        const auto t = static_cast<std::uint32_t>(e.t);
        out += {static_cast<char>(e.x), static_cast<char>(e.y), static_cast<char>((e.p ? 0x80 : 0) | ((t >> 16) & 0x7f)),
                static_cast<char>((t >> 8) & 0xff), static_cast<char>(t & 0xff)};
    }
    return out;
}

// eval FOLDER takes every kind of event file the library reads: the same events as text,
// gzip-compressed text, CSV, .npy, AEDAT 4, HDF5, MATLAB .mat and ATIS .bin give the same
// row; a file of another kind is skipped with a note.
TEST_F(CliEval, FolderTakesEveryFormatTheLibraryReads) {
    std::vector<Event> events = io::read_text_file(sample_.string());
    ASSERT_GT(events.size(), 1000u);
    const std::int64_t t0 = events.front().t;
    for (Event& e : events) e.t -= t0;  // within the ATIS clock's 23 bits
    ASSERT_LT(events.back().t, std::int64_t{1} << 23);
    std::string text;
    for (const Event& e : events) text += fmt::format("{}.{:06d} {} {} {}\n", e.t / 1'000'000, e.t % 1'000'000, e.x, e.y, int(e.p));
    fs::create_directories(dir_ / "rec");
    write("rec/a_text.txt", text);
    for (const char* f : {"b_csv.csv", "c_npy.npy", "d_aedat4.aedat4", "e_hdf5.h5"})
        ASSERT_EQ(run_status(std::string("convert rec/a_text.txt rec/") + f), 0) << f;
    ASSERT_EQ(std::system(("gzip -c '" + (dir_ / "rec/a_text.txt").string() + "' > '" +
                           (dir_ / "rec/f_gzip.TXT.gz").string() + "'").c_str()),
              0);
    write("rec/g_mat.mat", mat5_events(events));
    write("rec/h_atis.bin", atis_events(events));
    write("rec/notes.yaml", "not events\n");
    std::string err;
    ASSERT_EQ(run_status("eval rec -d efast --repeat 1 --report rep --no-figures", &err), 0) << err;
    EXPECT_NE(err.find("notes.yaml: skipped"), std::string::npos) << err;
    const auto rows = csv_rows(slurp(dir_ / "rep/table1.csv"));
    const char* names[] = {"a_text", "b_csv", "c_npy", "d_aedat4", "e_hdf5", "f_gzip", "g_mat", "h_atis"};
    ASSERT_EQ(rows.size(), std::size(names)) << slurp(dir_ / "rep/table1.csv");
    const std::string tail = rows[0].substr(rows[0].find(','));
    EXPECT_EQ(tail.rfind(",efast," + std::to_string(events.size()) + ",", 0), 0u) << tail;
    for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i], names[i] + tail);
}

// ROS bags in a folder: .bag, .db3 and .mcap files and rosbag2 folders (metadata.yaml) are
// sequences, read (here: refused, for they are cut short after their magic bytes) and
// never skipped by their name.
TEST_F(CliEval, FolderTakesBagFilesAndRosbag2Folders) {
    const std::string sqlite("SQLite format 3\0", 16);
    for (const auto& [f, magic] : {std::pair<std::string, std::string>{"x.bag", "#ROSBAG V2.0\n"},
                                   {"x.db3", sqlite},
                                   {"x.MCAP", "\x89MCAP0\r\n"}}) {
        const std::string folder = "in-" + f;
        fs::create_directories(dir_ / folder);
        write(folder + "/" + f, magic + "cut");
        std::string err;
        EXPECT_EQ(run_status("eval " + folder + " -d efast --repeat 1 -q --no-figures", &err), 1) << f;
        EXPECT_NE(err.find("evcorner: error: " + folder + "/" + f), std::string::npos) << err;
        EXPECT_EQ(err.find("skipped"), std::string::npos) << err;
        EXPECT_EQ(err.find("expected a timestamp"), std::string::npos) << err;  // not read as text
    }
    // A rosbag2 folder inside a folder, and given itself: one sequence, the folder.
    fs::create_directories(dir_ / "top/bag2");
    write("top/bag2/metadata.yaml", "rosbag2_bagfile_information:\n  relative_file_paths:\n    - part_0.db3\n");
    write("top/bag2/part_0.db3", sqlite + "cut");
    for (const char* in : {"top", "top/bag2"}) {
        std::string err;
        EXPECT_EQ(run_status(std::string("eval ") + in + " -d efast --repeat 1 -q --no-figures", &err), 1) << in;
        EXPECT_NE(err.find("top/bag2/part_0.db3"), std::string::npos) << err;
        EXPECT_EQ(err.find("no <sequence>/events.txt"), std::string::npos) << err;
    }
}

// The real recordings of the formats eval's folders took no file of before: the events
// and corners of each equal detect's on the same input.
TEST_F(CliEval, FolderOfRealMatAtisAndBagRecordings) {
    EVCORNER_REQUIRE_SHARED_DATA();
    const fs::path real = test::shared_data() / "real";
    const std::vector<std::pair<std::string, fs::path>> inputs = {
        {"building", real / "rpg-event-lifetime/building.mat"},
        {"sample_nmnist", real / "tonic-testdata/sample_nmnist.bin"},
        {"test_events_1.bag", real / "ros2-event-camera-py/ros1/test_events_1.bag"},
        {"test_events_1", real / "ros2-event-camera-py/test_events_1"},
        {"test_events_2_0", real / "ros2-event-camera-py/test_events_2/test_events_2_0.mcap"},
        {"libcaer_rollover_0", real / "ros2-event-camera-codecs/test_data_libcaer_rollover/libcaer_rollover_0.db3"}};
    fs::create_directories(dir_ / "rec");
    for (const auto& [name, path] : inputs) {
        ASSERT_TRUE(fs::exists(path)) << path;
        fs::create_symlink(path, dir_ / "rec" / path.filename());
    }
    std::string err;
    ASSERT_EQ(run_status("eval rec -d efast --repeat 1 --report rep --no-figures", &err), 0) << err;
    const auto rows = csv_rows(slurp(dir_ / "rep/table1.csv"));
    ASSERT_EQ(rows.size(), inputs.size()) << slurp(dir_ / "rep/table1.csv");
    for (const auto& [name, path] : inputs) {
        ASSERT_EQ(run_status("detect '" + path.string() + "' -d efast -q -o /dev/null --summary-json s.json", &err), 0)
            << err;
        const nlohmann::json s = nlohmann::json::parse(slurp(dir_ / "s.json"));
        const std::string want = fmt::format("{},efast,{},{},", name, s.at("events").get<std::size_t>(),
                                             s.at("corners").get<std::size_t>());
        EXPECT_TRUE(std::any_of(rows.begin(), rows.end(), [&](const std::string& r) { return r.rfind(want, 0) == 0; }))
            << want << "\n" << slurp(dir_ / "rep/table1.csv");
    }
}

// label --json -: standard output holds the JSON alone (the summary goes to stderr).
TEST_F(CliEval, LabelJsonOnStandardOutputParses) {
    ASSERT_EQ(run_status("detect '" + sample_.string() + "' -q -o corners.txt"), 0);
    ASSERT_EQ(run_status("label corners.txt -o labels.txt"), 0);
    const std::string labels = slurp(dir_ / "labels.txt");
    const auto ones = static_cast<std::size_t>(std::count(labels.begin(), labels.end(), '1'));
    const test::CliResult r = run("label corners.txt --json -");
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);  // throws when not pure JSON
    EXPECT_EQ(j.at("on_track").get<std::size_t>(), ones);
    EXPECT_NE(r.err.find("FT "), std::string::npos) << r.err;
    // Labels and JSON cannot share standard output.
    EXPECT_EQ(run_status("label corners.txt -o - --json -"), 2);
}

// Streaming: eval reads the input batch by batch (65 536 events). On a stream of several
// batches its corners and FT are those of detect (a streaming command) and label, for
// every detector, and each of the --repeat runs has its own time.
TEST_F(CliEval, StreamedEvalAgreesWithDetectAndLabel) {
    const std::vector<Event> events = io::read_text_file(sample_.string());
    ASSERT_FALSE(events.empty());
    std::string text;
    std::int64_t offset = 0;
    for (int copy = 0; copy < 5; ++copy) {  // 150 000 events, copies 1 ms apart
        const std::int64_t shift = offset - events.front().t;
        for (const Event& e : events) {
            const std::int64_t t = e.t + shift;
            text += fmt::format("{}.{:06d} {} {} {}\n", t / 1'000'000, t % 1'000'000, e.x, e.y, int(e.p));
        }
        offset = events.back().t + shift + 1000;
    }
    write("long.txt", text);
    std::string err;
    ASSERT_EQ(run_status("eval long.txt -d efast,harris --repeat 2 -q --report rep", &err), 0) << err;
    const nlohmann::json res = nlohmann::json::parse(slurp(dir_ / "rep/results.json"));
    ASSERT_EQ(res.at("runs").size(), 2u);
    for (const auto& run : res.at("runs")) {
        const std::string d = run.at("detector");
        ASSERT_EQ(run_status("detect long.txt -d " + d + " -q -o c-" + d + ".txt", &err), 0) << err;
        ASSERT_EQ(run_status("label c-" + d + ".txt --json l-" + d + ".json", &err), 0) << err;
        const nlohmann::json l = nlohmann::json::parse(slurp(dir_ / ("l-" + d + ".json")));
        EXPECT_EQ(run.at("events").get<std::size_t>(), 150'000u) << d;
        EXPECT_EQ(run.at("corners").get<std::size_t>(), test::count_lines(slurp(dir_ / ("c-" + d + ".txt")))) << d;
        EXPECT_EQ(run.at("on_track"), l.at("on_track")) << d;
        EXPECT_EQ(run.at("hypotheses"), l.at("hypotheses")) << d;
        EXPECT_EQ(run.at("detect_s_runs").size(), 2u) << d;
        for (const auto& s : run.at("detect_s_runs")) EXPECT_GT(s.get<double>(), 0.0) << d;
    }
}

}  // namespace
}  // namespace evcorner
