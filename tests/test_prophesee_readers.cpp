// Prophesee readers (RAW EVT 2.0, RAW EVT 3.0, DAT): the real recordings (figures from
// their READMEs) and crafted damaged files.

#include <gtest/gtest.h>

#include "evcorner/io/dat_reader.hpp"
#include "evcorner/io/evt2_reader.hpp"
#include "evcorner/io/evt3_reader.hpp"
#include "evcorner/io/open.hpp"
#include "io_test_util.hpp"
#include "test_util.hpp"

namespace evcorner::test {
namespace {

struct RealFile {
    const char* path;  // under data/real
    const char* format;
    SensorSize sensor;
    Figures fig;
};

// data/real/expelliarmus, faery-testdata and tonic-testdata READMEs.
const RealFile kRealFiles[] = {
    {"expelliarmus/evt2_sample.raw", "evt2", {640, 480},
     {539481, 1317888, 1367888, 60, 599, 18, 475, 367855, 171626}},
    {"expelliarmus/evt3_sample.raw", "evt3", {1280, 720},
     {219596, 11718656, 11727457, 0, 1279, 0, 719, 115532, 104064}},
    {"faery-testdata/evt2.raw", "evt2", {640, 480},
     {521252, 913716224, 913812095, 0, 639, 0, 479, 185861, 335391}},
    // No geometry in the header: the fallback sensor (240x180 unless set) holds its 78x42 crops.
    {"tonic-testdata/sample_ncars.dat", "dat", {240, 180}, {2009, 0, 99952, 0, 77, 0, 41, 1350, 659}},
};

TEST(PropheseeReal, FiguresMatchReadme) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const RealFile& f : kRealFiles) {
        const auto path = (shared_data() / "real" / f.path).string();
        auto reader = io::open_event_reader(path);
        EXPECT_EQ(reader->format(), f.format) << f.path;
        ASSERT_TRUE(reader->sensor()) << f.path;
        EXPECT_EQ(*reader->sensor(), f.sensor) << f.path;
        const ReadResult r = read_all(*reader);
        ASSERT_FALSE(r.failed) << r.error;
        expect_figures(r.events, f.fig, f.path);
    }
}

TEST(PropheseeReal, BatchSizeDoesNotChangeTheEvents) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const RealFile& f : kRealFiles) {
        const auto path = (shared_data() / "real" / f.path).string();
        auto big = io::open_event_reader(path);
        const ReadResult a = read_all(*big, 1 << 16);
        for (std::size_t batch : {1u, 5u, 11u}) {
            auto small = io::open_event_reader(path);
            const ReadResult b = read_all(*small, batch);
            ASSERT_FALSE(b.failed) << b.error;
            EXPECT_EQ(a.events, b.events) << f.path << " batch " << batch;
        }
    }
}

TEST(PropheseeReal, FormatOverrideAndGeometryOverride) {
    EVCORNER_REQUIRE_SHARED_DATA();
    const auto path = (shared_data() / "real/expelliarmus/evt3_sample.raw").string();
    io::ReaderOptions o;
    o.sensor = SensorSize{640, 480};
    auto reader = io::open_event_reader(path, o, "evt3");
    const ReadResult r = read_all(*reader);
    ASSERT_TRUE(r.failed);  // x reaches 1279
    EXPECT_NE(r.error.find("outside the 640x480 sensor"), std::string::npos) << r.error;
    EXPECT_THROW(io::open_event_reader(path, {}, "evt2"), InputError);  // header says EVT 3.0
}

// ---- EVT 2.0 crafted

const std::string kEvt2Header = "% evt 2.0\n% format EVT2;height=480;width=640\n% end\n";

