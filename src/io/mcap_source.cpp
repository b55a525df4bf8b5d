// MCAP, read from the MCAP format specification (mcap.dev/spec): "\x89MCAP0\r\n", then
// records (opcode u8, content length u64, content) until the DataEnd record, a summary
// section, the Footer and the magic again. Strings are u32-length-prefixed, integers
// little-endian. The records used:
//   0x03 Schema     id u16, name, encoding, data (u32 length)
//   0x04 Channel    id u16, schema_id u16, topic, message_encoding, metadata
//   0x05 Message    channel_id u16, sequence u32, log_time u64, publish_time u64, data (the rest)
//   0x06 Chunk      message_start_time u64, message_end_time u64, uncompressed_size u64,
//                   uncompressed_crc u32, compression ("", "lz4", "zstd"), records (u64 length)
//   0x0B Statistics message_count u64, schema_count u16, channel_count u32,
//                   attachment_count u32, metadata_count u32, chunk_count u32,
//                   message_start_time u64, message_end_time u64,
//                   channel_message_counts (u32 byte length, then u16 id -> u64 count)
//   0x02 Footer     summary_start u64, summary_offset_start u64, summary_crc u32
//   0x0F DataEnd
// Topics and counts come from the summary section when it has Channels and Statistics,
// else from a pass over the data section. CRCs are not checked.

#include <fmt/format.h>
#include <map>

#include "record_bag.hpp"
#include "evcorner/io/byte_order.hpp"

namespace evcorner::io::detail {

namespace {

constexpr std::size_t kRecordHeader = 9;
constexpr std::size_t kMessageFields = 2 + 4 + 8 + 8;

class McapBag final : public RecordBag {
public:
    McapBag(std::unique_ptr<ByteSource> bytes, std::string name) : RecordBag(std::move(bytes), std::move(name), 8) {
        unsigned char magic[8] = {};
        const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(size_, 8));
        b_->read_at(0, n, magic);
        if (std::string_view(reinterpret_cast<const char*>(magic), n) != kMcapMagic)
            throw InputError(name_, InputError::Unit::byte, 0,
                             n < 8 ? "the file ends inside the MCAP magic bytes: it is cut short"
                                   : "not an MCAP file (it must start with '\\x89MCAP0\\r\\n')");
        if (!read_summary()) scan();
        // No channel before the damage: the damage is the news.
        if (channels_.empty() && scan_error_) std::rethrow_exception(scan_error_);
        build_topics();
    }

    void select(const std::string& topic) override { select_channels(channels_, topic); }
    [[nodiscard]] std::string_view format() const noexcept override { return "mcap"; }

private:
    struct Channel {
        std::string topic;
        std::uint16_t schema = 0;
        std::string encoding;
    };

    void restart() override {
        RecordBag::restart();
        ended_ = false;
    }

    void add_schema(std::span<const unsigned char> c) {
        FieldReader f(c.data(), c.size());
        const std::uint16_t id = f.u16();
        schemas_[id] = std::string(f.str32());
    }
    void add_channel(std::span<const unsigned char> c) {
        FieldReader f(c.data(), c.size());
        const std::uint16_t id = f.u16();
        Channel ch;
        ch.schema = f.u16();
        ch.topic = std::string(f.str32());
        ch.encoding = std::string(f.str32());
        channels_.try_emplace(id, std::move(ch));
    }

