// The Event-Camera-Dataset text reader and writer: rounding, short decimals, CRLF,
// comments, each error with its line number, and the round trip.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "evcorner/error.hpp"
#include "evcorner/io/text_reader.hpp"
#include "evcorner/io/text_writer.hpp"

namespace evcorner {
namespace {

namespace fs = std::filesystem;

class TextIo : public ::testing::Test {
protected:
    fs::path dir_;
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("evcorner-text-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    std::string write_file(const std::string& content, const std::string& name = "in.txt") {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << content;
        return p.string();
    }
    std::vector<Event> read(const std::string& content, io::ReaderOptions o = {}) {
        return io::read_text_file(write_file(content), o);
    }
    // The message of the InputError that reading `content` throws ("" if none).
    std::string error_of(const std::string& content, io::ReaderOptions o = {}) {
        try {
            read(content, o);
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    }
};

TEST_F(TextIo, RoundsToTheNearestMicrosecond) {
    const auto ev = read(
        "0.000001 1 2 1\n"         // 1e-6 * 1e6 is not exactly 1 in binary floating point
        "0.000001499 1 2 1\n"      // just below a half: down
        "0.0000015 1 2 1\n"        // a half: up
        "43.499039001 1 2 1\n"     // 9 decimals as the dataset writes them
        "43.499039999 1 2 1\n"     // 999 ns: up to the next microsecond
        "51.980787000 1 2 0\n");
    ASSERT_EQ(ev.size(), 6u);
    EXPECT_EQ(ev[0].t, 1);
    EXPECT_EQ(ev[1].t, 1);
    EXPECT_EQ(ev[2].t, 2);
    EXPECT_EQ(ev[3].t, 43'499'039);
    EXPECT_EQ(ev[4].t, 43'499'040);
    EXPECT_EQ(ev[5].t, 51'980'787);
}

TEST_F(TextIo, DigitsPastTheNinthDecimalMustBeZeros) {
    // Zeros past the 9th decimal lose nothing; any other digit there is refused above.
    const auto ev = read("0.000001500000 1 2 1\n8999999999999.999999999 1 2 1\n");
    ASSERT_EQ(ev.size(), 2u);
    EXPECT_EQ(ev[0].t, 2);
    EXPECT_EQ(ev[1].t, 9'000'000'000'000'000'000);
}

TEST_F(TextIo, ExponentNotationIsReadExactly) {
    // The decimal the notation stands for, digit by digit (1.1e-6 is not 1.1 * 1e-6 in binary).
    const auto ev = read(
        "1e-6 1 2 1\n"
        "1.5e-6 1 2 1\n"      // a half: up, as 0.0000015
        "2.5E-1 1 2 1\n"
        "4.3499039001e1 1 2 1\n"
        "0.0051980787e4 1 2 0\n"
        "+6e+1 1 2 0\n"
        "8.999999999999999999999e12 1 2 0\n");
    ASSERT_EQ(ev.size(), 7u);
    EXPECT_EQ(ev[0].t, 1);
    EXPECT_EQ(ev[1].t, 2);
    EXPECT_EQ(ev[2].t, 250'000);
    EXPECT_EQ(ev[3].t, 43'499'039);
    EXPECT_EQ(ev[4].t, 51'980'787);
    EXPECT_EQ(ev[5].t, 60'000'000);
    EXPECT_EQ(ev[6].t, 9'000'000'000'000'000'000);
}

TEST_F(TextIo, ShortDecimals) {
    const auto ev = read("1.5 3 4 0\n2 5 6 1\n2.25 7 8 1\n3. 9 10 0\n");
    ASSERT_EQ(ev.size(), 4u);
    EXPECT_EQ(ev[0], (Event{1'500'000, 3, 4, 0}));
    EXPECT_EQ(ev[1], (Event{2'000'000, 5, 6, 1}));
    EXPECT_EQ(ev[2], (Event{2'250'000, 7, 8, 1}));
    EXPECT_EQ(ev[3], (Event{3'000'000, 9, 10, 0}));
}

TEST_F(TextIo, CrlfBlankLinesCommentsTabsAndNoFinalNewline) {
    const auto ev = read(
        "# t x y p\r\n"
        "\r\n"
        "0.1 1 2 1\r\n"
        "   \t  \n"
        "  # an indented comment\n"
        "0.2\t3\t4\t0  \r\n"
        "\n"
        "0.3 5 6 1");
    ASSERT_EQ(ev.size(), 3u);
    EXPECT_EQ(ev[0], (Event{100'000, 1, 2, 1}));
    EXPECT_EQ(ev[1], (Event{200'000, 3, 4, 0}));
    EXPECT_EQ(ev[2], (Event{300'000, 5, 6, 1}));
}

TEST_F(TextIo, EqualTimestampsAreFine) {
    EXPECT_EQ(read("1 1 1 1\n1 2 2 0\n1 3 3 1\n").size(), 3u);
}

TEST_F(TextIo, MalformedLineNamesFileLineAndText) {
    const std::string msg = error_of("0.1 1 2 1\n# c\n0.2 abc 2 1\n");
    EXPECT_NE(msg.find("in.txt:3:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'0.2 abc 2 1'"), std::string::npos) << msg;
}

TEST_F(TextIo, EachKindOfError) {
    struct Case {
        std::string content;
        std::string line;
        std::string reason;
    };
    const Case cases[] = {
        {"0.1 1 2 2\n", ":1:", "polarity must be 0 or 1"},
        {"0.1 1 2 1\n0.2 1 2 -1\n", ":2:", "polarity must be 0 or 1"},
        {"0.1 1 2 1\n0.2 1 2 1.0\n", ":2:", "polarity must be 0 or 1"},
        {"0.2 1 2 1\n0.1 1 2 1\n", ":2:", "timestamp goes backwards"},
        {"0.1 1 2\n", ":1:", "polarity"},
        {"0.1 1\n", ":1:", "expected a space and y"},
        {"x 1 2 1\n", ":1:", "expected a timestamp"},
        {"0.1 1 2 1 7 8\n", ":1:", "unexpected text after the score"},
        {"0.1 1 2 1 x\n", ":1:", "unexpected text after the polarity"},
        {"0.1 1 2 1 7\n0.2 1 2 1\n", ":2:", "no score, but the first event line had one"},
        {"0.1 1 2 1\n0.2 1 2 1 7\n", ":2:", "a fifth column (a score)"},
        {"0.1 70000 2 1\n", ":1:", "x does not fit 16 bits"},
        {"1e20 1 2 1\n", ":1:", "timestamp too large (at most 9e12 seconds)"},
        {"9.5e12 1 2 1\n", ":1:", "at most 9e12 seconds"},
        {"1e-12 1 2 1\n", ":1:", "more than 9 decimals of a second"},
        {"1e 1 2 1\n", ":1:", "expected a timestamp in seconds"},
        {"1.2.3e1 1 2 1\n", ":1:", "expected a timestamp in seconds"},
        {"e5 1 2 1\n", ":1:", "expected a timestamp in seconds"},
        {"0.0000014999 1 2 1\n", ":1:", "more than 9 decimals of a second"},
        {"9000000000000 1 2 1\n", ":1:", "at most 9e12 seconds"},
        {"\n\n0.1 1 2 1 junk\n", ":3:", "unexpected text"},
    };
    for (const Case& c : cases) {
        const std::string msg = error_of(c.content);
        EXPECT_NE(msg.find(c.line), std::string::npos) << c.content << " -> " << msg;
        EXPECT_NE(msg.find(c.reason), std::string::npos) << c.content << " -> " << msg;
    }
}

io::ReaderOptions davis240(bool skip_invalid) {
    io::ReaderOptions o;
    o.sensor = kDavis240;
    o.skip_invalid = skip_invalid;
    return o;
}

TEST_F(TextIo, OutsideTheSensorIsAnErrorUnlessSkipped) {
    const std::string content = "0.1 1 2 1\n0.2 240 5 1\n0.3 3 4 0\n0.4 5 180 1\n0.5 6 7 1\n";
    const std::string msg = error_of(content, davis240(false));
    EXPECT_NE(msg.find(":2:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("x=240 y=5"), std::string::npos) << msg;
    EXPECT_NE(msg.find("240x180"), std::string::npos) << msg;

    io::TextReader r(write_file(content), davis240(true));
    std::vector<Event> out(16);
    ASSERT_EQ(r.read(out), 3u);
    EXPECT_EQ(out[0].t, 100'000);
    EXPECT_EQ(out[1].t, 300'000);
    EXPECT_EQ(out[2].t, 500'000);
    EXPECT_EQ(r.skipped(), 2u);
    const auto runs = r.skipped_in_batch();
    ASSERT_EQ(runs.size(), 2u);
    EXPECT_EQ(runs[0].before, 1u);  // between the 1st and 2nd returned events
    EXPECT_EQ(runs[0].count, 1u);
    EXPECT_EQ(runs[1].before, 2u);
    EXPECT_EQ(r.read(out), 0u);
}

TEST_F(TextIo, EventsBeforeAnErrorAreReturnedFirst) {
    io::TextReader r(write_file("0.1 1 2 1\n0.2 3 4 0\nbroken\n0.3 5 6 1\n"));
    std::vector<Event> out(16);
    ASSERT_EQ(r.read(out), 2u);
    EXPECT_EQ(out[1], (Event{200'000, 3, 4, 0}));
    try {
        r.read(out);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_EQ(e.unit(), InputError::Unit::line);
        EXPECT_EQ(e.position(), 3u);
    }
}

TEST_F(TextIo, MissingFileAndDirectory) {
    try {
        io::TextReader r((dir_ / "nope.txt").string());
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("nope.txt: cannot open"), std::string::npos) << e.what();
    }
    EXPECT_THROW(io::TextReader r(dir_.string()), InputError);
}

TEST_F(TextIo, SmallBatchesSeeEveryEventOnce) {
    std::string content;
    for (int i = 0; i < 1000; ++i) content += std::to_string(i) + ".000001 " + std::to_string(i % 200) + " 7 1\n";
    io::TextReader r(write_file(content));
    std::vector<Event> out(7);
    std::size_t total = 0, n;
    std::int64_t expect_t = 1;
    while ((n = r.read(out)) > 0) {
        for (std::size_t i = 0; i < n; ++i, expect_t += 1'000'000) EXPECT_EQ(out[i].t, expect_t);
        total += n;
    }
    EXPECT_EQ(total, 1000u);
    EXPECT_EQ(r.line(), 1000u);
}

TEST_F(TextIo, LinesAcrossBufferBoundaries) {
    // More than the reader's 1 MiB buffer, with lines of varying length.
    std::string content;
    std::mt19937 rng(5);
    std::vector<Event> expected;
    std::int64_t t = 0;
    while (content.size() < (3u << 20)) {
        t += rng() % 50;
        const Event e{t, static_cast<std::uint16_t>(rng() % 65536), static_cast<std::uint16_t>(rng() % 65536),
                      static_cast<std::uint8_t>(rng() & 1)};
        expected.push_back(e);
        char line[io::kMaxTextLine];
        content.append(line, io::format_text_line(e, line));
        if (rng() % 17 == 0) content += "# comment " + std::string(rng() % 300, 'z') + "\n";
    }
    EXPECT_EQ(read(content), expected);
}

TEST_F(TextIo, WriterRoundTripsExactly) {
    std::mt19937_64 rng(11);
    std::vector<Event> events;
    std::int64_t t = -5'000'000;  // negative times too
    for (int i = 0; i < 20000; ++i) {
        t += static_cast<std::int64_t>(rng() % 1000);
        events.push_back({t, static_cast<std::uint16_t>(rng()), static_cast<std::uint16_t>(rng()),
                          static_cast<std::uint8_t>(rng() & 1)});
    }
    events.push_back({std::int64_t{8'999'999'999'999} * 1'000'000 + 999'999, 65535, 65535, 1});
    const std::string path = (dir_ / "out.txt").string();
    {
        io::TextWriter w(path);
        w.write(events);
        w.close();
    }
    EXPECT_EQ(io::read_text_file(path), events);
}

TEST_F(TextIo, WriterFormat) {
    char line[io::kMaxTextLine];
    EXPECT_EQ(std::string(line, io::format_text_line({51'980'787, 12, 34, 1}, line)),
              "51.980787000 12 34 1\n");
    EXPECT_EQ(std::string(line, io::format_text_line({5, 0, 0, 0}, line)), "0.000005000 0 0 0\n");
    EXPECT_EQ(std::string(line, io::format_text_line({-1'500'000, 1, 2, 0}, line)), "-1.500000000 1 2 0\n");
}

}  // namespace
}  // namespace evcorner