std::uint32_t cd(bool on, int t_lsb, int x, int y) {
    return std::uint32_t(on) << 28 | std::uint32_t(t_lsb) << 22 | std::uint32_t(x) << 11 | std::uint32_t(y);
}
std::uint32_t th2(std::uint32_t high) { return 0x8000'0000u | high; }

TEST(Evt2Crafted, DecodesAndSkipsUnknownWords) {
    TempDir tmp;
    std::string f = kEvt2Header;
    put_le32(f, th2(10));
    put_le32(f, cd(true, 5, 639, 479));
    put_le32(f, 0xA000'0001u);  // external trigger
    put_le32(f, 0x5123'4567u);  // unknown type 5
    put_le32(f, 0xE000'0000u);  // OTHERS
    put_le32(f, cd(false, 63, 1, 2));
    const auto path = tmp.write("a.raw", f);
    io::Evt2Reader reader(path);
    EXPECT_EQ(*reader.sensor(), (SensorSize{640, 480}));
    const ReadResult r = read_all(reader);
    ASSERT_FALSE(r.failed) << r.error;
    const std::vector<Event> want = {{10 * 64 + 5, 639, 479, 1}, {10 * 64 + 63, 1, 2, 0}};
    EXPECT_EQ(r.events, want);
    EXPECT_EQ(reader.other_words(), 3u);
}

TEST(Evt2Crafted, TimeHighWrapIsUnrolled) {
    TempDir tmp;
    std::string f = kEvt2Header;
    put_le32(f, th2(0x0FFF'FFFFu));
    put_le32(f, cd(true, 1, 1, 1));
    put_le32(f, th2(0));
    put_le32(f, cd(true, 2, 1, 1));
    const auto path = tmp.write("w.raw", f);
    io::Evt2Reader reader(path);
    const ReadResult r = read_all(reader);
    ASSERT_FALSE(r.failed) << r.error;
    ASSERT_EQ(r.events.size(), 2u);
    EXPECT_EQ(r.events[0].t, (std::int64_t{0x0FFF'FFFF} << 6) | 1);
    EXPECT_EQ(r.events[1].t, (std::int64_t{1} << 34) | 2);
}

TEST(Evt2Crafted, TruncatedAndCorruptWordsNameTheOffset) {
    TempDir tmp;
    const std::uint64_t h = kEvt2Header.size();
    {
        std::string f = kEvt2Header;
        put_le32(f, th2(1));
        put_le32(f, cd(true, 0, 3, 3));
        f += std::string("\x01\x02", 2);
        const auto path = tmp.write("t.raw", f);
        io::Evt2Reader reader(path);
        const ReadResult r = read_all(reader);
        EXPECT_EQ(r.events.size(), 1u);
        ASSERT_TRUE(r.failed);
        EXPECT_EQ(r.error_position, h + 8);
        EXPECT_NE(r.error.find(path + ": byte " + std::to_string(h + 8)), std::string::npos) << r.error;
    }
    {
        std::string f = kEvt2Header;
        put_le32(f, cd(true, 0, 3, 3));  // no time yet
        const auto path = tmp.write("c.raw", f);
        io::Evt2Reader reader(path);
        const ReadResult r = read_all(reader);
        ASSERT_TRUE(r.failed);
        EXPECT_EQ(r.error_position, h);
        EXPECT_NE(r.error.find("EV_TIME_HIGH"), std::string::npos) << r.error;
    }
    {
        std::string f = kEvt2Header;
        put_le32(f, th2(1));
        put_le32(f, cd(true, 0, 3, 3));
        put_le32(f, cd(true, 0, 2000, 3));  // outside 640x480
        const auto path = tmp.write("o.raw", f);
        io::Evt2Reader reader(path);
        const ReadResult r = read_all(reader);
        EXPECT_EQ(r.events.size(), 1u);
        ASSERT_TRUE(r.failed);
        EXPECT_EQ(r.error_position, h + 8);
    }
}

// ---- EVT 3.0 crafted

const std::string kEvt3Header = "% evt 3.0\n% geometry 1280x720\n% end\n";

std::uint16_t w3(int type, int payload) { return static_cast<std::uint16_t>(type << 12 | payload); }

TEST(Evt3Crafted, DecodesSingleAndVectorEvents) {
    TempDir tmp;
    std::string f = kEvt3Header;
    for (std::uint16_t w : {w3(0x8, 0x001), w3(0x6, 0x010),  // t = 4096 + 16
                            w3(0x0, 7),                       // y = 7
                            w3(0x2, 0x800 | 100),             // ON event at x = 100
                            w3(0xA, 0x123),                   // trigger: skipped
                            w3(0x3, 200),                     // base x = 200, OFF
                            w3(0x4, 0x801),                   // bits 0 and 11: x = 200, 211
                            w3(0x5, 0x03),                    // bits 0, 1: x = 212, 213
                            w3(0x8, 0x001),                   // repeated TIME_HIGH: no change
                            w3(0x1, 0x555),                   // unknown type 1: skipped
                            w3(0x2, 5)})
        put_le16(f, w);
    const auto path = tmp.write("v.raw", f);
    for (std::size_t batch : {1u, 2u, 3u, 64u}) {
        io::Evt3Reader reader(path);
        EXPECT_EQ(*reader.sensor(), (SensorSize{1280, 720}));
        const ReadResult r = read_all(reader, batch);
        ASSERT_FALSE(r.failed) << r.error;
        const std::int64_t t = 4096 + 16;
        const std::vector<Event> want = {{t, 100, 7, 1}, {t, 200, 7, 0}, {t, 211, 7, 0},
                                         {t, 212, 7, 0}, {t, 213, 7, 0}, {t, 5, 7, 0}};
        EXPECT_EQ(r.events, want) << "batch " << batch;
        EXPECT_EQ(reader.other_words(), 2u);
    }
}

TEST(Evt3Crafted, TimeWrapIsUnrolled) {
    TempDir tmp;
    std::string f = kEvt3Header;
    for (std::uint16_t w : {w3(0x0, 1), w3(0x8, 0xFFF), w3(0x6, 0xFFE), w3(0x2, 1),
                            w3(0x8, 0x000), w3(0x6, 0x003), w3(0x2, 2)})
        put_le16(f, w);
    const auto path = tmp.write("w.raw", f);
    io::Evt3Reader reader(path);
    const ReadResult r = read_all(reader);
    ASSERT_FALSE(r.failed) << r.error;
    ASSERT_EQ(r.events.size(), 2u);
    EXPECT_EQ(r.events[0].t, 0xFFFFFE);
    EXPECT_EQ(r.events[1].t, (1 << 24) + 3);
}

TEST(Evt3Crafted, TruncatedAndCorruptWordsNameTheOffset) {
    TempDir tmp;
    const std::uint64_t h = kEvt3Header.size();
    {
        std::string f = kEvt3Header;
        for (std::uint16_t w : {w3(0x8, 1), w3(0x0, 1), w3(0x2, 1)}) put_le16(f, w);
        f.push_back('\x42');
        const auto path = tmp.write("t.raw", f);
        io::Evt3Reader reader(path);
        const ReadResult r = read_all(reader);
        EXPECT_EQ(r.events.size(), 1u);
        ASSERT_TRUE(r.failed);
        EXPECT_EQ(r.error_position, h + 6);
        EXPECT_NE(r.error.find(path + ": byte " + std::to_string(h + 6)), std::string::npos) << r.error;
    }
    {
        std::string f = kEvt3Header;
        for (std::uint16_t w : {w3(0x8, 1), w3(0x0, 1), w3(0x2, 1), w3(0x4, 1)}) put_le16(f, w);  // no base x
        const auto path = tmp.write("c.raw", f);
        io::Evt3Reader reader(path);
        const ReadResult r = read_all(reader);
        EXPECT_EQ(r.events.size(), 1u);
        ASSERT_TRUE(r.failed);
        EXPECT_EQ(r.error_position, h + 6);
        EXPECT_NE(r.error.find("VECT_BASE_X"), std::string::npos) << r.error;
    }
    {
        std::string f = kEvt3Header;
        for (std::uint16_t w : {w3(0x0, 1), w3(0x2, 1)}) put_le16(f, w);  // no time
        const auto path = tmp.write("n.raw", f);
        io::Evt3Reader reader(path);
        const ReadResult r = read_all(reader);
        ASSERT_TRUE(r.failed);
        EXPECT_EQ(r.error_position, h + 2);
    }
    {
        std::string f = kEvt3Header;  // a vector running past the 1280-wide sensor
        for (std::uint16_t w : {w3(0x8, 1), w3(0x0, 1), w3(0x3, 1275), w3(0x4, 0x0C1)}) put_le16(f, w);
        const auto path = tmp.write("o.raw", f);
        io::Evt3Reader reader(path);
        const ReadResult r = read_all(reader);
        EXPECT_EQ(r.events.size(), 1u);  // x = 1275; 1281 is outside
        ASSERT_TRUE(r.failed);
        EXPECT_EQ(r.error_position, h + 6);
        EXPECT_NE(r.error.find("x=1281"), std::string::npos) << r.error;
    }
}

// ---- DAT crafted

const std::string kDatHeader = "% Data file containing Event2d events.\n% Version 2\n% Width 304\n% Height 240\n";

void dat_record(std::string& f, std::uint32_t t, int x, int y, int p) {
    put_le32(f, t);
    put_le32(f, std::uint32_t(p) << 28 | std::uint32_t(y) << 14 | std::uint32_t(x));
}

TEST(DatCrafted, DecodesWrapsAndNamesOffsets) {
    TempDir tmp;
    const std::string h = kDatHeader + std::string("\x00\x08", 2);
    {
        std::string f = h;
        dat_record(f, 0xFFFF'FFF0u, 303, 239, 1);
        dat_record(f, 0x0000'0002u, 0, 0, 0);
        const auto path = tmp.write("a.dat", f);
        auto reader = io::open_event_reader(path);
        EXPECT_EQ(reader->format(), "dat");
        EXPECT_EQ(*reader->sensor(), (SensorSize{304, 240}));
        const ReadResult r = read_all(*reader);
        ASSERT_FALSE(r.failed) << r.error;
        const std::vector<Event> want = {{0xFFFF'FFF0LL, 303, 239, 1}, {(1LL << 32) + 2, 0, 0, 0}};
        EXPECT_EQ(r.events, want);
    }
    {
        std::string f = h;
        dat_record(f, 1, 1, 1, 1);
        dat_record(f, 2, 1, 1, 7);  // polarity 7
        const auto path = tmp.write("p.dat", f);
        io::DatReader reader(path);
        const ReadResult r = read_all(reader);
        EXPECT_EQ(r.events.size(), 1u);
        ASSERT_TRUE(r.failed);
        EXPECT_EQ(r.error_position, h.size() + 8);
        EXPECT_NE(r.error.find(path + ": byte " + std::to_string(h.size() + 8)), std::string::npos) << r.error;
    }
    {
        std::string f = h;
        dat_record(f, 1, 1, 1, 1);
        f += "abc";
        const auto path = tmp.write("t.dat", f);
        io::DatReader reader(path);
        const ReadResult r = read_all(reader);
        EXPECT_EQ(r.events.size(), 1u);
        ASSERT_TRUE(r.failed);
        EXPECT_EQ(r.error_position, h.size() + 8);
    }
    {
        std::string f = kDatHeader + std::string("\x00\x10", 2);  // 16-byte records: not Event2d
        dat_record(f, 1, 1, 1, 1);
        EXPECT_THROW(io::DatReader(tmp.write("s.dat", f)), InputError);
    }
}

TEST(PropheseeDetect, HeaderWithoutEncodingIsAClearError) {
    TempDir tmp;
    const auto path = tmp.write("x.raw", "% Date 2020\n% plugin_name foo\nabcd");
    try {
        io::open_event_reader(path);
        ADD_FAILURE() << "expected an error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--format"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace evcorner::test
