// ROS bag readers (ros_bag.hpp): the real bags of ../shared/data against their READMEs'
// figures, the ROS 1 copy against its ROS 2 twin, cut and damaged copies, and small
// synthetic bags for what the real files lack (compressed chunks, several topics,
// dvs_msgs/EventArray, libcaer roll-over, a bag without index or summary).

#include <bzlib.h>
#include <gtest/gtest.h>
#include <lz4frame.h>
#include <sqlite3.h>
#include <zstd.h>

#include <cstring>
#include <filesystem>
#include <map>
#include <fstream>

#include "cli_test_util.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/ros_bag.hpp"
#include "io_test_util.hpp"
#include "test_util.hpp"

namespace evcorner::test {
namespace {

// ---------------------------------------------------------------- real bags

struct RealBag {
    const char* path;  // under data/real
    const char* format;
    const char* encoding;
    std::uint64_t messages;
    SensorSize sensor;
    Figures fig;
};

// data/real/ros2-event-camera-codecs/README.md and ros2-event-camera-py/README.md. The
// libcaer bag's README times are in ns (as float64); in us they are the ns / 1000.
const RealBag kRealBags[] = {
    {"ros2-event-camera-codecs/test_data_evt3_trigger/test_data_evt3_trigger_0.db3", "rosbag2", "evt3", 105,
     {1280, 720}, {82469, 14224870, 15476187, 0, 1279, 0, 719, 41439, 41030}},
    {"ros2-event-camera-codecs/test_data_libcaer_rollover/libcaer_rollover_0.db3", "rosbag2", "libcaer", 201,
     {640, 480}, {334331, 1702309120762236, 1702309122762222, 0, 639, 0, 479, 181908, 152423}},
    {"ros2-event-camera-py/test_events_1/test_events_1.db3", "rosbag2", "evt3", 517, {640, 480},
     {343474, 7139845, 9218023, 0, 639, 0, 479, 125183, 218291}},
    {"ros2-event-camera-py/test_events_2/test_events_2_0.mcap", "mcap", "libcaer_cmp", 100, {346, 260},
     {571266, 1744227144732712, 1744227145732708, 0, 345, 0, 259, 211043, 360223}},
    {"ros2-event-camera-py/ros1/test_events_1.bag", "rosbag", "evt3", 517, {640, 480},
     {343474, 7139845, 9218023, 0, 639, 0, 479, 125183, 218291}},
};

std::string real(const char* p) { return (shared_data() / "real" / p).string(); }

TEST(RosBagReal, FiguresMatchReadme) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const RealBag& b : kRealBags) {
        SCOPED_TRACE(b.path);
        EXPECT_EQ(io::detect_format(real(b.path)), b.format);
        auto reader = io::open_event_reader(real(b.path));
        EXPECT_EQ(reader->format(), b.format);
        ASSERT_TRUE(reader->sensor());
        EXPECT_EQ(*reader->sensor(), b.sensor);
        const ReadResult r = read_all(*reader);
        ASSERT_FALSE(r.failed) << r.error;
        expect_figures(r.events, b.fig, b.path);
        const auto& bag = dynamic_cast<const io::BagReader&>(*reader);
        EXPECT_EQ(bag.encoding(), b.encoding);
        EXPECT_EQ(bag.messages(), b.messages);
        ASSERT_EQ(bag.topics().size(), 1u);
        EXPECT_EQ(bag.topics()[0].name, "/event_camera/events");
        EXPECT_EQ(bag.topics()[0].messages, b.messages);
        EXPECT_TRUE(bag.topics()[0].events());
    }
}

TEST(RosBagReal, FolderReadsLikeItsFile) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const char* dir : {"ros2-event-camera-codecs/test_data_evt3_trigger", "ros2-event-camera-py/test_events_2"}) {
        SCOPED_TRACE(dir);
        auto folder = io::open_event_reader(real(dir));
        const ReadResult a = read_all(*folder);
        ASSERT_FALSE(a.failed) << a.error;
        std::string file;
        for (const auto& e : fs::directory_iterator(real(dir)))
            if (e.path().extension() != ".yaml") file = e.path().string();
        auto single = io::open_event_reader(file);
        const ReadResult b = read_all(*single);
        EXPECT_EQ(a.events, b.events);
        EXPECT_FALSE(a.events.empty());
        // The folder's metadata.yaml given as the input opens the folder's bag.
        auto yaml = io::open_event_reader(real(dir) + "/metadata.yaml");
        EXPECT_EQ(yaml->format(), folder->format());
        const ReadResult c = read_all(*yaml);
        ASSERT_FALSE(c.failed) << c.error;
        EXPECT_EQ(c.events, a.events);
    }
}