    // The summary section's Schemas, Channels and Statistics; false when the file has
    // none, or they cannot be read (then a pass over the data section stands in).
    bool read_summary() {
        constexpr std::uint64_t kFooter = kRecordHeader + 20;
        if (size_ < 8 + kFooter + 8) return false;
        unsigned char tail[kFooter + 8];
        b_->read_at(size_ - sizeof tail, sizeof tail, tail);
        if (std::string_view(reinterpret_cast<const char*>(tail + kFooter), 8) != kMcapMagic) return false;
        if (tail[0] != 0x02 || load_le64(tail + 1) != 20) return false;
        const std::uint64_t start = load_le64(tail + kRecordHeader);
        const std::uint64_t end = size_ - sizeof tail;
        if (start < 8 || start >= end || end - start > kMaxChunkBytes) return false;
        std::vector<unsigned char> s(static_cast<std::size_t>(end - start));
        b_->read_at(start, s.size(), s.data());
        bool stats = false;
        try {
            std::size_t p = 0;
            while (p < s.size()) {
                if (s.size() - p < kRecordHeader) return false;
                const std::uint8_t op = s[p];
                const std::uint64_t len = load_le64(s.data() + p + 1);
                if (len > s.size() - p - kRecordHeader) return false;
                const std::span<const unsigned char> c(s.data() + p + kRecordHeader, static_cast<std::size_t>(len));
                if (op == 0x03) add_schema(c);
                if (op == 0x04) add_channel(c);
                if (op == 0x0B) {
                    FieldReader f(c.data(), c.size());
                    f.skip(8 + 2 + 4 + 4 + 4 + 4 + 8 + 8);
                    const std::uint32_t bytes = f.u32();
                    FieldReader m(f.bytes(bytes).data(), bytes);
                    while (m.left() > 0) {
                        const std::uint16_t id = m.u16();
                        counts_[id] = m.u64();
                    }
                    stats = true;
                }
                p += kRecordHeader + static_cast<std::size_t>(len);
            }
        } catch (const Truncated&) {
            return false;
        }
        return stats && !channels_.empty();
    }

    // A pass over the data section for the channels and their message counts. Damage
    // stops it quietly: reading the events reports it where it lies.
    void scan() {
        channels_.clear();
        schemas_.clear();
        counts_.clear();
        count_records();
        restart();
    }

    void build_topics() {
        std::map<std::string, std::size_t> at;
        for (const auto& [id, c] : channels_) {
            const auto [it, fresh] = at.emplace(c.topic, topics_.size());
            if (fresh) {
                const auto s = schemas_.find(c.schema);
                topics_.push_back({c.topic, s == schemas_.end() ? std::string() : s->second, c.encoding, 0});
            }
            const auto n = counts_.find(id);
            if (n != counts_.end()) topics_[it->second].messages += n->second;
        }
    }

    // One record of a chunk, or of the data section; true while there are records.
    // Sets msg_ (and current_) when the record is a message of a selected channel.
    bool step() override {
        if (in_chunk_) {
            if (chunk_pos_ < chunk_.size()) {
                const std::size_t at = chunk_pos_;
                if (chunk_.size() - at < kRecordHeader) chunk_fail(at, "the chunk ends inside a record header");
                const std::uint8_t op = chunk_[at];
                const std::uint64_t len = load_le64(chunk_.data() + at + 1);
                if (len > chunk_.size() - at - kRecordHeader)
                    chunk_fail(at, fmt::format("a record of {} bytes runs past the end of the chunk", len));
                chunk_pos_ = at + kRecordHeader + static_cast<std::size_t>(len);
                record(op, {chunk_.data() + at + kRecordHeader, static_cast<std::size_t>(len)}, at + kRecordHeader, true);
                return true;
            }
            in_chunk_ = false;
        }
        if (ended_) return false;
        if (size_ - pos_ < kRecordHeader)
            fail(pos_, pos_ == size_ ? "the file ends without a DataEnd or Footer record: it is cut short"
                                     : "the file ends inside a record header: it is cut short");
        unsigned char h[kRecordHeader];
        b_->read_at(pos_, kRecordHeader, h);
        const std::uint8_t op = h[0];
        const std::uint64_t len = load_le64(h + 1);
        const std::uint64_t at = pos_;
        if (len > size_ - pos_ - kRecordHeader)
            fail(at, fmt::format("a record (opcode 0x{:02x}) of {} bytes runs past the end of the file ({} bytes): "
                                 "it is cut short", op, len, size_));
        pos_ += kRecordHeader + len;
        switch (op) {
            case 0x02:
            case 0x0F:
                ended_ = true;
                return false;
            case 0x03:
            case 0x04:
            case 0x05:
                if (len > kMaxChunkBytes) fail(at, fmt::format("a record of {} bytes: more than evcorner reads", len));
                if (op == 0x05 && !counting_ && len >= 2) {
                    // Only a selected channel's messages are read whole.
                    unsigned char id[2];
                    b_->read_at(at + kRecordHeader, 2, id);
                    if (!selected_.contains(load_le16(id))) return true;
                }
                rec_.resize(static_cast<std::size_t>(len));
                b_->read_at(at + kRecordHeader, rec_.size(), rec_.data());
                record(op, rec_, at + kRecordHeader, false);
                return true;
            case 0x06:
                load_chunk(at, len);
                return true;
            default:
                return true;
        }
    }

