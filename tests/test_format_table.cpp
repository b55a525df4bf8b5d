// The input-format table (io/formats.hpp): the one list that open_event_reader(), the
// format names, the extensions and the reader options come from.

#include <gtest/gtest.h>

#include <set>
#include <stdexcept>

#include "evcorner/io/formats.hpp"
#include "evcorner/io/open.hpp"
#include "io_test_util.hpp"
#include "test_util.hpp"

namespace evcorner::test {
namespace {

TEST(FormatTable, NamesAliasesAndTheFormatList) {
    std::set<std::string_view> seen;
    std::string names;
    for (const io::InputFormat& f : io::input_formats()) {
        names += (names.empty() ? "" : ", ") + std::string(f.name);
        EXPECT_TRUE(seen.insert(f.name).second) << f.name;
        EXPECT_EQ(io::find_input_format(f.name), &f);
        EXPECT_FALSE(f.title.empty()) << f.name;
        EXPECT_FALSE(f.extensions.empty()) << f.name;
        EXPECT_NE(f.open, nullptr) << f.name;
    }
    EXPECT_EQ(names, io::input_format_names());
    EXPECT_EQ(seen.size(), 14u);  // ecd-text csv npy aedat2 aedat4 evt2 evt3 dat hdf5 atis-bin mat rosbag2 mcap rosbag
    EXPECT_EQ(io::find_input_format("text")->name, "ecd-text");
    EXPECT_EQ(io::find_input_format("aedat")->name, "aedat2");
    EXPECT_EQ(io::find_input_format("h5")->name, "hdf5");
    EXPECT_EQ(io::find_input_format("auto"), nullptr);
    EXPECT_EQ(io::find_input_format("ecd"), nullptr);
}

TEST(FormatTable, EveryExtensionIsListedOnce) {
    const auto listed = io::input_file_extensions();
    const std::set<std::string_view> unique(listed.begin(), listed.end());
    EXPECT_EQ(unique.size(), listed.size());
    for (const io::InputFormat& f : io::input_formats()) {
        std::string_view e = f.extensions;
        while (!e.empty()) {
            const auto sp = e.find(' ');
            EXPECT_TRUE(unique.count(e.substr(0, sp))) << f.name << " " << e.substr(0, sp);
            e.remove_prefix(sp == std::string_view::npos ? e.size() : sp + 1);
        }
    }
}

// A file that starts with a format's magic is told as that format.
TEST(FormatTable, MagicsTellTheFormat) {
    TempDir tmp;
    int with_magic = 0;
    for (const io::InputFormat& f : io::input_formats())
        for (const std::string_view m : f.magic) {
            if (m.empty()) continue;
            ++with_magic;
            const std::string path = tmp.write("m.bin", std::string(m) + std::string(200, '\0'));
            EXPECT_EQ(io::detect_format(path), f.name) << f.name;
        }
    EXPECT_GE(with_magic, 8);
}

TEST(FormatTable, AnOptionTheFormatDoesNotTakeIsRefused) {
    TempDir tmp;
    const std::string csv = tmp.write("a.csv", "1,2,3,1\n");
    io::ReaderOptions o;
    o.aedat2_chip = "DVS128";
    try {
        io::open_event_reader(csv, o);
        ADD_FAILURE() << "--chip accepted on a CSV file";
    } catch (const std::invalid_argument& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find(csv), std::string::npos) << m;
        EXPECT_NE(m.find("--chip applies to aedat2 files; this file is csv"), std::string::npos) << m;
    }
    o = {};
    o.topic = "/events";
    EXPECT_THROW(io::open_event_reader(csv, o), std::invalid_argument);
    o = {};
    o.mat_columns = "x,y,p,t";
    EXPECT_THROW(io::open_event_reader(csv, o), std::invalid_argument);
    // The time unit is shared by mixed folders: never refused for that reason.
    o = {};
    o.csv_time_unit = "us";
    const std::string txt = tmp.write("a.txt", "0.1 1 2 1\n");
    EXPECT_NO_THROW(io::open_event_reader(txt, o));
}

TEST(FormatTable, ReaderOptionsSetAndGetTheirField) {
    std::set<std::string_view> flags, keywords;
    for (const io::ReaderOptionInfo& r : io::reader_option_infos()) {
        EXPECT_TRUE(flags.insert(r.flag).second) << r.flag;
        EXPECT_TRUE(keywords.insert(r.keyword).second) << r.keyword;
        EXPECT_EQ(r.flag.substr(0, 2), "--");
        io::ReaderOptions o;
        EXPECT_EQ(r.get(o), "");
        r.set(o, "v1");
        EXPECT_EQ(r.get(o), "v1");
        // Exactly one option is set now.
        int set = 0;
        for (const io::ReaderOptionInfo& q : io::reader_option_infos()) set += !q.get(o).empty();
        EXPECT_EQ(set, 1) << r.flag;
        int takers = 0;
        for (const io::InputFormat& f : io::input_formats()) takers += (f.options & r.bit) != 0;
        EXPECT_GE(takers, 1) << r.flag;
    }
}

}  // namespace
}  // namespace evcorner::test