TEST(RosBagReal, Ros1BagHoldsTheEventsOfItsRos2Twin) {
    EVCORNER_REQUIRE_SHARED_DATA();
    auto ros1 = io::open_event_reader(real("ros2-event-camera-py/ros1/test_events_1.bag"));
    auto ros2 = io::open_event_reader(real("ros2-event-camera-py/test_events_1/test_events_1.db3"));
    const ReadResult a = read_all(*ros1), b = read_all(*ros2);
    ASSERT_FALSE(a.failed) << a.error;
    ASSERT_FALSE(b.failed) << b.error;
    EXPECT_EQ(a.events.size(), 343474u);
    EXPECT_TRUE(a.events == b.events);
}

TEST(RosBagReal, BatchSizeDoesNotChangeTheEvents) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const RealBag& b : kRealBags) {
        auto big = io::open_event_reader(real(b.path));
        const ReadResult a = read_all(*big, 1 << 16);
        for (std::size_t batch : {1u, 7u}) {
            auto small = io::open_event_reader(real(b.path));
            const ReadResult c = read_all(*small, batch);
            ASSERT_FALSE(c.failed) << c.error;
            EXPECT_TRUE(a.events == c.events) << b.path << " batch " << batch;
        }
    }
}

TEST(RosBagReal, TopicOptionPicksOrNamesTheTopics) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const RealBag& b : kRealBags) {
        io::ReaderOptions o;
        o.topic = "/event_camera/events";
        auto r = io::open_event_reader(real(b.path), o);
        EXPECT_EQ(read_all(*r).events.size(), b.fig.events) << b.path;
        o.topic = "/camera/imu";
        try {
            io::open_event_reader(real(b.path), o);
            ADD_FAILURE() << b.path << ": an unknown topic was accepted";
        } catch (const InputError& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find("no topic '/camera/imu'"), std::string::npos) << m;
            EXPECT_NE(m.find("/event_camera/events ("), std::string::npos) << m;  // the topics are listed
            EXPECT_NE(m.find(std::to_string(b.messages) + " messages"), std::string::npos) << m;
        }
    }
}

TEST(RosBagReal, SensorOverrideChecksEvents) {
    EVCORNER_REQUIRE_SHARED_DATA();
    io::ReaderOptions o;
    o.sensor = SensorSize{320, 240};
    auto r = io::open_event_reader(real(kRealBags[3].path), o);
    const ReadResult res = read_all(*r);
    ASSERT_TRUE(res.failed);
    EXPECT_NE(res.error.find("outside the 320x240 sensor"), std::string::npos) << res.error;
    EXPECT_EQ(res.error_unit, InputError::Unit::byte);  // an uncompressed chunk: a file offset
    o.skip_invalid = true;
    auto s = io::open_event_reader(real(kRealBags[3].path), o);
    const ReadResult k = read_all(*s);
    ASSERT_FALSE(k.failed) << k.error;
    EXPECT_GT(k.skipped, 0u);
    EXPECT_EQ(k.events.size() + k.skipped, kRealBags[3].fig.events);
}

// Cut copies: the events before the cut, then an error naming the file; never a crash
// or a silent short read (a cut that spares every message, in MCAP's summary, reads all).
TEST(RosBagReal, CutCopiesFailCleanly) {
    EVCORNER_REQUIRE_SHARED_DATA();
    TempDir tmp;
    for (const RealBag& b : kRealBags) {
        std::ifstream in(real(b.path), std::ios::binary);
        const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        for (const double frac : {0.0001, 0.3, 0.77, 0.999}) {
            const auto cut = static_cast<std::size_t>(static_cast<double>(all.size()) * frac);
            SCOPED_TRACE(std::string(b.path) + " cut at " + std::to_string(cut));
            const std::string p = tmp.write("cut" + std::string(fs::path(b.path).extension()), all.substr(0, cut));
            std::string error;
            std::size_t events = 0;
            try {
                auto r = io::open_event_reader(p);
                const ReadResult res = read_all(*r);
                events = res.events.size();
                error = res.error;
            } catch (const InputError& e) {
                error = e.what();
            }
            // A cut in the summary / index after the data loses no event: then all are read.
            if (error.empty()) {
                EXPECT_EQ(events, b.fig.events) << "a cut bag lost events without an error";
                continue;
            }
            EXPECT_LE(events, b.fig.events);  // a cut index (ROS 1) is reported after every message
            EXPECT_EQ(error.rfind(p, 0), 0u) << error;  // names the file first
            for (const char c : error) EXPECT_TRUE(c >= 0x20 && c < 0x7F) << "raw byte in: " << error;
        }
    }
}

