// ROS 1 bags, format 2.0 (wiki.ros.org/Bags/Format/2.0): "#ROSBAG V2.0\n", then records
//   u32 header_len, header = fields (u32 field_len, "name=value", value binary),
//   u32 data_len, data
// with the field "op" giving the kind:
//   0x03 bag header  index_pos u64, conn_count u32, chunk_count u32 (data: padding)
//   0x05 chunk       compression ("none", "bz2", "lz4"), size u32 (decompressed);
//                    data: the records (connections, messages) compressed
//   0x07 connection  conn u32, topic; data: the connection header (fields: type, ...)
//   0x02 message     conn u32, time u64; data: the serialised message
//   0x04 index data, 0x06 chunk info (ver, chunk_pos, start_time, end_time, count;
//                    data: count x (conn u32, messages u32))
// The index at index_pos (connections and chunk infos) gives the topics and counts; a
// bag without one (a recording cut short) gets them from a pass over its chunks.

#include <fmt/format.h>
#include <map>

#include "record_bag.hpp"
#include "evcorner/io/byte_order.hpp"

namespace evcorner::io::detail {

namespace {

constexpr std::uint64_t kMagicSize = 13;
constexpr std::uint32_t kMaxHeader = 1 << 20;

// The fields of a record header.
class Fields {
public:
    // False when the fields are not well formed.
    bool parse(std::span<const unsigned char> h) {
        items_.clear();
        std::size_t p = 0;
        while (p < h.size()) {
            if (h.size() - p < 4) return false;
            const std::uint32_t n = load_le32(h.data() + p);
            p += 4;
            if (n > h.size() - p) return false;
            const std::string_view f(reinterpret_cast<const char*>(h.data() + p), n);
            p += n;
            const auto eq = f.find('=');
            if (eq == std::string_view::npos) return false;
            items_.emplace_back(f.substr(0, eq), f.substr(eq + 1));
        }
        return true;
    }
    [[nodiscard]] std::optional<std::string_view> get(std::string_view name) const {
        for (const auto& [k, v] : items_)
            if (k == name) return v;
        return std::nullopt;
    }
    template <class T>
    [[nodiscard]] std::optional<T> num(std::string_view name) const {
        const auto v = get(name);
        if (!v || v->size() != sizeof(T)) return std::nullopt;
        const auto* p = reinterpret_cast<const unsigned char*>(v->data());
        if constexpr (sizeof(T) == 1) return static_cast<T>(p[0]);
        if constexpr (sizeof(T) == 4) return static_cast<T>(load_le32(p));
        if constexpr (sizeof(T) == 8) return static_cast<T>(load_le64(p));
        return std::nullopt;
    }

private:
    std::vector<std::pair<std::string_view, std::string_view>> items_;
};

class Ros1Bag final : public RecordBag {
public:
    Ros1Bag(std::unique_ptr<ByteSource> bytes, std::string name)
        : RecordBag(std::move(bytes), std::move(name), kMagicSize) {
        unsigned char magic[kMagicSize] = {};
        const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(size_, kMagicSize));
        b_->read_at(0, n, magic);
        if (std::string_view(reinterpret_cast<const char*>(magic), n) != kRosbag1Magic)
            fail(0, n < kMagicSize ? "the file ends inside the '#ROSBAG V2.0' line: it is cut short"
                                   : "not a ROS 1 bag (it must start with '#ROSBAG V2.0\\n')");
        // The bag header record comes first.
        std::uint64_t pos = kMagicSize;
        Top r = read_top(pos);
        if (r.op != 0x03) fail(kMagicSize, fmt::format("the first record is op 0x{:02x}, not the bag header (0x03)", r.op));
        const auto index = fields_.num<std::uint64_t>("index_pos");
        if (!index) fail(kMagicSize, "the bag header has no 8-byte index_pos field");
        data_start_ = pos;
        // index_pos 0: the recording was not closed; past the end: the file is cut short.
        if (*index >= data_start_ && *index < size_ && read_index(*index)) {
            end_ = *index;
        } else {
            end_ = size_;
            scan();
            if (conns_.empty() && scan_error_) std::rethrow_exception(scan_error_);
        }
        std::map<std::string, std::size_t> at;
        for (const auto& [id, c] : conns_) {
            const auto [it, fresh] = at.emplace(c.topic, topics_.size());
            if (fresh) topics_.push_back({c.topic, c.type, "ros1", 0});
            const auto k = counts_.find(id);
            if (k != counts_.end()) topics_[it->second].messages += k->second;
        }
        restart();
    }

