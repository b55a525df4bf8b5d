// CSV reader: column orders (option and header row), time units, detection, errors.

#include <gtest/gtest.h>

#include <fmt/format.h>

#include "evcorner/io/csv_reader.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/text_reader.hpp"
#include "io_test_util.hpp"
#include "test_util.hpp"

namespace evcorner::test {
namespace {

const std::vector<Event> kThree = {{5, 1, 2, 1}, {7, 239, 179, 0}, {7, 0, 0, 1}};

TEST(CsvReader, DefaultOrderAndDetection) {
    TempDir tmp;
    const auto path = tmp.write("a.csv", "# comment\n5,1,2,1\n7, 239 ,179,0\r\n\n7,0,0,1");
    auto reader = io::open_event_reader(path);
    EXPECT_EQ(reader->format(), "csv");
    const ReadResult r = read_all(*reader);
    ASSERT_FALSE(r.failed) << r.error;
    EXPECT_EQ(r.events, kThree);
}

TEST(CsvReader, HeaderRowNamesTheOrder) {
    TempDir tmp;
    const auto path = tmp.write("h.csv", "x,y,polarity,timestamp\n1,2,1,5\n239,179,-1,7\n0,0,1,7\n");
    auto reader = io::open_event_reader(path);
    const ReadResult r = read_all(*reader);
    ASSERT_FALSE(r.failed) << r.error;
    EXPECT_EQ(r.events, kThree);
}

TEST(CsvReader, OptionOrderWithIgnoredColumnAndSeconds) {
    TempDir tmp;
    const auto path = tmp.write("o.csv", "1,2,1,0.0000049,9\n239,179,0,0.000007,9\n0,0,1,0.0000074,9\n");
    io::ReaderOptions o;
    o.csv_columns = "x,y,p,t,_";
    o.csv_time_unit = "s";
    io::CsvReader reader(path, o);
    const ReadResult r = read_all(reader);
    ASSERT_FALSE(r.failed) << r.error;
    EXPECT_EQ(r.events, kThree);
}

TEST(CsvReader, NanosecondsRoundToMicroseconds) {
    TempDir tmp;
    const auto path = tmp.write("n.csv", "4500,1,2,1\n7499,239,179,0\n");
    io::ReaderOptions o;
    o.csv_time_unit = "ns";
    io::CsvReader reader(path, o);
    const ReadResult r = read_all(reader);
    ASSERT_FALSE(r.failed) << r.error;
    ASSERT_EQ(r.events.size(), 2u);
    EXPECT_EQ(r.events[0].t, 5);
    EXPECT_EQ(r.events[1].t, 7);
}

// The float-time rule: without --time-unit the first time decides (a decimal point:
// seconds; none: microseconds); with one, every time is in it.
TEST(CsvReader, FloatTimesAreSecondsUnlessTheUnitIsGiven) {
    TempDir tmp;
    const auto read_t = [&](const std::string& text, const std::string& unit) {
        io::ReaderOptions o;
        o.csv_time_unit = unit;
        io::CsvReader reader(tmp.write("f.csv", text), o);
        const ReadResult r = read_all(reader);
        EXPECT_FALSE(r.failed) << text << " -> " << r.error;
        std::vector<std::int64_t> t;
        for (const Event& e : r.events) t.push_back(e.t);
        return t;
    };
    using T = std::vector<std::int64_t>;
    EXPECT_EQ(read_t("0.1,10,10,1\n0.25,10,10,1\n1,10,10,0\n", ""), (T{100'000, 250'000, 1'000'000}));
    EXPECT_EQ(read_t("0.1 , 10,10,1\n", ""), (T{100'000}));  // as the same line with spaces
    EXPECT_EQ(read_t("100,10,10,1\n250,10,10,1\n", ""), (T{100, 250}));
    EXPECT_EQ(read_t("0.000001499,1,1,1\n0.0000015,1,1,1\n", ""), (T{1, 2}));  // nearest us
    EXPECT_EQ(read_t("100,10,10,1\n", "s"), (T{100'000'000}));
    EXPECT_EQ(read_t("1.5,10,10,1\n2.0015,10,10,1\n", "ms"), (T{1500, 2002}));
    EXPECT_EQ(read_t("1499,10,10,1\n1500,10,10,1\n", "ns"), (T{1, 2}));
}

TEST(CsvReader, TimesTheRuleCannotReadAreErrors) {
    TempDir tmp;
    struct Case {
        std::string text, unit;
        std::uint64_t line;
        std::string says;
    };
    const Case cases[] = {
        {"100,1,1,1\n100.5,1,1,1\n", "", 2, "whose first time was an integer"},
        {"0.1,1,1,1\n", "us", 1, "--time-unit is us"},
        {"0.5,1,1,1\n", "us", 1, "--time-unit is us"},
        {"1,1,1,1\n1.0000000001,1,1,1\n", "s", 2, "more than 9 decimals of a second"},
        {"0.1,1,1,1\n0.2000000000001,1,1,1\n", "", 2, "more than 9 decimals of a second"},
        {"1,1,1,1\n2.5,1,1,1\n", "ns", 2, "fraction of a nanosecond"},
        {"1,1,1,1\n1e20,1,1,1\n", "s", 2, "at most 9e12 seconds"},
        {"1,1,1,1\n2e-3,1,1,1\n", "", 2, "whose first time was an integer"},  // exponent notation: a float
        {"1,1,1,1\n9000000000000,1,1,1\n", "s", 2, "at most 9e12 seconds"},
    };
    for (const Case& c : cases) {
        io::ReaderOptions o;
        o.csv_time_unit = c.unit;
        const auto path = tmp.write("e.csv", c.text);
        io::CsvReader reader(path, o);
        const ReadResult r = read_all(reader);
        ASSERT_TRUE(r.failed) << c.text;
        EXPECT_EQ(r.events.size(), c.line - 1) << c.text;
        EXPECT_NE(r.error.find(path + ":" + std::to_string(c.line) + ": "), std::string::npos) << r.error;
        EXPECT_NE(r.error.find(c.says), std::string::npos) << c.text << " -> " << r.error;
    }
}

TEST(CsvReader, ErrorsNameTheLineAndKeepEventsBefore) {
    TempDir tmp;
    struct Case {
        std::string text;
        std::uint64_t line;
        std::string says;
    };
    const Case cases[] = {
        {"1,1,1,1\n2,1,1\n", 2, "fewer columns"},
        {"1,1,1,1\n2,1,1,1,1\n", 2, "more columns"},
        {"1,1,1,1\n2,1,1,5\n", 2, "polarity"},
        {"1,1,1,1\n2,x,1,1\n", 2, "x is not"},
        {"1,1,1,1\n0,1,1,1\n", 2, "backwards"},
        {"1,1,1,1\n2,300,1,1\n", 2, "outside the 240x180"},
        {"1,1,1,1\nt,x,y,p\n", 2, "text where an event"},
    };
    for (const Case& c : cases) {
        const auto path = tmp.write("e.csv", c.text);
        io::CsvReader reader(path);
        const ReadResult r = read_all(reader);
        EXPECT_EQ(r.events.size(), 1u) << c.text;
        ASSERT_TRUE(r.failed) << c.text;
        EXPECT_EQ(r.error_unit, InputError::Unit::line);
        EXPECT_EQ(r.error_position, c.line) << r.error;
        EXPECT_NE(r.error.find(path + ":" + std::to_string(c.line) + ": "), std::string::npos) << r.error;
        EXPECT_NE(r.error.find(c.says), std::string::npos) << r.error;
    }
}

TEST(CsvReader, BadOptionsAreErrors) {
    TempDir tmp;
    const auto path = tmp.write("b.csv", "1,1,1,1\n");
    io::ReaderOptions o;
    o.csv_columns = "t,x,y";
    EXPECT_THROW(io::CsvReader(path, o), InputError);
    o.csv_columns = "t,x,y,y";
    EXPECT_THROW(io::CsvReader(path, o), InputError);
    o.csv_columns = "t,x,y,q";
    EXPECT_THROW(io::CsvReader(path, o), InputError);
    o.csv_columns.clear();
    o.csv_time_unit = "min";
    EXPECT_THROW(io::CsvReader(path, o), InputError);
}

// The real ECD text, rewritten here as "x,y,p,t" microsecond CSV, reads back the same.
TEST(CsvReader, RealEcdCutAsCsvMatchesTextReader) {
    EVCORNER_REQUIRE_SHARED_DATA();
    const auto text = ecd_text_files().back().events.string();
    const auto events = io::read_text_file(text);
    ASSERT_EQ(events.size(), 50000u);  // data README: the first 50 000 events of slider_depth
    std::string csv = "x,y,p,t\n";
    for (const Event& e : events) csv += fmt::format("{},{},{},{}\n", e.x, e.y, int(e.p), e.t);
    TempDir tmp;
    auto reader = io::open_event_reader(tmp.write("s.csv", csv));
    const ReadResult r = read_all(*reader, 777);
    ASSERT_FALSE(r.failed) << r.error;
    EXPECT_EQ(r.events, events);
}

}  // namespace
}  // namespace evcorner::test