TEST(RosBagReal, DamagedRecordLengthIsAnErrorAtItsOffset) {
    EVCORNER_REQUIRE_SHARED_DATA();
    TempDir tmp;
    for (const char* path : {kRealBags[3].path, kRealBags[4].path}) {
        std::ifstream in(real(path), std::ios::binary);
        std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        std::size_t at = 0;
        if (fs::path(path).extension() == ".mcap") {
            // The first Chunk record (opcode 0x06): its length becomes huge.
            std::size_t p = 8;
            while (static_cast<unsigned char>(all[p]) != 0x06) {
                std::uint64_t len = 0;
                std::memcpy(&len, all.data() + p + 1, 8);
                p += 9 + len;
            }
            at = p;
            all[p + 8] = '\x7f';
        } else {
            // The record after the bag header (a chunk): its header length becomes huge.
            std::uint32_t hlen = 0, dlen = 0;
            std::memcpy(&hlen, all.data() + 13, 4);
            std::memcpy(&dlen, all.data() + 13 + 4 + hlen, 4);
            at = 13 + 4 + hlen + 4 + dlen;
            all[at + 3] = '\x7f';
        }
        const std::string p = tmp.write(std::string("damaged") + fs::path(path).extension().string(), all);
        std::string error;
        InputError::Unit unit = InputError::Unit::none;
        std::uint64_t pos = 0;
        try {
            auto r = io::open_event_reader(p);
            const ReadResult res = read_all(*r);
            error = res.error;
            unit = res.error_unit;
            pos = res.error_position;
        } catch (const InputError& e) {
            error = e.what();
            unit = e.unit();
            pos = e.position();
        }
        SCOPED_TRACE(error);
        ASSERT_FALSE(error.empty());
        EXPECT_EQ(unit, InputError::Unit::byte);
        EXPECT_EQ(pos, at);
        EXPECT_NE(error.find("past the end of the file"), std::string::npos);
    }
}

// ---------------------------------------------------------------- synthetic bags

void le(std::string& s, std::uint64_t v, int bytes) {
    for (int k = 0; k < bytes; ++k) s.push_back(static_cast<char>((v >> (8 * k)) & 0xFF));
}

// CDR (with the 4-byte encapsulation header) or ROS 1 serialisation.
class Ser {
public:
    explicit Ser(bool cdr) : cdr_(cdr) {
        if (cdr_) s_ = std::string("\x00\x01\x00\x00", 4);
    }
    void align(std::size_t n) {
        if (cdr_)
            while ((s_.size() - 4) % n != 0) s_.push_back('\0');
    }
    Ser& u8(std::uint8_t v) { return s_.push_back(static_cast<char>(v)), *this; }
    Ser& u16(std::uint16_t v) { return align(2), le(s_, v, 2), *this; }
    Ser& u32(std::uint32_t v) { return align(4), le(s_, v, 4), *this; }
    Ser& u64(std::uint64_t v) { return align(8), le(s_, v, 8), *this; }
    Ser& str(const std::string& v) {
        u32(static_cast<std::uint32_t>(v.size() + (cdr_ ? 1 : 0)));
        s_ += v;
        if (cdr_) s_.push_back('\0');
        return *this;
    }
    Ser& header() {
        if (!cdr_) u32(7);
        return u32(1700000000).u32(5).str("cam");
    }
    [[nodiscard]] const std::string& bytes() const { return s_; }

private:
    bool cdr_;
    std::string s_;
};

