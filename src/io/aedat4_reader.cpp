#include "evcorner/io/aedat4_reader.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <fmt/format.h>

#include "flatbuffer_view.hpp"

namespace evcorner::io {

namespace {

constexpr std::size_t kPacketHeader = 8;
constexpr std::size_t kEventBytes = 16;
constexpr std::size_t kMaxIoHeader = std::size_t{16} << 20;

// The value of `name="..."` inside a tag's text.
std::optional<std::string_view> xml_attribute(std::string_view tag, std::string_view name) {
    std::size_t pos = 0;
    while ((pos = tag.find(name, pos)) != std::string_view::npos) {
        const bool word_start = pos > 0 && (tag[pos - 1] == ' ' || tag[pos - 1] == '\t' || tag[pos - 1] == '\n');
        const std::size_t q = pos + name.size();
        if (word_start && q + 1 < tag.size() && tag[q] == '=' && (tag[q + 1] == '"' || tag[q + 1] == '\'')) {
            const auto end = tag.find(tag[q + 1], q + 2);
            if (end == std::string_view::npos) return std::nullopt;
            return tag.substr(q + 2, end - q - 2);
        }
        pos = q;
    }
    return std::nullopt;
}

std::optional<int> to_int(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\n' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\n' || s.back() == '\t')) s.remove_suffix(1);
    int v = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
    return v;
}

// The streams of DV's output description: <node name="outInfo"> / <node name="ID">
// with attr typeIdentifier, and its <node name="info"> with attr sizeX, sizeY.
std::vector<Aedat4Stream> parse_streams(std::string_view xml) {
    std::vector<Aedat4Stream> streams;
    std::vector<std::string_view> path;  // names of the open <node>s
    int size_x = 0, size_y = 0;  // 0: not given
    std::size_t pos = 0;
    while ((pos = xml.find('<', pos)) != std::string_view::npos) {
        const auto close = xml.find('>', pos);
        if (close == std::string_view::npos) break;
        const std::string_view tag = xml.substr(pos + 1, close - pos - 1);
        pos = close + 1;
        if (tag.starts_with("node") && (tag.size() == 4 || tag[4] == ' ' || tag[4] == '\t' || tag[4] == '\n')) {
            if (tag.ends_with("/")) continue;
            path.push_back(xml_attribute(tag, "name").value_or(""));
            if (path.size() == 2 && path[0] == "outInfo") {
                const auto id = to_int(path[1]);
                if (id) streams.push_back({*id, "", std::nullopt});
                size_x = size_y = 0;
            }
        } else if (tag == "/node") {
            if (!path.empty()) path.pop_back();
        } else if (tag.starts_with("attr ")) {
            const auto end = xml.find("</attr>", pos);
            if (end == std::string_view::npos) break;
            const std::string_view value = xml.substr(pos, end - pos);
            pos = end + 7;
            const auto key = xml_attribute(tag, "key").value_or("");
            if (path.size() < 2 || path[0] != "outInfo" || streams.empty() || to_int(path[1]) != streams.back().id)
                continue;
            if (path.size() == 2 && key == "typeIdentifier") {
                streams.back().type = std::string(value);
            } else if (path.size() == 3 && path[2] == "info") {
                if (key == "sizeX") size_x = to_int(value).value_or(0);
                if (key == "sizeY") size_y = to_int(value).value_or(0);
                if (size_x >= 1 && size_y >= 1 && size_x <= kMaxSensorSide && size_y <= kMaxSensorSide)
                    streams.back().size = SensorSize{size_x, size_y};
            }
        }
    }
    return streams;
}

}  // namespace

