// AEDAT 4.0: the real DV recordings (figures from their READMEs), round trips through
// the writer (LZ4, uncompressed, ZSTD re-encoded here), and damaged files.

#include <gtest/gtest.h>
#include <zstd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "evcorner/error.hpp"
#include "evcorner/io/aedat4_reader.hpp"
#include "evcorner/io/aedat4_writer.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/open.hpp"
#include "io_test_util.hpp"
#include "test_util.hpp"

namespace evcorner::test {
namespace {

using io::Aedat4Reader;
using io::Aedat4Writer;

std::string real(const std::string& folder) { return (shared_data() / "real" / folder / "sample.aedat4").string(); }

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(Aedat4Real, DvxplorerFiguresMatchReadme) {
    EVCORNER_REQUIRE_SHARED_DATA();
    // real/tonic-testdata/README.md: sample.aedat4.
    const Figures fig{111954, 1605537493718345, 1605537494308262, 0, 319, 0, 239, 55023, 56931};
    auto reader = io::open_event_reader(real("tonic-testdata"));
    EXPECT_EQ(reader->format(), "aedat4");
    ASSERT_TRUE(reader->sensor());
    EXPECT_EQ(*reader->sensor(), (SensorSize{320, 240}));
    const ReadResult r = read_all(*reader, 1000);  // batches that split packets
    ASSERT_FALSE(r.failed) << r.error;
    expect_figures(r.events, fig, "tonic-testdata/sample.aedat4");
}

TEST(Aedat4Real, Davis346MultiStreamFiguresMatchReadme) {
    EVCORNER_REQUIRE_SHARED_DATA();
    // real/evlib-shiba/README.md: events, frames, IMU and triggers; only events are read.
    const Figures fig{6676, 1589163147368868, 1589163147538809, 14, 334, 8, 245, 3563, 3113};
    Aedat4Reader reader(real("evlib-shiba"));
    EXPECT_EQ(reader.compression(), Aedat4Reader::Compression::lz4);
    ASSERT_TRUE(reader.sensor());
    EXPECT_EQ(*reader.sensor(), (SensorSize{346, 260}));
    std::vector<std::string> types;
    for (const auto& s : reader.streams()) types.push_back(s.type);
    EXPECT_EQ(types, (std::vector<std::string>{"EVTS", "FRME", "IMUS", "TRIG"}));
    EXPECT_EQ(reader.event_stream(), 0);
    const ReadResult r = read_all(reader);
    ASSERT_FALSE(r.failed) << r.error;
    expect_figures(r.events, fig, "evlib-shiba/sample.aedat4");
    EXPECT_GT(reader.other_packets(), 0u);  // frames, IMU, triggers were skipped
}

TEST(Aedat4Real, ChoosingANonEventStreamIsAnError) {
    EVCORNER_REQUIRE_SHARED_DATA();
    EXPECT_THROW(Aedat4Reader(real("evlib-shiba"), {}, 1), InputError);   // FRME
    EXPECT_THROW(Aedat4Reader(real("evlib-shiba"), {}, 42), InputError);  // absent
}

TEST(Aedat4Real, CutFileReturnsEventsBeforeTheDamageThenNamesTheOffset) {
    EVCORNER_REQUIRE_SHARED_DATA();
    TempDir dir;
    const std::string bytes = slurp(real("tonic-testdata"));
    const std::string cut = dir.write("cut.aedat4", bytes.substr(0, bytes.size() / 2));
    Aedat4Reader reader(cut);
    const ReadResult r = read_all(reader);
    ASSERT_TRUE(r.failed);
    EXPECT_GT(r.events.size(), 10000u);
    EXPECT_LT(r.events.size(), 111954u);
    EXPECT_EQ(r.error_unit, InputError::Unit::byte);
    EXPECT_NE(r.error.find(cut), std::string::npos) << r.error;
    EXPECT_LT(r.error_position, bytes.size() / 2);
}

std::vector<Event> random_events(std::size_t n, int w, int h, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::vector<Event> ev(n);
    std::int64_t t = 1'600'000'000'000'000;
    for (auto& e : ev) {
        t += static_cast<std::int64_t>(rng() % 5);
        e = Event{t, static_cast<std::uint16_t>(rng() % static_cast<unsigned>(w)),
                  static_cast<std::uint16_t>(rng() % static_cast<unsigned>(h)), static_cast<std::uint8_t>(rng() & 1)};
    }
    return ev;
}

void write_events(const std::string& path, const std::vector<Event>& ev, Aedat4Writer::Options o) {
    Aedat4Writer w(path, o);
    // Uneven write sizes, so that packets and write() calls do not line up.
    std::size_t i = 0, step = 1;
    while (i < ev.size()) {
        const std::size_t k = std::min(step, ev.size() - i);
        w.write(std::span<const Event>(ev.data() + i, k));
        i += k;
        step = step * 3 + 1;
    }
    w.close();
}

TEST(Aedat4RoundTrip, Lz4AndUncompressedGiveBackTheEvents) {
    TempDir dir;
    const auto ev = random_events(50'000, 346, 260, 7);
    for (const auto c : {Aedat4Writer::Compression::lz4, Aedat4Writer::Compression::none}) {
        const std::string path = dir.path(c == Aedat4Writer::Compression::lz4 ? "lz4.aedat4" : "raw.aedat4");
        write_events(path, ev, {SensorSize{346, 260}, c, 3000});
        Aedat4Reader reader(path);
        EXPECT_EQ(reader.compression(),
                  c == Aedat4Writer::Compression::lz4 ? Aedat4Reader::Compression::lz4 : Aedat4Reader::Compression::none);
        ASSERT_TRUE(reader.sensor());
        EXPECT_EQ(*reader.sensor(), (SensorSize{346, 260}));
        const ReadResult r = read_all(reader, 777);
        ASSERT_FALSE(r.failed) << r.error;
        EXPECT_EQ(r.events, ev);
    }
}

TEST(Aedat4RoundTrip, WithoutASensorTheHeaderGetsTheSmallestHoldingEveryEvent) {
    TempDir dir;
    std::vector<Event> ev = random_events(1000, 100, 50, 3);
    ev[500].x = 639;
    ev[600].y = 479;
    const std::string path = dir.path("auto.aedat4");
    auto w = io::open_event_writer(path);  // by extension
    w->write(ev);
    w->close();
    auto reader = io::open_event_reader(path);
    EXPECT_EQ(reader->format(), "aedat4");
    ASSERT_TRUE(reader->sensor());
    EXPECT_EQ(*reader->sensor(), (SensorSize{640, 480}));
    const ReadResult r = read_all(*reader);
    ASSERT_FALSE(r.failed) << r.error;
    EXPECT_EQ(r.events, ev);
}

TEST(Aedat4RoundTrip, EmptyStream) {
    TempDir dir;
    const std::string path = dir.path("empty.aedat4");
    write_events(path, {}, {SensorSize{32, 32}, Aedat4Writer::Compression::lz4, 100});
    Aedat4Reader reader(path);
    const ReadResult r = read_all(reader);
    EXPECT_FALSE(r.failed) << r.error;
    EXPECT_TRUE(r.events.empty());
}

// Rewrites an uncompressed file from the writer with every packet ZSTD-compressed.
std::string zstd_reencode(const std::string& raw) {
    std::string out = raw.substr(0, 14);
    const std::uint32_t hsize = static_cast<unsigned char>(raw[14]) | static_cast<unsigned char>(raw[15]) << 8 |
                                static_cast<unsigned char>(raw[16]) << 16 |
                                static_cast<std::uint32_t>(static_cast<unsigned char>(raw[17])) << 24;
    std::string header = raw.substr(14, 4 + hsize);
    header[40] = 3;  // compression field (writer's layout): ZSTD
    out += header;
    std::size_t pos = 14 + 4 + hsize;
    while (pos < raw.size()) {
        std::uint32_t size = 0;
        for (int k = 0; k < 4; ++k) size |= std::uint32_t{static_cast<unsigned char>(raw[pos + 4 + k])} << (8 * k);
        const std::string packet = raw.substr(pos + 8, size);
        std::string z(ZSTD_compressBound(packet.size()), '\0');
        const std::size_t zn = ZSTD_compress(z.data(), z.size(), packet.data(), packet.size(), 3);
        EXPECT_FALSE(ZSTD_isError(zn));
        z.resize(zn);
        out += raw.substr(pos, 4);
        put_le32(out, static_cast<std::uint32_t>(zn));
        out += z;
        pos += 8 + size;
    }
    return out;
}

TEST(Aedat4RoundTrip, ZstdPackets) {
    TempDir dir;
    const auto ev = random_events(20'000, 640, 480, 11);
    const std::string raw = dir.path("raw.aedat4");
    write_events(raw, ev, {SensorSize{640, 480}, Aedat4Writer::Compression::none, 4096});
    const std::string z = dir.write("zstd.aedat4", zstd_reencode(slurp(raw)));
    Aedat4Reader reader(z);
    EXPECT_EQ(reader.compression(), Aedat4Reader::Compression::zstd);
    const ReadResult r = read_all(reader);
    ASSERT_FALSE(r.failed) << r.error;
    EXPECT_EQ(r.events, ev);
}

TEST(Aedat4Writer, RejectsCoordinatesBeyondInt16AndOutsideTheSensor) {
    TempDir dir;
    Aedat4Writer w(dir.path("a.aedat4"));
    const Event far{1, 40000, 3, 1};
    EXPECT_THROW(w.write(std::span<const Event>(&far, 1)), OutputError);
    Aedat4Writer s(dir.path("b.aedat4"), {SensorSize{10, 10}, Aedat4Writer::Compression::lz4, 16});
    const Event out{1, 10, 3, 1};
    EXPECT_THROW(s.write(std::span<const Event>(&out, 1)), OutputError);
}

TEST(Aedat4Reader, EventsOutsideAGivenSensorFailOrAreSkipped) {
    TempDir dir;
    const std::vector<Event> ev = {{10, 1, 1, 1}, {11, 50, 1, 0}, {12, 2, 2, 1}};
    const std::string path = dir.path("x.aedat4");
    write_events(path, ev, {SensorSize{64, 64}, Aedat4Writer::Compression::lz4, 2});
    io::ReaderOptions o;
    o.sensor = SensorSize{20, 20};
    {
        Aedat4Reader reader(path, o);
        const ReadResult r = read_all(reader);
        EXPECT_TRUE(r.failed);
        EXPECT_EQ(r.events.size(), 1u);
        EXPECT_NE(r.error.find("outside the 20x20 sensor"), std::string::npos) << r.error;
    }
    o.skip_invalid = true;
    Aedat4Reader reader(path, o);
    const ReadResult r = read_all(reader);
    EXPECT_FALSE(r.failed) << r.error;
    EXPECT_EQ(r.events, (std::vector<Event>{ev[0], ev[2]}));
    EXPECT_EQ(r.skipped, 1u);
}

// A valid uncompressed file of three events, for the damage tests.
std::string small_file(const TempDir& dir) {
    const std::string path = dir.path("small.aedat4");
    write_events(path, {{10, 1, 1, 1}, {11, 2, 1, 0}, {12, 3, 2, 1}},
                 {SensorSize{64, 64}, Aedat4Writer::Compression::none, 2});
    return slurp(path);
}

std::size_t first_packet(const std::string& f) {
    return 14 + 4 + (static_cast<unsigned char>(f[14]) | static_cast<unsigned char>(f[15]) << 8);
}

TEST(Aedat4Damage, BadMagicAndHeader) {
    TempDir dir;
    std::string f = small_file(dir);
    std::string bad = f;
    bad[10] = '5';
    EXPECT_THROW(Aedat4Reader(dir.write("m.aedat4", bad)), InputError);
    bad = f;
    bad[14 + 8] = 'X';  // identifier IOHE
    EXPECT_THROW(Aedat4Reader(dir.write("i.aedat4", bad)), InputError);
    bad = f;
    bad[14 + 40] = 9;  // compression 9
    try {
        Aedat4Reader r(dir.write("c.aedat4", bad));
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("compression type 9"), std::string::npos) << e.what();
        EXPECT_EQ(e.position(), 14u);
    }
    bad = f;
    bad[14 + 4 + 3] = 0x7F;  // root offset far outside
    EXPECT_THROW(Aedat4Reader(dir.write("r.aedat4", bad)), InputError);
    bad = f.substr(0, 30);
    EXPECT_THROW(Aedat4Reader(dir.write("t.aedat4", bad)), InputError);
}

TEST(Aedat4Damage, PacketSizeAndVectorLengthAreChecked) {
    TempDir dir;
    const std::string f = small_file(dir);
    const std::size_t p = first_packet(f);
    std::string bad = f;
    bad[p + 7] = static_cast<char>(0x80);  // size negative
    {
        Aedat4Reader r(dir.write("s.aedat4", bad));
        const ReadResult res = read_all(r);
        EXPECT_TRUE(res.failed);
        EXPECT_EQ(res.error_position, p + 4);
    }
    bad = f;
    bad[p + 8 + 28 + 2] = 0x7F;  // event count of the first packet: huge
    {
        Aedat4Reader r(dir.write("v.aedat4", bad));
        const ReadResult res = read_all(r);
        EXPECT_TRUE(res.failed);
        EXPECT_EQ(res.error_position, p);
        EXPECT_NE(res.error.find("vector"), std::string::npos) << res.error;
    }
    bad = f;
    bad[p + 8 + 8] = 'X';  // identifier EVTS
    {
        Aedat4Reader r(dir.write("e.aedat4", bad));
        EXPECT_TRUE(read_all(r).failed);
    }
    // The second packet damaged: the first packet's two events come first.
    bad = f;
    const std::size_t p2 = p + 8 + 32 + 2 * 16;
    bad[p2 + 8 + 4] = static_cast<char>(0xFF);
    {
        Aedat4Reader r(dir.write("2.aedat4", bad));
        const ReadResult res = read_all(r);
        EXPECT_TRUE(res.failed);
        EXPECT_EQ(res.events.size(), 2u);
        EXPECT_EQ(res.error_position, p2);
    }
}

TEST(Aedat4Damage, CorruptLz4DataIsAnErrorNotACrash) {
    TempDir dir;
    const std::string path = dir.path("l.aedat4");
    write_events(path, random_events(5000, 64, 64, 5), {SensorSize{64, 64}, Aedat4Writer::Compression::lz4, 1000});
    std::string f = slurp(path);
    const std::size_t p = first_packet(f);
    for (std::size_t i = p + 8 + 12; i < p + 8 + 200; ++i) f[i] = static_cast<char>(f[i] ^ 0x5A);
    Aedat4Reader r(dir.write("bad.aedat4", f));
    const ReadResult res = read_all(r);
    EXPECT_TRUE(res.failed);
    EXPECT_TRUE(res.events.empty());
    EXPECT_EQ(res.error_position, p);
}

}  // namespace
}  // namespace evcorner::test
