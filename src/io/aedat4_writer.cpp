#include "evcorner/io/aedat4_writer.hpp"

#include <lz4frame.h>

#include <algorithm>
#include <cstring>
#include <fmt/format.h>

#include "evcorner/error.hpp"
#include "evcorner/io/aedat4_reader.hpp"

namespace evcorner::io {

namespace {

// The description is padded to this length so that the header keeps its size when it
// is rewritten with the final sensor size.
constexpr std::size_t kXmlLength = 2048;
constexpr std::size_t kEventBytes = 16;
// Events start 32 bytes into the size-prefixed EventPacket (see make_packet_head).
constexpr std::size_t kPacketHead = 32;

void put16(std::string& s, std::uint16_t v) {
    s.push_back(static_cast<char>(v & 0xFF));
    s.push_back(static_cast<char>(v >> 8));
}
void put32(std::string& s, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) s.push_back(static_cast<char>((v >> (8 * k)) & 0xFF));
}
void put64(std::string& s, std::uint64_t v) {
    put32(s, static_cast<std::uint32_t>(v));
    put32(s, static_cast<std::uint32_t>(v >> 32));
}
std::string description(Aedat4Writer::Compression c, SensorSize s) {
    std::string xml = fmt::format(
        "<dv version=\"2.0\">\n"
        "    <node name=\"outInfo\" path=\"/mainloop/Recorder/outInfo/\">\n"
        "        <node name=\"0\" path=\"/mainloop/Recorder/outInfo/0/\">\n"
        "            <attr key=\"compression\" type=\"string\">{}</attr>\n"
        "            <attr key=\"originalModuleName\" type=\"string\">evcorner</attr>\n"
        "            <attr key=\"originalOutputName\" type=\"string\">events</attr>\n"
        "            <attr key=\"typeDescription\" type=\"string\">Array of events (polarity ON/OFF).</attr>\n"
        "            <attr key=\"typeIdentifier\" type=\"string\">EVTS</attr>\n"
        "            <node name=\"info\" path=\"/mainloop/Recorder/outInfo/0/info/\">\n"
        "                <attr key=\"sizeX\" type=\"int\">{}</attr>\n"
        "                <attr key=\"sizeY\" type=\"int\">{}</attr>\n"
        "                <attr key=\"source\" type=\"string\">evcorner</attr>\n"
        "                <attr key=\"tsOffset\" type=\"long\">0</attr>\n"
        "            </node>\n"
        "        </node>\n"
        "    </node>\n"
        "</dv>\n",
        c == Aedat4Writer::Compression::lz4 ? "LZ4" : "NONE", s.width, s.height);
    xml.resize(kXmlLength, ' ');  // whitespace after the root element
    return xml;
}

// The size-prefixed IOHeader FlatBuffer. Offsets from the size prefix:
//   0 size | 4 root offset (-> 24) | 8 "IOHE" | 12 vtable (10 bytes) | 22 pad
//   24 table: soffset 12 | 28 infoNode offset (-> 44) | 32 dataTablePosition (int64)
//   40 compression (int32) | 44 string: length, bytes, NUL, padding to 8.
std::string io_header(Aedat4Writer::Compression c, SensorSize s) {
    const std::string xml = description(c, s);
    std::string b;
    put32(b, 0);  // size, set below
    put32(b, 24 - 4);
    b += "IOHE";
    put16(b, 10);  // vtable size
    put16(b, 20);  // table size
    put16(b, 16);  // field 0 compression
    put16(b, 8);   // field 1 dataTablePosition
    put16(b, 4);   // field 2 infoNode
    put16(b, 0);
    put32(b, 24 - 12);
    put32(b, 44 - 28);
    put64(b, static_cast<std::uint64_t>(std::int64_t{-1}));
    put32(b, c == Aedat4Writer::Compression::lz4 ? 1 : 0);
    put32(b, static_cast<std::uint32_t>(xml.size()));
    b += xml;
    b.push_back('\0');
    while (b.size() % 8 != 0) b.push_back('\0');
    const auto n = static_cast<std::uint32_t>(b.size() - 4);
    for (int k = 0; k < 4; ++k) b[static_cast<std::size_t>(k)] = static_cast<char>((n >> (8 * k)) & 0xFF);
    return b;
}

// The first 32 bytes of a size-prefixed EventPacket of n events. Offsets:
//   0 size | 4 root offset (-> 20) | 8 "EVTS" | 12 vtable (6 bytes) | 18 pad
//   20 table: soffset 8 | 24 elements offset (-> 28) | 28 length | 32 events
void make_packet_head(unsigned char* p, std::size_t n) {
    std::string b;
    put32(b, static_cast<std::uint32_t>(kPacketHead - 4 + n * kEventBytes));
    put32(b, 20 - 4);
    b += "EVTS";
    put16(b, 6);
    put16(b, 8);
    put16(b, 4);
    put16(b, 0);
    put32(b, 20 - 12);
    put32(b, 28 - 24);
    put32(b, static_cast<std::uint32_t>(n));
    std::memcpy(p, b.data(), kPacketHead);
}

std::string regular_or_sized(std::string path, const Aedat4Writer::Options& o) {
    if (path.size() == 1 && path[0] == '-' && !o.sensor)
        throw OutputError("<stdout>", "an AEDAT 4.0 file without a given sensor size cannot go to standard "
                                      "output (the size is written into its header at the end)");
    return path;
}

}  // namespace