    void select(const std::string& topic) override { select_channels(conns_, topic); }
    [[nodiscard]] std::string_view format() const noexcept override { return "rosbag"; }

private:
    struct Conn {
        std::string topic;
        std::string type;
    };
    struct Top {
        std::uint8_t op = 0;
        std::uint64_t at = 0;       // the record's offset
        std::uint64_t data_at = 0;  // its data's offset
        std::uint32_t data_len = 0;
    };

    // The record at `pos` (its header parsed into fields_); pos moves past it.
    Top read_top(std::uint64_t& pos) {
        Top r;
        r.at = pos;
        if (size_ - pos < 4) fail(pos, "the file ends inside a record's header length: it is cut short");
        unsigned char n4[4];
        b_->read_at(pos, 4, n4);
        const std::uint32_t hlen = load_le32(n4);
        if (hlen > kMaxHeader || hlen > size_ - pos - 4)
            fail(pos, fmt::format("a record header of {} bytes runs past the end of the file ({} bytes) or {} bytes: "
                                  "it is cut short or damaged", hlen, size_, kMaxHeader));
        header_.resize(hlen);
        b_->read_at(pos + 4, hlen, header_.data());
        if (!fields_.parse(header_)) fail(pos + 4, "a record header whose fields are not 'name=value' entries");
        const auto op = fields_.num<std::uint8_t>("op");
        if (!op) fail(pos + 4, "a record header without a one-byte 'op' field");
        r.op = *op;
        const std::uint64_t dl_at = pos + 4 + hlen;
        if (size_ - dl_at < 4) fail(dl_at, "the file ends inside a record's data length: it is cut short");
        b_->read_at(dl_at, 4, n4);
        r.data_len = load_le32(n4);
        r.data_at = dl_at + 4;
        if (r.data_len > size_ - r.data_at)
            fail(dl_at, fmt::format("a record's {} data bytes run past the end of the file ({} bytes): it is cut short",
                                    r.data_len, size_));
        pos = r.data_at + r.data_len;
        return r;
    }

    // A connection record (header in fields_, data = the connection header).
    void add_conn(std::span<const unsigned char> data, std::uint64_t at) {
        const auto id = fields_.num<std::uint32_t>("conn");
        const auto topic = fields_.get("topic");
        if (!id || !topic) fail(at, "a connection record without 'conn' and 'topic' fields");
        Fields ch;
        if (!ch.parse(data)) fail(at, "a connection header whose fields are not 'name=value' entries");
        conns_.try_emplace(*id, Conn{std::string(*topic), std::string(ch.get("type").value_or(""))});
    }

    // The connections and chunk infos at index_pos; false when they cannot be read.
    bool read_index(std::uint64_t pos) {
        try {
            std::vector<unsigned char> data;
            while (pos < size_) {
                const Top r = read_top(pos);
                if (r.op != 0x07 && r.op != 0x06) return false;
                data.resize(r.data_len);
                b_->read_at(r.data_at, data.size(), data.data());
                if (r.op == 0x07) {
                    add_conn(data, r.at);
                } else {
                    const auto count = fields_.num<std::uint32_t>("count");
                    if (!count || std::uint64_t{*count} * 8 > data.size()) return false;
                    for (std::uint32_t i = 0; i < *count; ++i)
                        counts_[load_le32(data.data() + 8 * i)] += load_le32(data.data() + 8 * i + 4);
                }
            }
        } catch (const InputError&) {
            conns_.clear();
            counts_.clear();
            return false;
        }
        return !conns_.empty();
    }

    void scan() {
        conns_.clear();
        counts_.clear();
        count_records();
    }