    // A Schema, Channel or Message record at `at` (a file offset, or an offset in the chunk).
    void record(std::uint8_t op, std::span<const unsigned char> c, std::uint64_t at, bool in_chunk) {
        try {
            if (op == 0x03) add_schema(c);
            if (op == 0x04) add_channel(c);
            if (op != 0x05) return;
            FieldReader f(c.data(), c.size());
            const std::uint16_t channel = f.u16();
            f.skip(kMessageFields - 2);
            if (counting_) {
                ++counts_[channel];
                return;
            }
            if (!selected_.contains(channel)) return;
            found(c.subspan(kMessageFields), at + kMessageFields, in_chunk);
        } catch (const Truncated& t) {
            const char* what = op == 0x03 ? "Schema" : op == 0x04 ? "Channel" : "Message";
            const std::string reason = fmt::format("the {} record ends inside its fields", what);
            if (in_chunk) chunk_fail(static_cast<std::size_t>(at) + t.at, reason);
            fail(at + t.at, reason);
        }
    }

    void load_chunk(std::uint64_t at, std::uint64_t len) {
        const std::uint64_t c = at + kRecordHeader;
        constexpr std::size_t kFixed = 8 + 8 + 8 + 4;
        if (len < kFixed + 4 + 8) fail(at, fmt::format("a Chunk record of {} bytes: too short for its fields", len));
        unsigned char h[kFixed + 4];
        b_->read_at(c, sizeof h, h);
        const std::uint64_t usize = load_le64(h + 16);
        const std::uint32_t clen = load_le32(h + kFixed);
        if (clen > 16 || kFixed + 4 + clen + 8 > len)
            fail(c + kFixed, fmt::format("a Chunk's compression name of {} bytes: not a valid chunk", clen));
        unsigned char rest[16 + 8];
        b_->read_at(c + kFixed + 4, clen + 8, rest);
        chunk_method_ = std::string(reinterpret_cast<const char*>(rest), clen);
        const std::uint64_t rlen = load_le64(rest + clen);
        const std::uint64_t data_at = c + kFixed + 4 + clen + 8;
        if (rlen > len - (kFixed + 4 + clen + 8))
            fail(data_at - 8, fmt::format("a Chunk's records length {} runs past the end of the chunk", rlen));
        if (rlen > kMaxChunkBytes || usize > kMaxChunkBytes)
            fail(at, fmt::format("a chunk of {} bytes ({} decompressed): more than evcorner reads ({})", rlen, usize,
                                 kMaxChunkBytes));
        chunk_at_ = at;
        chunk_data_at_ = data_at;
        chunk_plain_ = chunk_method_.empty();
        if (chunk_plain_) {
            if (usize != rlen)
                fail(at, fmt::format("an uncompressed chunk of {} bytes declares {} uncompressed bytes", rlen, usize));
            chunk_.resize(static_cast<std::size_t>(rlen));
            b_->read_at(data_at, chunk_.size(), chunk_.data());
        } else {
            if (chunk_method_ != "lz4" && chunk_method_ != "zstd")
                fail(c + kFixed, fmt::format("chunk compression '{}' is not supported (lz4 and zstd are)",
                                             escaped(chunk_method_)));
            raw_.resize(static_cast<std::size_t>(rlen));
            b_->read_at(data_at, raw_.size(), raw_.data());
            const std::string err = decompress(chunk_method_, raw_, chunk_, static_cast<std::size_t>(usize));
            if (!err.empty()) fail(data_at, fmt::format("the {} chunk cannot be decompressed: {}", chunk_method_, err));
        }
        chunk_pos_ = 0;
        in_chunk_ = true;
    }

    std::map<std::uint16_t, std::string> schemas_;
    std::map<std::uint16_t, Channel> channels_;
    std::map<std::uint16_t, std::uint64_t> counts_;
    bool ended_ = false;
};

}  // namespace

std::unique_ptr<BagSource> open_mcap(std::unique_ptr<ByteSource> bytes, std::string name) {
    return std::make_unique<McapBag>(std::move(bytes), std::move(name));
}

}  // namespace evcorner::io::detail