std::string packet(bool cdr, std::uint32_t w, std::uint32_t h, std::uint64_t time_base, const std::string& enc,
                   const std::string& payload) {
    Ser s(cdr);
    s.header().u32(h).u32(w).u64(1).u64(time_base).str(enc).u8(0).u32(static_cast<std::uint32_t>(payload.size()));
    return s.bytes() + payload;
}

// libcaer events: data = x << 17 | y << 2 | p << 1 | valid, then the int32 timestamp.
std::string libcaer(const std::vector<std::array<std::int64_t, 4>>& ev) {  // {ts, x, y, p}
    std::string s;
    for (const auto& e : ev) {
        le(s, static_cast<std::uint64_t>(e[1] << 17 | e[2] << 2 | e[3] << 1 | 1), 4);
        le(s, static_cast<std::uint64_t>(e[0]), 4);
    }
    return s;
}

std::string event_array(bool cdr, std::uint32_t w, std::uint32_t h, const std::vector<Event>& ev) {
    Ser s(cdr);
    s.header().u32(h).u32(w).u32(static_cast<std::uint32_t>(ev.size()));
    for (const Event& e : ev)
        s.u16(e.x).u16(e.y).u32(static_cast<std::uint32_t>(e.t / 1'000'000)).u32(static_cast<std::uint32_t>(e.t % 1'000'000 * 1000)).u8(e.p);
    return s.bytes();
}

std::string compress(const std::string& method, const std::string& raw) {
    std::string out;
    if (method == "lz4") {
        out.resize(LZ4F_compressFrameBound(raw.size(), nullptr));
        out.resize(LZ4F_compressFrame(out.data(), out.size(), raw.data(), raw.size(), nullptr));
    } else if (method == "zstd") {
        out.resize(ZSTD_compressBound(raw.size()));
        out.resize(ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), 3));
    } else if (method == "bz2") {
        auto n = static_cast<unsigned int>(raw.size() + raw.size() / 100 + 600);
        out.resize(n);
        BZ2_bzBuffToBuffCompress(out.data(), &n, const_cast<char*>(raw.data()), static_cast<unsigned int>(raw.size()), 9, 0, 0);
        out.resize(n);
    } else {
        out = raw;
    }
    return out;
}

struct SynthMessage {
    int channel;  // 1-based
    std::string data;
};
struct SynthTopic {
    std::string name, type, encoding;  // encoding: "cdr" / "ros1"
};

// MCAP: Header, Schemas, Channels and Messages in one Chunk, DataEnd, Footer; no summary.
std::string mcap(const std::vector<SynthTopic>& topics, const std::vector<SynthMessage>& msgs, const std::string& method) {
    auto rec = [](int op, const std::string& c) {
        std::string r(1, static_cast<char>(op));
        le(r, c.size(), 8);
        return r + c;
    };
    auto s32 = [](const std::string& v) {
        std::string r;
        le(r, v.size(), 4);
        return r + v;
    };
    std::string records;
    for (std::size_t i = 0; i < topics.size(); ++i) {
        std::string sc, ch;
        le(sc, i + 1, 2);
        records += rec(0x03, sc + s32(topics[i].type) + s32("ros2msg") + s32(""));
        le(ch, i + 1, 2);
        le(ch, i + 1, 2);
        std::string meta;
        le(meta, 0, 4);
        records += rec(0x04, ch + s32(topics[i].name) + s32(topics[i].encoding) + meta);
    }
    std::uint32_t seq = 0;
    for (const auto& m : msgs) {
        std::string c;
        le(c, static_cast<std::uint64_t>(m.channel), 2);
        le(c, seq++, 4);
        le(c, 1000 + seq, 8);
        le(c, 1000 + seq, 8);
        records += rec(0x05, c + m.data);
    }
    std::string chunk;
    le(chunk, 0, 8);
    le(chunk, 0, 8);
    le(chunk, records.size(), 8);
    le(chunk, 0, 4);
    const std::string packed = compress(method, records);
    chunk += s32(method == "none" ? "" : method);
    le(chunk, packed.size(), 8);
    chunk += packed;
    std::string f(io::kMcapMagic);
    f += rec(0x01, s32("ros2") + s32("evcorner-test"));
    f += rec(0x06, chunk);
    f += rec(0x0F, std::string(4, '\0'));
    f += rec(0x02, std::string(20, '\0'));
    return f + std::string(io::kMcapMagic);
}