Aedat4Reader::Aedat4Reader(InputFile file, ReaderOptions options, std::optional<int> stream_id)
    : BinaryReader(std::move(file), std::move(options)) {
    const std::size_t m = kAedat4Magic.size();
    if (fill(m) < m || std::memcmp(data(), kAedat4Magic.data(), m) != 0)
        fail(0, "not an AEDAT 4.0 file (it must start with '#!AER-DAT4.0\\r\\n')");
    consume(m);
    if (fill(4) < 4) fail(offset(), "the file ends before the IOHeader");
    const std::uint64_t header_at = offset();
    const std::uint32_t size = fb::u32(data());
    if (size > kMaxIoHeader || (bytes_total() && size > *bytes_total() - header_at - 4))
        fail(header_at, fmt::format("IOHeader size {} exceeds the file or {} bytes", size, kMaxIoHeader));
    consume(4);
    load_packet(size);  // the IOHeader is never compressed
    const fb::Buffer h(raw_.data(), size);
    const auto root = h.root("IOHE");
    if (!root) fail(header_at, "the IOHeader is not a valid FlatBuffer with identifier 'IOHE'");
    const auto comp = h.present(*root, 0) ? h.i32(*root, 0) : std::optional<std::int32_t>(0);
    if (!comp) fail(header_at, "the IOHeader's compression field lies outside it");
    if (*comp < 0 || *comp > 4) fail(header_at, fmt::format("unknown compression type {} in the IOHeader", *comp));
    compression_ = static_cast<Compression>(*comp);
    const auto table = h.present(*root, 1) ? h.i64(*root, 1) : std::optional<std::int64_t>(-1);
    if (!table) fail(header_at, "the IOHeader's dataTablePosition field lies outside it");
    table_pos_ = *table;
    if (table_pos_ >= 0 && static_cast<std::uint64_t>(table_pos_) < offset())
        fail(header_at, fmt::format("data table position {} lies inside the header", table_pos_));
    const auto xml = h.string(*root, 2);
    if (!xml) fail(header_at, "the IOHeader has no stream description (infoNode)");
    streams_ = parse_streams(*xml);

    const Aedat4Stream* chosen = nullptr;
    for (const auto& s : streams_)
        if (stream_id ? s.id == *stream_id : s.type == "EVTS") {
            chosen = &s;
            break;
        }
    if (!chosen) {
        std::string have;
        for (const auto& s : streams_) have += fmt::format("{}{} ({})", have.empty() ? "" : ", ", s.id, s.type);
        if (stream_id) fail(header_at, fmt::format("no stream {} in the description (streams: {})", *stream_id, have));
        fail(header_at, fmt::format("the file has no event stream (typeIdentifier EVTS); streams: {}",
                                    have.empty() ? "none" : have));
    }
    if (chosen->type != "EVTS")
        fail(header_at, fmt::format("stream {} holds '{}', not events (EVTS)", chosen->id, chosen->type));
    stream_id_ = chosen->id;
    set_address_limit(32768);  // int16 coordinates
    set_file_sensor(chosen->size);

    if (compression_ == Compression::lz4 || compression_ == Compression::lz4_high) {
        LZ4F_dctx* ctx = nullptr;
        if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)))
            throw std::bad_alloc();
        lz4_ = ctx;
    } else if (compression_ == Compression::zstd || compression_ == Compression::zstd_high) {
        zstd_ = ZSTD_createDCtx();
        if (!zstd_) throw std::bad_alloc();
    }
}

Aedat4Reader::~Aedat4Reader() {
    if (lz4_) LZ4F_freeDecompressionContext(static_cast<LZ4F_dctx*>(lz4_));
    if (zstd_) ZSTD_freeDCtx(static_cast<ZSTD_DCtx*>(zstd_));
}

// Copies the next `size` bytes of the file into raw_ (they may exceed the read buffer).
void Aedat4Reader::load_packet(std::size_t size) {
    raw_.resize(size);
    std::size_t got = 0;
    while (got < size) {
        const std::size_t avail = fill(std::min<std::size_t>(size - got, 1 << 16));
        if (avail == 0) fail(offset(), fmt::format("the file ends {} bytes into a {}-byte record", got, size));
        const std::size_t n = std::min(avail, size - got);
        std::memcpy(raw_.data() + got, data(), n);
        consume(n);
        got += n;
    }
}

void Aedat4Reader::decompress(const unsigned char* src, std::size_t size) {
    const auto grow = [&] {
        if (decoded_.size() >= kMaxPacketBytes)
            fail(packet_at_, fmt::format("packet decompresses to more than {} bytes", kMaxPacketBytes));
        decoded_.resize(std::min(kMaxPacketBytes, std::max<std::size_t>(decoded_.size() * 2, 1 << 16)));
    };
    decoded_size_ = 0;
    if (compression_ == Compression::none) {
        decoded_.resize(std::max(decoded_.size(), size));
        if (size > 0) std::memcpy(decoded_.data(), src, size);  // an empty vector's data() may be null
        decoded_size_ = size;
        return;
    }
    if (decoded_.empty()) grow();
    std::size_t in = 0;
    if (lz4_) {
        auto* ctx = static_cast<LZ4F_dctx*>(lz4_);
        LZ4F_resetDecompressionContext(ctx);
        std::size_t hint = 1;
        while (hint != 0) {
            if (decoded_size_ == decoded_.size()) grow();
            std::size_t dst_n = decoded_.size() - decoded_size_;
            std::size_t src_n = size - in;
            hint = LZ4F_decompress(ctx, decoded_.data() + decoded_size_, &dst_n, src + in, &src_n, nullptr);
            if (LZ4F_isError(hint))
                fail(packet_at_, fmt::format("bad LZ4 data in the packet: {}", LZ4F_getErrorName(hint)));
            in += src_n;
            decoded_size_ += dst_n;
            if (src_n == 0 && dst_n == 0 && decoded_size_ < decoded_.size())
                fail(packet_at_, "the packet's LZ4 frame is cut short");
        }
    } else {
        auto* ctx = static_cast<ZSTD_DCtx*>(zstd_);
        ZSTD_DCtx_reset(ctx, ZSTD_reset_session_only);
        std::size_t ret = 1;
        while (ret != 0 || in < size) {
            if (decoded_size_ == decoded_.size()) grow();
            ZSTD_outBuffer out{decoded_.data(), decoded_.size(), decoded_size_};
            ZSTD_inBuffer inb{src, size, in};
            ret = ZSTD_decompressStream(ctx, &out, &inb);
            if (ZSTD_isError(ret)) fail(packet_at_, fmt::format("bad ZSTD data in the packet: {}", ZSTD_getErrorName(ret)));
            if (inb.pos == in && out.pos == decoded_size_ && out.pos < out.size && ret != 0)
                fail(packet_at_, "the packet's ZSTD frame is cut short");
            in = inb.pos;
            decoded_size_ = out.pos;
        }
    }
    if (in != size) fail(packet_at_, fmt::format("{} bytes after the packet's compressed frame", size - in));
}

