// Writers (text, CSV, npy): every writer round-trips real recordings through the
// matching reader to the identical events; the npy layout follows the .npy spec; the
// info and convert commands.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <sstream>

#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/npy.hpp"
#include "evcorner/io/open.hpp"
#include "io_test_util.hpp"
#include "test_util.hpp"

namespace evcorner::test {
namespace {

std::vector<Event> read_file(const std::string& path) {
    io::ReaderOptions o;
    o.fallback_sensor = std::nullopt;
    auto r = io::open_event_reader(path, o);
    const ReadResult res = read_all(*r, 1 << 16);
    EXPECT_FALSE(res.failed) << res.error;
    return res.events;
}

const char* const kRealInputs[] = {
    "davis240c-imu-pyaedattools/IMU_translBoxes.aedat",
    "expelliarmus/evt3_sample.raw",
    "faery-testdata/evt2.raw",
    "tonic-testdata/sample_ncars.dat",
};

TEST(Writers, RealFilesRoundTripThroughEveryWriter) {
    EVCORNER_REQUIRE_SHARED_DATA();
    TempDir tmp;
    for (const char* input : kRealInputs) {
        const auto events = read_file((shared_data() / "real" / input).string());
        ASSERT_FALSE(events.empty()) << input;
        for (const char* ext : {"txt", "csv", "npy"}) {
            SCOPED_TRACE(std::string(input) + " -> ." + ext);
            const auto out = tmp.path(std::string("out.") + ext);
            {
                auto w = io::open_event_writer(out);
                // Uneven pieces, so that batch edges are exercised.
                std::size_t i = 0, piece = 1;
                while (i < events.size()) {
                    const std::size_t n = std::min(piece, events.size() - i);
                    w->write(std::span<const Event>(events.data() + i, n));
                    i += n;
                    piece = piece * 3 + 1;
                }
                w->close();
            }
            auto r = io::open_event_reader(out, [] {
                io::ReaderOptions o;
                o.fallback_sensor = std::nullopt;
                return o;
            }());
            EXPECT_EQ(r->format(), std::string(ext) == "txt" ? "ecd-text" : ext);
            const ReadResult back = read_all(*r, 1000);
            ASSERT_FALSE(back.failed) << back.error;
            EXPECT_EQ(back.events, events);
        }
    }
}

TEST(Writers, CraftedEdgeValuesRoundTrip) {
    TempDir tmp;
    const std::vector<Event> events = {{-5, 0, 0, 0}, {0, 65535, 65535, 1}, {(1LL << 40) + 3, 7, 9, 1}};
    for (const char* ext : {"txt", "csv", "npy"}) {
        const auto out = tmp.path(std::string("e.") + ext);
        auto w = io::open_event_writer(out);
        w->write(events);
        w->close();
        EXPECT_EQ(read_file(out), events) << ext;
    }
}

// Every writer that carries scores gives them back through its reader, exactly, in
// batches of any size; events outside a given sensor are skipped with their scores.
TEST(Writers, ScoresRoundTripThroughEveryScoredWriter) {
    TempDir tmp;
    std::vector<Event> events;
    std::vector<double> scores;
    for (int i = 0; i < 3000; ++i) {
        events.push_back({i * 7 - 50, static_cast<std::uint16_t>(i % 300), static_cast<std::uint16_t>(i % 170),
                          static_cast<std::uint8_t>(i % 2)});
        scores.push_back(i % 5 == 0 ? -0.0 : (i - 1500) * 1.2345678901234567e-3 * (i % 3 ? 1e-200 : 1e200));
    }
    scores[7] = std::numeric_limits<double>::infinity();
    for (const char* ext : {"txt", "csv", "npy", "h5"}) {
        SCOPED_TRACE(ext);
        const auto out = tmp.path(std::string("s.") + ext);
        {
            auto w = io::open_event_writer(out, "auto", SensorSize{300, 170}, true);
            EXPECT_THROW(w->write(std::span<const Event>(events.data(), 1)), std::logic_error);
            w->write(std::span<const Event>(events.data(), 1000), std::span<const double>(scores.data(), 1000));
            w->write(std::span<const Event>(events.data() + 1000, 2000), std::span<const double>(scores.data() + 1000, 2000));
            w->close();
        }
        for (const std::size_t batch : {std::size_t{1}, std::size_t{777}, std::size_t{1} << 16}) {
            io::ReaderOptions o;
            o.fallback_sensor = std::nullopt;
            auto r = io::open_event_reader(out, o);
            std::vector<Event> ev_back;
            std::vector<double> sc_back;
            std::vector<Event> buf(batch);
            for (;;) {
                const std::size_t n = r->read(buf);
                if (n == 0 && r->skipped_in_batch().empty()) break;
                ASSERT_EQ(r->scores_in_batch().size(), n);
                ev_back.insert(ev_back.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
                sc_back.insert(sc_back.end(), r->scores_in_batch().begin(), r->scores_in_batch().end());
            }
            EXPECT_EQ(ev_back, events);
            ASSERT_EQ(sc_back.size(), scores.size());
            for (std::size_t i = 0; i < scores.size(); ++i)
                ASSERT_EQ(std::memcmp(&sc_back[i], &scores[i], 8), 0) << i << ": " << sc_back[i] << " vs " << scores[i];
        }
        // With a smaller sensor the events outside it are skipped, their scores too.
        io::ReaderOptions small;
        small.sensor = SensorSize{100, 170};
        small.skip_invalid = true;
        auto r = io::open_event_reader(out, small);
        std::vector<Event> buf(500);
        for (;;) {
            const std::size_t n = r->read(buf);
            if (n == 0 && r->skipped_in_batch().empty()) break;
            ASSERT_EQ(r->scores_in_batch().size(), n);
            for (std::size_t i = 0; i < n; ++i) {
                const std::size_t k = static_cast<std::size_t>((buf[i].t + 50) / 7);
                ASSERT_LT(buf[i].x, 100);
                ASSERT_EQ(std::memcmp(&r->scores_in_batch()[i], &scores[k], 8), 0) << k;
            }
        }
    }
    // A file without scores gives none; AEDAT 4.0 has no field for them.
    const auto plain = tmp.path("plain.csv");
    {
        auto w = io::open_event_writer(plain);
        w->write(events);
        EXPECT_THROW(w->write(events, scores), std::logic_error);
        w->close();
    }
    auto r = io::open_event_reader(plain);
    std::vector<Event> buf(100);
    EXPECT_EQ(r->read(buf), 100u);
    EXPECT_TRUE(r->scores_in_batch().empty());
    try {
        io::open_event_writer(tmp.path("s.aedat4"), "auto", std::nullopt, true);
        ADD_FAILURE() << "aedat4 with scores accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("no field for a score"), std::string::npos) << e.what();
    }
}

// The .npy format (numpy NEP 1): magic, version 1.0, little-endian header length, a
// dict literal padded with spaces to a multiple of 64 bytes ending in '\n', then the data.
TEST(Npy, HeaderFollowsTheSpec) {
    TempDir tmp;
    const auto out = tmp.path("h.npy");
    {
        io::NpyWriter w(out);
        const std::vector<Event> ev = {{1, 2, 3, 1}, {4, 5, 6, 0}};
        w.write(ev);
        w.close();
    }
    std::ifstream in(out, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    ASSERT_GE(bytes.size(), 10u);
    EXPECT_EQ(bytes.substr(0, 6), "\x93NUMPY");
    EXPECT_EQ(bytes[6], 1);
    EXPECT_EQ(bytes[7], 0);
    const std::size_t len = static_cast<unsigned char>(bytes[8]) | static_cast<unsigned char>(bytes[9]) << 8;
    EXPECT_EQ((10 + len) % 64, 0u);
    ASSERT_EQ(bytes.size(), 10 + len + 2 * 16);
    const std::string dict = bytes.substr(10, len);
    EXPECT_EQ(dict.back(), '\n');
    EXPECT_NE(dict.find("'shape': (2,)"), std::string::npos) << dict;
    EXPECT_NE(dict.find("'fortran_order': False"), std::string::npos) << dict;
    EXPECT_NE(dict.find("('t', '<i8'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1'), ('_', '|V3')"), std::string::npos)
        << dict;
    // Record 0: t = 1 (int64 LE), x = 2, y = 3, p = 1, 3 zero padding bytes.
    const std::string rec = bytes.substr(10 + len, 16);
    const std::string want("\x01\0\0\0\0\0\0\0\x02\0\x03\0\x01\0\0\0", 16);
    EXPECT_EQ(rec, want);
}

TEST(Npy, PackedDtypeAndDamage) {
    TempDir tmp;
    const auto npy = test::npy_file;
    auto rec13 = [](std::int64_t t, std::uint16_t x, std::uint16_t y, std::uint8_t p) {
        std::string r(13, '\0');
        std::memcpy(r.data(), &t, 8);
        std::memcpy(r.data() + 8, &x, 2);
        std::memcpy(r.data() + 10, &y, 2);
        r[12] = static_cast<char>(p);
        return r;
    };
    const std::string packed = "{'descr': [('t', '<i8'), ('x', '<u2'), ('y', '<u2'), ('p', '|b1')], "
                               "'fortran_order': False, 'shape': (2,), }";
    const std::size_t hdr = npy(packed, "").size();  // where the data starts
    ASSERT_EQ(hdr % 64, 0u);
    {
        const auto f = npy(packed, rec13(1, 2, 3, 1) + rec13(4, 5, 6, 0));
        EXPECT_EQ(read_file(tmp.write("p.npy", f)), (std::vector<Event>{{1, 2, 3, 1}, {4, 5, 6, 0}}));
    }
    {
        // The header says 2 events, 1.5 follow: a cut-short file. The whole event comes
        // first, then an error naming the offset where the data ends.
        const auto f = npy(packed, rec13(1, 2, 3, 1) + rec13(4, 5, 6, 0).substr(0, 6));
        const auto path = tmp.write("t.npy", f);
        io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;
        io::NpyReader r(path, o);
        const ReadResult res = read_all(r);
        EXPECT_EQ(res.events, (std::vector<Event>{{1, 2, 3, 1}}));
        ASSERT_TRUE(res.failed);
        EXPECT_EQ(res.error_position, hdr + 13u);
        EXPECT_NE(res.error.find(path + ": byte " + std::to_string(hdr + 13)), std::string::npos) << res.error;
        EXPECT_NE(res.error.find("ends after 1 of the 2 events"), std::string::npos) << res.error;
    }
    {
        const auto f = npy(packed, rec13(1, 2, 3, 1) + rec13(4, 5, 6, 9));  // polarity 9
        const auto path = tmp.write("c.npy", f);
        io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;
        io::NpyReader r(path, o);
        const ReadResult res = read_all(r);
        EXPECT_EQ(res.events.size(), 1u);
        ASSERT_TRUE(res.failed);
        EXPECT_EQ(res.error_position, hdr + 13u + 12u);
    }
    {
        const auto f = npy("{'descr': '<f8', 'fortran_order': False, 'shape': (2,), }", std::string(16, '\0'));
        EXPECT_THROW(io::NpyReader(tmp.write("f.npy", f)), InputError);
    }
    {
        std::string f("\x93NUMPY\x01\x00\xff\xff", 10);  // a 65535-byte header that is not there
        EXPECT_THROW(io::NpyReader(tmp.write("l.npy", f)), InputError);
    }
}

// The reader checks records in runs (BinaryReader::push_run) and hands the first one that
// fails a check to the slow path: every record is still checked, skipped or reported at
// its own byte offset, across batch boundaries.
TEST(Npy, EveryRecordIsCheckedAcrossRunsAndBatches) {
    TempDir tmp;
    std::vector<Event> events;
    for (int i = 0; i < 20000; ++i)
        events.push_back({i / 3, static_cast<std::uint16_t>(i % 240), static_cast<std::uint16_t>(i % 180),
                          static_cast<std::uint8_t>(i & 1)});
    // Outside a 240x180 sensor: single events and a run of three, at batch edges too.
    std::vector<std::size_t> outside = {0, 17, 4095, 4096, 9000, 9001, 9002, 19999};
    for (const std::size_t i : outside) events[i].x = 300;
    const std::string path = tmp.path("e.npy");
    {
        auto w = io::open_event_writer(path, "npy");
        w->write(events);
        w->close();
    }
    std::vector<Event> kept;
    for (std::size_t i = 0; i < events.size(); ++i)
        if (std::find(outside.begin(), outside.end(), i) == outside.end()) kept.push_back(events[i]);
    {
        io::ReaderOptions o;
        o.skip_invalid = true;  // 240x180 fallback sensor
        io::NpyReader r(path, o);
        const ReadResult res = read_all(r, 4096);
        EXPECT_FALSE(res.failed) << res.error;
        EXPECT_EQ(res.skipped, outside.size());
        EXPECT_EQ(res.events, kept);
    }
    {
        io::NpyReader r(path);  // no skipping: the first outside event is an error at its offset
        const ReadResult res = read_all(r, 4096);
        ASSERT_TRUE(res.failed);
        EXPECT_TRUE(res.events.empty());
        EXPECT_EQ(res.error_position, 192u);  // record 0, right after the 192-byte header
    }
    {
        // Time going backwards at record 12345: the events before it come first.
        std::vector<Event> back = kept;
        back[12345].t = back[12344].t - 1;
        auto w = io::open_event_writer(tmp.path("b.npy"), "npy");
        w->write(back);
        w->close();
        io::NpyReader r(tmp.path("b.npy"));
        const ReadResult res = read_all(r, 4096);
        ASSERT_TRUE(res.failed);
        EXPECT_EQ(res.events, std::vector<Event>(back.begin(), back.begin() + 12345));
        EXPECT_EQ(res.error_position, 192u + 16u * 12345u);
        EXPECT_NE(res.error.find("backwards"), std::string::npos) << res.error;
    }
}

#ifdef EVCORNER_CLI
std::string run(const std::string& cmd, int& status) {
    std::string out;
    FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
    if (!p) return out;
    std::array<char, 4096> buf{};
    while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
    status = ::pclose(p);
    return out;
}

TEST(Cli, InfoReportsTheReadmeFigures) {
    EVCORNER_REQUIRE_SHARED_DATA();
    int status = -1;
    const auto path = (shared_data() / "real/davis240c-imu-pyaedattools/IMU_translBoxes.aedat").string();
    const std::string out = run(std::string(EVCORNER_CLI) + " info '" + path + "'", status);
    EXPECT_EQ(status, 0) << out;
    EXPECT_NE(out.find("format       aedat2"), std::string::npos) << out;
    EXPECT_NE(out.find("sensor       240x180"), std::string::npos) << out;
    EXPECT_NE(out.find("events       162771"), std::string::npos) << out;
    EXPECT_NE(out.find("time         294976755 .. 297049406 us"), std::string::npos) << out;
    EXPECT_NE(out.find("ON / OFF     82944 / 79827"), std::string::npos) << out;
}

TEST(Cli, ConvertThenReadBack) {
    EVCORNER_REQUIRE_SHARED_DATA();
    TempDir tmp;
    const auto in = (shared_data() / "real/expelliarmus/evt3_sample.raw").string();
    const auto out = tmp.path("e.csv");
    int status = -1;
    const std::string log = run(std::string(EVCORNER_CLI) + " convert '" + in + "' '" + out + "'", status);
    EXPECT_EQ(status, 0) << log;
    EXPECT_EQ(read_file(out), read_file(in));
    const std::string bad = run(std::string(EVCORNER_CLI) + " convert '" + in + "' '" + tmp.path("e.xyz") + "'", status);
    EXPECT_NE(status, 0);
    EXPECT_NE(bad.find("--to"), std::string::npos) << bad;
}
#endif

}  // namespace
}  // namespace evcorner::test