// ROS 1 bag: header, one chunk (connections and messages), then the index (connections,
// one chunk info), unless `indexed` is false (index_pos 0, as a recording not closed).
std::string rosbag1(const std::vector<SynthTopic>& topics, const std::vector<SynthMessage>& msgs,
                    const std::string& method, bool indexed = true) {
    auto field = [](const std::string& name, const std::string& value) {
        std::string r;
        le(r, name.size() + 1 + value.size(), 4);
        return r + name + "=" + value;
    };
    auto num = [](std::uint64_t v, int bytes) {
        std::string r;
        le(r, v, bytes);
        return r;
    };
    auto record = [](const std::string& header, const std::string& data) {
        std::string r;
        le(r, header.size(), 4);
        r += header;
        le(r, data.size(), 4);
        return r + data;
    };
    std::string conns;
    for (std::size_t i = 0; i < topics.size(); ++i)
        conns += record(field("op", "\x07") + field("conn", num(i, 4)) + field("topic", topics[i].name),
                        field("topic", topics[i].name) + field("type", topics[i].type) + field("md5sum", "*"));
    std::string inner = conns;
    std::map<int, std::uint32_t> counts;
    for (const auto& m : msgs) {
        inner += record(field("op", std::string(1, '\x02')) + field("conn", num(static_cast<std::uint64_t>(m.channel - 1), 4)) +
                            field("time", num(5, 8)),
                        m.data);
        ++counts[m.channel - 1];
    }
    const std::string header_rec_placeholder(4 + 0, ' ');
    std::string f(io::kRosbag1Magic);
    const std::string chunk =
        record(field("op", "\x05") + field("compression", method) + field("size", num(inner.size(), 4)),
               compress(method, inner));
    // The bag header's size does not depend on index_pos's value.
    auto bag_header = [&](std::uint64_t index_pos) {
        return record(field("op", "\x03") + field("index_pos", num(index_pos, 8)) +
                          field("conn_count", num(topics.size(), 4)) + field("chunk_count", num(1, 4)),
                      std::string(16, ' '));
    };
    const std::uint64_t chunk_pos = f.size() + bag_header(0).size();
    const std::uint64_t index_pos = chunk_pos + chunk.size();
    f += bag_header(indexed ? index_pos : 0) + chunk;
    if (indexed) {
        f += conns;
        std::string data;
        for (const auto& [c, n] : counts) data += num(static_cast<std::uint64_t>(c), 4) + num(n, 4);
        f += record(field("op", "\x06") + field("ver", num(1, 4)) + field("chunk_pos", num(chunk_pos, 8)) +
                        field("start_time", num(0, 8)) + field("end_time", num(0, 8)) + field("count", num(counts.size(), 4)),
                    data);
    }
    return f;
}

const std::vector<std::array<std::int64_t, 4>> kCaerA = {{10, 1, 2, 1}, {20, 3, 4, 0}, {20, 639, 479, 1}};
const std::vector<std::array<std::int64_t, 4>> kCaerB = {{35, 5, 6, 0}, {2147483640, 7, 8, 1}, {3, 9, 10, 1}};
// time_base 5 000 123 ns: 5000 us.
std::vector<Event> caer_expected() {
    return {{5010, 1, 2, 1}, {5020, 3, 4, 0}, {5020, 639, 479, 1},
            {5035, 5, 6, 0}, {std::int64_t{5000} + 2147483640, 7, 8, 1}, {5000 + 3 + (std::int64_t{1} << 31), 9, 10, 1}};
}
const std::vector<Event> kDvs = {{1700000000123456, 0, 0, 1}, {1700000000123457, 345, 259, 0}, {1700000000123999, 17, 3, 1}};

std::vector<SynthTopic> two_topics(bool cdr) {
    const std::string enc = cdr ? "cdr" : "ros1";
    return {{"/dvs/events", cdr ? "dvs_msgs/msg/EventArray" : "dvs_msgs/EventArray", enc},
            {"/cam/events", cdr ? "event_camera_msgs/msg/EventPacket" : "event_camera_msgs/EventPacket", enc},
            {"/imu", cdr ? "sensor_msgs/msg/Imu" : "sensor_msgs/Imu", enc}};
}
std::vector<SynthMessage> two_topic_messages(bool cdr) {
    return {{2, packet(cdr, 640, 480, 5'000'123, "libcaer", libcaer(kCaerA))},
            {1, event_array(cdr, 346, 260, {kDvs[0], kDvs[1]})},
            {3, "imu"},
            {2, packet(cdr, 640, 480, 5'000'123, "libcaer", libcaer(kCaerB))},
            {1, event_array(cdr, 346, 260, {kDvs[2]})}};
}