Aedat4Writer::Aedat4Writer(std::string path, Options options)
    : options_(options), out_(regular_or_sized(std::move(path), options)) {
    if (options_.packet_events == 0) options_.packet_events = 8192;
    if (options_.sensor && (options_.sensor->width > 32768 || options_.sensor->height > 32768))
        throw OutputError(out_.name(), "AEDAT 4.0 coordinates are int16: the sensor must be at most 32768x32768");
    packet_.resize(kPacketHead + options_.packet_events * kEventBytes);
    rewrite_header_ = !options_.sensor;
    out_.write(kAedat4Magic);
    out_.write(io_header(options_.compression, options_.sensor.value_or(SensorSize{1, 1})));
}

Aedat4Writer::~Aedat4Writer() = default;  // without close(), out_ removes the unfinished file

void Aedat4Writer::set_sensor(SensorSize size) {
    if (size.width < 1 || size.height < 1 || size.width > 32768 || size.height > 32768)
        throw OutputError(out_.name(), fmt::format("sensor {}x{}: AEDAT 4.0 sizes are 1..32768 per side", size.width,
                                                   size.height));
    if (max_x_ >= size.width || max_y_ >= size.height)
        throw OutputError(out_.name(), fmt::format("an event written at x={} y={} lies outside the {}x{} sensor",
                                                   max_x_, max_y_, size.width, size.height));
    if (options_.sensor == size) return;
    options_.sensor = size;
    rewrite_header_ = true;
}

void Aedat4Writer::write(std::span<const Event> events) {
    for (const Event& e : events) {
        if (e.x > 32767 || e.y > 32767) [[unlikely]]
            throw OutputError(out_.name(), fmt::format("event at x={} y={}: AEDAT 4.0 coordinates are int16", e.x, e.y));
        if (options_.sensor && !options_.sensor->contains(e)) [[unlikely]]
            throw OutputError(out_.name(), fmt::format("event at x={} y={} lies outside the {}x{} sensor", e.x, e.y,
                                                       options_.sensor->width, options_.sensor->height));
        max_x_ = std::max<int>(max_x_, e.x);
        max_y_ = std::max<int>(max_y_, e.y);
        unsigned char* p = packet_.data() + kPacketHead + pending_ * kEventBytes;
        std::memcpy(p, &e.t, 8);
        std::memcpy(p + 8, &e.x, 2);
        std::memcpy(p + 10, &e.y, 2);
        p[12] = e.p != 0;
        p[13] = p[14] = p[15] = 0;
        if (++pending_ == options_.packet_events) flush_packet();
    }
}

void Aedat4Writer::flush_packet() {
    if (pending_ == 0) return;
    make_packet_head(packet_.data(), pending_);
    const std::size_t n = kPacketHead + pending_ * kEventBytes;
    pending_ = 0;
    std::string head;
    put32(head, 0);  // stream id
    if (options_.compression == Compression::none) {
        put32(head, static_cast<std::uint32_t>(n));
        out_.write(head);
        out_.write(std::string_view(reinterpret_cast<const char*>(packet_.data()), n));
        return;
    }
    LZ4F_preferences_t prefs{};
    prefs.frameInfo.contentSize = n;
    compressed_.resize(LZ4F_compressFrameBound(n, &prefs));
    const std::size_t c = LZ4F_compressFrame(compressed_.data(), compressed_.size(), packet_.data(), n, &prefs);
    if (LZ4F_isError(c)) throw OutputError(out_.name(), std::string("LZ4 compression failed: ") + LZ4F_getErrorName(c));
    put32(head, static_cast<std::uint32_t>(c));
    out_.write(head);
    out_.write(std::string_view(compressed_.data(), c));
}

void Aedat4Writer::close() {
    if (closed_) return;
    flush_packet();
    if (rewrite_header_) {
        // The header is the same length whatever the size (kXmlLength): rewritten in place.
        const SensorSize size = options_.sensor.value_or(SensorSize{std::max(max_x_ + 1, 1), std::max(max_y_ + 1, 1)});
        out_.write_at(kAedat4Magic.size(), io_header(options_.compression, size));
    }
    out_.close();
    closed_ = true;
}

}  // namespace evcorner::io