    // One record; true while there are records. Sets msg_ for a selected message.
    bool step() override {
        if (in_chunk_) {
            if (chunk_pos_ < chunk_.size()) {
                const std::size_t at = chunk_pos_;
                const std::size_t left = chunk_.size() - at;
                if (left < 4) chunk_fail(at, "the chunk ends inside a record's header length");
                const std::uint32_t hlen = load_le32(chunk_.data() + at);
                if (hlen > left - 4) chunk_fail(at, fmt::format("a record header of {} bytes runs past the chunk", hlen));
                if (!fields_.parse({chunk_.data() + at + 4, hlen}))
                    chunk_fail(at + 4, "a record header whose fields are not 'name=value' entries");
                const auto op = fields_.num<std::uint8_t>("op");
                if (!op) chunk_fail(at + 4, "a record header without a one-byte 'op' field");
                const std::size_t dl = at + 4 + hlen;
                if (chunk_.size() - dl < 4) chunk_fail(dl, "the chunk ends inside a record's data length");
                const std::uint32_t dlen = load_le32(chunk_.data() + dl);
                if (dlen > chunk_.size() - dl - 4)
                    chunk_fail(dl, fmt::format("a record's {} data bytes run past the chunk", dlen));
                chunk_pos_ = dl + 4 + dlen;
                record(*op, {chunk_.data() + dl + 4, dlen}, at, dl + 4, true);
                return true;
            }
            in_chunk_ = false;
        }
        if (pos_ >= end_) return false;
        const Top r = read_top(pos_);
        switch (r.op) {
            case 0x05:
                load_chunk(r);
                return true;
            case 0x02:
            case 0x07:
                if (r.data_len > kMaxChunkBytes) fail(r.at, "a record larger than evcorner reads");
                rec_.resize(r.data_len);
                b_->read_at(r.data_at, rec_.size(), rec_.data());
                record(r.op, rec_, r.at, r.data_at, false);
                return true;
            default:
                return true;
        }
    }

    // A message or connection record: header in fields_, `data` at `data_at` (a file
    // offset, or one in the chunk).
    void record(std::uint8_t op, std::span<const unsigned char> data, std::uint64_t at, std::uint64_t data_at,
                bool in_chunk) {
        if (op == 0x07) {
            if (counting_) {
                try {
                    add_conn(data, in_chunk ? chunk_at_ : at);
                } catch (const InputError&) {
                }
            }
            return;
        }
        if (op != 0x02) return;
        const auto conn = fields_.num<std::uint32_t>("conn");
        if (!conn) {
            if (in_chunk) chunk_fail(static_cast<std::size_t>(at), "a message record without a 4-byte 'conn' field");
            fail(at, "a message record without a 4-byte 'conn' field");
        }
        if (counting_) {
            ++counts_[*conn];
            return;
        }
        if (!selected_.contains(*conn)) return;
        found(data, data_at, in_chunk);
    }

    void load_chunk(const Top& r) {
        const auto method = fields_.get("compression");
        const auto size = fields_.num<std::uint32_t>("size");
        if (!method || !size) fail(r.at, "a chunk record without 'compression' and 4-byte 'size' fields");
        chunk_method_ = std::string(*method);
        chunk_at_ = r.at;
        chunk_data_at_ = r.data_at;
        chunk_plain_ = chunk_method_ == "none";
        if (r.data_len > kMaxChunkBytes || *size > kMaxChunkBytes)
            fail(r.at, fmt::format("a chunk of {} bytes ({} decompressed): more than evcorner reads", r.data_len, *size));
        if (chunk_plain_) {
            if (*size != r.data_len)
                fail(r.at, fmt::format("an uncompressed chunk of {} bytes declares size {}", r.data_len, *size));
            chunk_.resize(r.data_len);
            b_->read_at(r.data_at, chunk_.size(), chunk_.data());
        } else {
            if (chunk_method_ != "bz2" && chunk_method_ != "lz4")
                fail(r.at, fmt::format("chunk compression '{}' is not supported (none, bz2 and lz4 are)",
                                       escaped(chunk_method_)));
            raw_.resize(r.data_len);
            b_->read_at(r.data_at, raw_.size(), raw_.data());
            const std::string err = decompress(chunk_method_, raw_, chunk_, *size);
            if (!err.empty()) fail(r.data_at, fmt::format("the {} chunk cannot be decompressed: {}", chunk_method_, err));
        }
        chunk_pos_ = 0;
        in_chunk_ = true;
    }

    std::uint64_t end_ = 0;
    std::map<std::uint32_t, Conn> conns_;
    std::map<std::uint32_t, std::uint64_t> counts_;

    Fields fields_;
    std::vector<unsigned char> header_;
};

}  // namespace

std::unique_ptr<BagSource> open_rosbag1(std::unique_ptr<ByteSource> bytes, std::string name) {
    return std::make_unique<Ros1Bag>(std::move(bytes), std::move(name));
}

}  // namespace evcorner::io::detail