std::vector<Event> read_topic(const std::string& path, const std::string& topic, std::optional<SensorSize>* sensor = nullptr) {
    io::ReaderOptions o;
    o.topic = topic;
    auto r = io::open_event_reader(path, o);
    if (sensor) *sensor = r->sensor();
    const ReadResult res = read_all(*r, 2);
    EXPECT_FALSE(res.failed) << res.error;
    return res.events;
}

void check_two_topic_bag(const std::string& path, const std::string& format) {
    SCOPED_TRACE(path);
    EXPECT_EQ(io::detect_format(path), format);
    std::optional<SensorSize> sensor;
    EXPECT_EQ(read_topic(path, "/cam/events", &sensor), caer_expected());
    EXPECT_EQ(sensor, (SensorSize{640, 480}));
    EXPECT_EQ(read_topic(path, "/dvs/events", &sensor), kDvs);
    EXPECT_EQ(sensor, (SensorSize{346, 260}));
    try {
        io::open_event_reader(path);
        ADD_FAILURE() << "two event topics and no --topic were accepted";
    } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("2 event topics: choose one with --topic"), std::string::npos) << m;
        EXPECT_NE(m.find("/dvs/events ("), std::string::npos) << m;
        EXPECT_NE(m.find("/cam/events ("), std::string::npos) << m;
    }
    io::ReaderOptions o;
    o.topic = "/imu";
    try {
        io::open_event_reader(path, o);
        ADD_FAILURE() << "a topic of another type was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("not an event type"), std::string::npos) << e.what();
    }
    o.topic = "/cam/events";
    auto r = io::open_bag_reader(path, o);
    ASSERT_EQ(r->topics().size(), 3u);
    for (const auto& t : r->topics()) EXPECT_EQ(t.messages, t.name == "/imu" ? 1u : 2u) << t.name;
}

TEST(RosBagSynthetic, McapChunksPlainLz4Zstd) {
    TempDir tmp;
    for (const std::string method : {"none", "lz4", "zstd"}) {
        const auto path = tmp.write(method + ".mcap", mcap(two_topics(true), two_topic_messages(true), method));
        check_two_topic_bag(path, "mcap");
    }
}

TEST(RosBagSynthetic, McapWithRos1EncodedChannel) {
    TempDir tmp;
    const auto path = tmp.write("ros1.mcap", mcap(two_topics(false), two_topic_messages(false), "zstd"));
    check_two_topic_bag(path, "mcap");
}

TEST(RosBagSynthetic, Ros1ChunksNoneBz2Lz4IndexedOrNot) {
    TempDir tmp;
    for (const std::string method : {"none", "bz2", "lz4"})
        for (const bool indexed : {true, false}) {
            const auto path = tmp.write(method + (indexed ? "" : "-noindex") + ".bag",
                                        rosbag1(two_topics(false), two_topic_messages(false), method, indexed));
            check_two_topic_bag(path, "rosbag");
        }
}

TEST(RosBagSynthetic, Rosbag2SqliteWithSeveralTopics) {
    TempDir tmp;
    const auto path = tmp.path("bag.db3");
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
    sqlite3_exec(db,
                 "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
                 "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
                 "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
                 "data BLOB NOT NULL);",
                 nullptr, nullptr, nullptr);
    const auto topics = two_topics(true);
    for (std::size_t i = 0; i < topics.size(); ++i) {
        const std::string sql = "INSERT INTO topics VALUES(" + std::to_string(i + 1) + ",'" + topics[i].name + "','" +
                                topics[i].type + "','cdr','')";
        ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
    }
    sqlite3_stmt* st = nullptr;
    sqlite3_prepare_v2(db, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, 0, ?)", -1, &st, nullptr);
    for (const auto& m : two_topic_messages(true)) {
        sqlite3_bind_int(st, 1, m.channel);
        sqlite3_bind_blob(st, 2, m.data.data(), static_cast<int>(m.data.size()), SQLITE_TRANSIENT);
        ASSERT_EQ(sqlite3_step(st), SQLITE_DONE);
        sqlite3_reset(st);
    }
    sqlite3_finalize(st);
    sqlite3_close(db);
    check_two_topic_bag(path, "rosbag2");
}