void Aedat4Reader::parse_event_packet() {
    // A size-prefixed FlatBuffer: uint32 size, then the buffer.
    if (decoded_size_ < 4) fail(packet_at_, "event packet shorter than its size prefix");
    const std::uint32_t n = fb::u32(decoded_.data());
    if (n > decoded_size_ - 4)
        fail(packet_at_, fmt::format("event packet's size prefix {} exceeds its {} bytes", n, decoded_size_ - 4));
    const fb::Buffer b(decoded_.data() + 4, n);
    const auto root = b.root("EVTS");
    if (!root) fail(packet_at_, "event packet is not a valid FlatBuffer with identifier 'EVTS'");
    if (!b.present(*root, 0)) {
        count_ = next_ = 0;
        return;
    }
    const auto v = b.vector(*root, 0, kEventBytes);
    if (!v) fail(packet_at_, "event packet's event vector lies outside the packet");
    events_ = b.at(v->data);
    count_ = static_cast<std::size_t>(v->length);
    next_ = 0;
}

// Reads packet headers until one of the event stream's; false at the end of the packets.
bool Aedat4Reader::next_packet() {
    for (;;) {
        packet_at_ = offset();
        if (table_pos_ >= 0 && packet_at_ >= static_cast<std::uint64_t>(table_pos_)) {
            if (packet_at_ > static_cast<std::uint64_t>(table_pos_))
                fail(static_cast<std::uint64_t>(table_pos_),
                     fmt::format("a packet overlaps the data table at byte {}", table_pos_));
            return false;
        }
        const std::size_t avail = fill(kPacketHeader);
        if (avail == 0) {
            if (table_pos_ >= 0)
                fail(packet_at_, fmt::format("the file ends before its data table at byte {} (cut short?)", table_pos_));
            return false;
        }
        if (avail < kPacketHeader)
            fail(packet_at_, fmt::format("the file ends inside a packet header ({} of 8 bytes)", avail));
        const auto id = static_cast<std::int32_t>(fb::u32(data()));
        const auto size = static_cast<std::int32_t>(fb::u32(data() + 4));
        if (size < 0 || static_cast<std::size_t>(size) > kMaxPacketBytes)
            fail(packet_at_ + 4, fmt::format("packet size {} is outside 0..{}", size, kMaxPacketBytes));
        const std::uint64_t end = packet_at_ + kPacketHeader + static_cast<std::uint64_t>(size);
        if (const auto total = bytes_total(); total && end > *total)
            fail(packet_at_ + 4, fmt::format("packet of {} bytes runs past the end of the file", size));
        if (table_pos_ >= 0 && end > static_cast<std::uint64_t>(table_pos_))
            fail(packet_at_ + 4, fmt::format("packet of {} bytes runs into the data table at byte {}", size, table_pos_));
        consume(kPacketHeader);
        const auto n = static_cast<std::size_t>(size);
        if (id != stream_id_) {
            ++other_packets_;
            for (std::size_t left = n; left > 0;) {
                const std::size_t a = fill(std::min<std::size_t>(left, 1 << 16));
                if (a == 0) fail(offset(), "the file ends inside a packet");
                const std::size_t k = std::min(a, left);
                consume(k);
                left -= k;
            }
            continue;
        }
        if (fill(n) >= n) {
            decompress(data(), n);
            consume(n);
        } else {
            load_packet(n);
            decompress(raw_.data(), n);
            if (raw_.capacity() > (std::size_t{4} << 20)) std::vector<unsigned char>().swap(raw_);
        }
        parse_event_packet();
        return true;
    }
}

bool Aedat4Reader::decode() {
    while (next_ == count_) {
        if (!next_packet()) return false;
    }
    const std::size_t k = std::min(count_ - next_, batch_room());
    const unsigned char* p = events_ + next_ * kEventBytes;
    for (std::size_t i = 0; i < k; ++i, p += kEventBytes) {
        std::int64_t t;
        std::int16_t x, y;
        std::memcpy(&t, p, 8);
        std::memcpy(&x, p + 8, 2);
        std::memcpy(&y, p + 10, 2);
        // Negative coordinates become huge unsigned ones and fail the sensor check.
        push(t, static_cast<std::uint32_t>(static_cast<std::int32_t>(x)),
             static_cast<std::uint32_t>(static_cast<std::int32_t>(y)), p[12] != 0, packet_at_);
    }
    next_ += k;
    return true;
}

}  // namespace evcorner::io