TEST(RosBagSynthetic, LibcaerCmpWordsDecodePerPacket) {
    TempDir tmp;
    // time high 1, low 2 -> 4098 us; x 7; y 9 ON; vector base y 16 OFF, mask 0b101 -> y 16, 18;
    // then x 8 and vector mask 0b1 at base 24 -> y 24. Next packet: the state starts at 0.
    std::string w;
    for (const std::uint16_t word : {0x0001, 0x1002, 0x2007, 0x3809, 0x4010, 0x5005, 0x2008, 0x5001})
        le(w, word, 2);
    std::string w2;
    for (const std::uint16_t word : {0x1003, 0x2001, 0x3001}) le(w2, word, 2);
    const std::vector<SynthTopic> t = {{"/e", "event_camera_msgs/msg/EventPacket", "cdr"}};
    const auto path = tmp.write("cmp.mcap", mcap(t, {{1, packet(true, 346, 260, 7'000'999, "libcaer_cmp", w)},
                                                     {1, packet(true, 346, 260, 12'000'000, "libcaer_cmp", w2)}}, "none"));
    const std::vector<Event> want = {{7000 + 4098, 7, 9, 1},  {7000 + 4098, 7, 16, 0}, {7000 + 4098, 7, 18, 0},
                                     {7000 + 4098, 8, 24, 0}, {12000 + 3, 1, 1, 0}};
    EXPECT_EQ(read_topic(path, "", nullptr), want);
}

TEST(RosBagSynthetic, DamagedMessagesNameTheMessage) {
    TempDir tmp;
    const std::vector<SynthTopic> t = {{"/e", "event_camera_msgs/msg/EventPacket", "cdr"}};
    const std::string good = packet(true, 640, 480, 0, "libcaer", libcaer(kCaerA));
    struct Case {
        std::string name, data, expect;
    };
    const std::vector<Case> cases = {
        {"unknown encoding", packet(true, 640, 480, 0, "mono8\x01", ""), "encoding 'mono8\\x01' is not supported"},
        {"cut payload", good.substr(0, good.size() - 3), "the message ends inside the events"},
        {"odd libcaer", packet(true, 640, 480, 0, "libcaer", libcaer(kCaerA) + "x"), "not whole 8-byte events"},
        {"time backwards", packet(true, 640, 480, 0, "libcaer", libcaer({{50, 1, 1, 1}, {40, 1, 1, 1}})),
         "timestamp goes backwards"},
        {"big-endian CDR", std::string("\x00\x00", 2) + good.substr(2), "big-endian CDR"},
    };
    for (const std::string method : {"none", "zstd"})
        for (const Case& c : cases) {
            SCOPED_TRACE(c.name + " in a chunk " + method);
            const auto path = tmp.write("d.mcap", mcap(t, {{1, good}, {1, c.data}}, method));
            std::string error;
            std::size_t events = 0;
            InputError::Unit unit = InputError::Unit::none;
            try {
                auto r = io::open_event_reader(path);
                const ReadResult res = read_all(*r);
                error = res.error;
                events = res.events.size();
                unit = res.error_unit;
            } catch (const InputError& e) {
                error = e.what();
            }
            EXPECT_EQ(events, c.name == "time backwards" ? 4u : 3u);  // the good message's events come first
            EXPECT_NE(error.find(c.expect), std::string::npos) << error;
            EXPECT_NE(error.find("message 2 of topic /e"), std::string::npos) << error;
            // In a plain chunk the payload's file offset; in a compressed one the chunk's.
            EXPECT_EQ(unit, InputError::Unit::byte) << error;
            if (method == "zstd") {
                EXPECT_NE(error.find("in the zstd chunk at byte"), std::string::npos) << error;
            }
        }
}

TEST(RosBagSynthetic, NotABagAndPipes) {
    TempDir tmp;
    const auto path = tmp.write("x.bag", "#ROSBAG V2.0\nhello");
    EXPECT_THROW(io::open_event_reader(path), InputError);
    const auto mc = tmp.write("x.mcap", std::string(io::kMcapMagic) + "\x01");
    try {
        io::open_event_reader(mc);
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("cut short"), std::string::npos) << e.what();
    }
    const auto db = tmp.write("x.db3", std::string(io::kSqliteMagic) + std::string(100, '\0'));
    EXPECT_THROW(io::open_event_reader(db), InputError);
    // --format must agree with the magic bytes.
    const auto mcap_file = tmp.write("y.mcap", mcap({{"/e", "event_camera_msgs/msg/EventPacket", "cdr"}}, {}, "none"));
    EXPECT_THROW(io::open_event_reader(mcap_file, {}, "rosbag"), InputError);
    auto empty = io::open_event_reader(mcap_file, {}, "mcap");
    EXPECT_TRUE(read_all(*empty).events.empty());
}

// ---------------------------------------------------------------- the command line

class RosBagCli : public CliTest {};

TEST_F(RosBagCli, InfoShowsFiguresAndTopics) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const RealBag& b : kRealBags) {
        SCOPED_TRACE(b.path);
        const CliResult r = run("info --no-progress '" + real(b.path) + "'");
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_NE(r.out.find(std::string("format       ") + b.format + "\n"), std::string::npos) << r.out;
        EXPECT_NE(r.out.find("events       " + std::to_string(b.fig.events) + "\n"), std::string::npos) << r.out;
        EXPECT_NE(r.out.find("time         " + std::to_string(b.fig.t_min) + " .. " + std::to_string(b.fig.t_max)),
                  std::string::npos) << r.out;
        EXPECT_NE(r.out.find("ON / OFF     " + std::to_string(b.fig.on) + " / " + std::to_string(b.fig.off)),
                  std::string::npos) << r.out;
        EXPECT_NE(r.out.find("x range      " + std::to_string(b.fig.x_min) + ".." + std::to_string(b.fig.x_max)),
                  std::string::npos);
        EXPECT_NE(r.out.find("y range      " + std::to_string(b.fig.y_min) + ".." + std::to_string(b.fig.y_max)),
                  std::string::npos);
        const std::string type = b.format == std::string("rosbag") ? "event_camera_msgs/EventPacket"
                                                                   : "event_camera_msgs/msg/EventPacket";
        EXPECT_NE(r.out.find("/event_camera/events  " + type + "  " + std::to_string(b.messages) + " messages"),
                  std::string::npos) << r.out;
        EXPECT_NE(r.out.find(std::string("encoding ") + b.encoding + ")"), std::string::npos) << r.out;
    }
}

TEST_F(RosBagCli, ConvertWritesTheSameEvents) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const RealBag& b : {kRealBags[1], kRealBags[3], kRealBags[4]}) {
        SCOPED_TRACE(b.path);
        const CliResult c = run("convert --no-progress '" + real(b.path) + "' out.npy");
        ASSERT_EQ(c.status, 0) << c.err;
        io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;  // .npy has no sensor size
        auto r = io::open_event_reader((dir_ / "out.npy").string(), o);
        const ReadResult res = read_all(*r);
        ASSERT_FALSE(res.failed) << res.error;
        expect_figures(res.events, b.fig, b.path);
    }
}

TEST_F(RosBagCli, TopicOption) {
    EVCORNER_REQUIRE_SHARED_DATA();
    const std::string bag = real(kRealBags[4].path);
    CliResult r = run("info --no-progress --topic /event_camera/events --json info.json '" + bag + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    const std::string json = slurp(dir_ / "info.json");
    EXPECT_NE(json.find("\"topic\": \"/event_camera/events\""), std::string::npos) << json;
    EXPECT_NE(json.find("\"encoding\": \"evt3\""), std::string::npos) << json;
    EXPECT_NE(json.find("\"messages\": 517"), std::string::npos) << json;
    r = run("info --no-progress --topic /nope '" + bag + "'");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("no topic '/nope' in the bag (topics: /event_camera/events (event_camera_msgs/EventPacket, "
                         "517 messages))"),
              std::string::npos) << r.err;
    r = run("info --no-progress --topic /x '" + real("expelliarmus/evt3_sample.raw") + "'");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("--topic"), std::string::npos) << r.err;
    // A bag read from standard input cannot be seeked.
    r = run("info --no-progress -", bag);
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("regular file"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace evcorner::test
