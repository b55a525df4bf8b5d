// ROS bag reader: the topic chosen, each message's EventPacket / EventArray fields, the
// events of its payload decoded (evt3, libcaer, libcaer_cmp, EventArray) and checked.
// Layouts in evcorner/io/ros_bag.hpp; the containers are in rosbag2_sqlite.cpp,
// mcap_source.cpp and rosbag1_source.cpp.

#include "evcorner/io/ros_bag.hpp"

#include <algorithm>
#include <bit>
#include <climits>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>

#include "bag_source.hpp"
#include "evcorner/error.hpp"
#include "evcorner/io/byte_order.hpp"
#include "evt3_decoder.hpp"

namespace evcorner::io {

namespace {

constexpr std::string_view kEventPacket = "event_camera_msgs/msg/EventPacket";
constexpr std::string_view kEventPacket1 = "event_camera_msgs/EventPacket";
constexpr std::string_view kEventArray = "dvs_msgs/msg/EventArray";
constexpr std::string_view kEventArray1 = "dvs_msgs/EventArray";

bool is_packet(std::string_view type) { return type == kEventPacket || type == kEventPacket1; }
bool is_array(std::string_view type) { return type == kEventArray || type == kEventArray1; }

// A message field that cannot be read: where in the payload, and why.
struct MsgError {
    std::size_t at;
    std::string reason;
};

// The fields of a message in CDR (aligned to their size from the end of the 4-byte
// encapsulation header) or in ROS 1 serialisation (packed).
class MsgCursor {
public:
    MsgCursor(std::span<const unsigned char> m, bool cdr) : p_(m.data()), size_(m.size()), cdr_(cdr) {
        if (cdr_) {
            need(4, "the CDR encapsulation header");
            if (p_[0] != 0 || (p_[1] != 1 && p_[1] != 0))
                throw MsgError{0, fmt::format("unknown CDR encapsulation {:02x} {:02x} (expected 00 01, little-endian CDR)",
                                              p_[0], p_[1])};
            if (p_[1] == 0) throw MsgError{0, "big-endian CDR (encapsulation 00 00) is not supported"};
            pos_ = origin_ = 4;
        }
    }
    void align(std::size_t n) {
        if (!cdr_) return;
        const std::size_t pad = (n - (pos_ - origin_) % n) % n;
        need(pad, "alignment padding");
        pos_ += pad;
    }
    std::uint8_t u8(const char* what) {
        need(1, what);
        return p_[pos_++];
    }
    std::uint16_t u16(const char* what) {
        align(2);
        need(2, what);
        const auto v = load_le16(p_ + pos_);
        pos_ += 2;
        return v;
    }
    std::uint32_t u32(const char* what) {
        align(4);
        need(4, what);
        const auto v = load_le32(p_ + pos_);
        pos_ += 4;
        return v;
    }
    std::uint64_t u64(const char* what) {
        align(8);
        need(8, what);
        const auto v = load_le64(p_ + pos_);
        pos_ += 8;
        return v;
    }
    std::string_view str(const char* what) {
        const std::uint32_t n = u32(what);
        need(n, what);
        std::string_view s(reinterpret_cast<const char*>(p_ + pos_), n);
        pos_ += n;
        if (cdr_ && !s.empty() && s.back() == '\0') s.remove_suffix(1);  // CDR counts the NUL
        return s;
    }
    // A std_msgs/Header: ROS 1 has a seq before the stamp.
    void header() {
        if (!cdr_) u32("the header's seq");
        u32("the header's stamp");
        u32("the header's stamp");
        str("the header's frame_id");
    }
    void need(std::size_t n, const char* what) const {
        if (n > size_ - pos_)
            throw MsgError{pos_, fmt::format("the message ends inside {} ({} bytes needed, {} left)", what, n,
                                             size_ - pos_)};
    }
    [[nodiscard]] std::size_t pos() const noexcept { return pos_; }
    [[nodiscard]] std::size_t size() const noexcept { return size_; }
    [[nodiscard]] const unsigned char* data() const noexcept { return p_; }
    void seek(std::size_t pos) noexcept { pos_ = pos; }

private:
    const unsigned char* p_;
    std::size_t size_;
    std::size_t pos_ = 0;
    std::size_t origin_ = 0;
    bool cdr_;
};

enum class Kind { evt3, libcaer, libcaer_cmp, dvs };

std::string topic_list(const std::vector<BagTopic>& topics) {
    std::string s;
    for (const BagTopic& t : topics)
        s += fmt::format("{}{} ({}, {} messages)", s.empty() ? "" : ", ", detail::escaped(t.name),
                         detail::escaped(t.type), t.messages);
    return s.empty() ? "none" : s;
}

}  // namespace

bool BagTopic::events() const noexcept { return is_packet(type) || is_array(type); }

std::string_view detect_bag_format(std::string_view head) noexcept {
    if (head.starts_with(kSqliteMagic)) return "rosbag2";
    if (head.starts_with(kMcapMagic)) return "mcap";
    if (head.starts_with(kRosbag1Magic)) return "rosbag";
    return {};
}

std::string escape_bytes(std::string_view s) { return detail::escaped(s); }

bool is_bag_format(std::string_view format) noexcept {
    return format == "rosbag2" || format == "mcap" || format == "rosbag";
}

// ---------------------------------------------------------------- decoding

struct BagReader::Impl {
    detail::BagSource* src = nullptr;
    std::string topic;
    bool skip_invalid = false;
    bool keyword_spelling = false;
    SkipLog* skips = nullptr;
    std::optional<SensorSize> sensor;
    std::uint32_t lw = kMaxSensorSide, lh = kMaxSensorSide;

    // the batch
    std::span<Event> out;
    std::size_t n = 0;
    std::int64_t last_t = INT64_MIN;

    // the current message
    detail::BagMessage msg;
    bool have_msg = false;
    bool cdr = true;
    bool array = false;
    Kind kind = Kind::evt3;
    std::span<const unsigned char> ev;  // the events' bytes
    std::size_t ev_at = 0;              // their payload offset
    std::size_t cursor = 0;             // bytes of ev done (dvs: payload offset of the next event)
    std::uint64_t left = 0;             // dvs: events left in the message
    std::int64_t tb_us = 0;

    detail::Evt3Decoder evt3;
    // libcaer: roll-overs inside the packet
    std::int64_t caer_epoch = 0;
    std::int64_t caer_prev = -1;
    // libcaer_cmp state, reset per packet
    std::uint32_t high = 0, low = 0, x = 0, ybase = 0;
    bool pol = false;
    std::uint32_t pend_mask = 0, pend_y = 0;
    std::uint64_t pend_at = 0;

    [[nodiscard]] bool full() const noexcept { return n == out.size(); }

    [[noreturn]] void fail(std::uint64_t at, const std::string& reason) const {
        if (msg.offset)
            throw InputError(src->name(), InputError::Unit::byte, *msg.offset + at,
                             fmt::format("message {} of topic {}: {}", msg.index + 1, detail::escaped(topic), reason));
        const std::string what = fmt::format("message {} of topic {} ({}), payload byte {}: {}", msg.index + 1,
                                             detail::escaped(topic), msg.where, at, reason);
        if (msg.chunk_at) throw InputError(src->name(), InputError::Unit::byte, *msg.chunk_at, what);
        throw InputError(src->name(), what);
    }

    void push(std::int64_t t, std::uint32_t ex, std::uint32_t ey, bool on, std::uint64_t at) {
        if (ex >= lw || ey >= lh) [[unlikely]] {
            if (!skip_invalid) fail(at, outside_sensor_message(ex, ey, sensor, keyword_spelling));
            skips->skip(n);
            return;
        }
        if (t < last_t) [[unlikely]]
            fail(at, backwards_message(last_t, t));
        last_t = t;
        out[n++] = Event{t, static_cast<std::uint16_t>(ex), static_cast<std::uint16_t>(ey), static_cast<std::uint8_t>(on)};
    }

    // Parses the message's fields up to its events; the sensor size when `first`.
    void start(const std::string& type, bool first, std::string& encoding, std::optional<SensorSize>& file_sensor) {
        try {
            MsgCursor c(msg.data, cdr);
            c.header();
            const std::uint32_t height = c.u32("height");
            const std::uint32_t width = c.u32("width");
            if (first && width >= 1 && height >= 1 && width <= kMaxSensorSide && height <= kMaxSensorSide)
                file_sensor = SensorSize{static_cast<int>(width), static_cast<int>(height)};
            if (is_array(type)) {
                array = true;
                kind = Kind::dvs;
                left = c.u32("the number of events");
                // Each event takes at least 13 bytes: a count beyond the message is damage.
                if (left > (c.size() - c.pos()) / 13)
                    throw MsgError{c.pos() - 4, fmt::format("{} events do not fit the {} bytes left in the message",
                                                            left, c.size() - c.pos())};
                cursor = c.pos();
                ev = msg.data;
                if (first) encoding.clear();
                return;
            }
            c.u64("seq");
            const std::uint64_t time_base = c.u64("time_base");
            const std::string_view enc = c.str("encoding");
            const bool big = c.u8("is_bigendian") != 0;
            const std::uint32_t size = c.u32("the events' length");
            c.need(size, "the events");
            ev = {c.data() + c.pos(), size};
            ev_at = c.pos();
            cursor = 0;
            if (enc == "evt3")
                kind = Kind::evt3;
            else if (enc == "libcaer")
                kind = Kind::libcaer;
            else if (enc == "libcaer_cmp")
                kind = Kind::libcaer_cmp;
            else
                throw MsgError{0, fmt::format("encoding '{}' is not supported (evt3, libcaer and libcaer_cmp are)",
                                              detail::escaped(enc))};
            if (first)
                encoding = std::string(enc);
            else if (enc != encoding)
                throw MsgError{0, fmt::format("encoding '{}' after '{}' in earlier messages", detail::escaped(enc),
                                              detail::escaped(encoding))};
            if (big && kind != Kind::evt3) throw MsgError{0, "is_bigendian is set: big-endian payloads are not supported"};
            tb_us = static_cast<std::int64_t>(time_base / 1000);
            if (kind == Kind::evt3 && ev.size() % 2 != 0)
                throw MsgError{ev_at, fmt::format("EVT 3.0 payload of {} bytes: not whole 16-bit words", ev.size())};
            if (kind == Kind::libcaer && ev.size() % 8 != 0)
                throw MsgError{ev_at, fmt::format("libcaer payload of {} bytes: not whole 8-byte events", ev.size())};
            if (kind == Kind::libcaer_cmp && ev.size() % 2 != 0)
                throw MsgError{ev_at, fmt::format("libcaer_cmp payload of {} bytes: not whole 16-bit words", ev.size())};
            caer_epoch = 0;
            caer_prev = -1;
            high = low = x = ybase = 0;
            pol = false;
            pend_mask = 0;
        } catch (const MsgError& e) {
            fail(e.at, e.reason);
        }
    }

    struct Evt3Sink {
        Impl& r;
        std::size_t ev_at;
        [[nodiscard]] bool full() const noexcept { return r.full(); }
        void push(std::int64_t t, std::uint32_t ex, std::uint32_t ey, bool on, std::uint64_t at) {
            r.push(t, ex, ey, on, ev_at + at);
        }
        [[noreturn]] void fail(std::uint64_t at, const char* reason) const { r.fail(ev_at + at, reason); }
    };

    // Decodes events of the current message until the batch is full or the message ends.
    void decode() {
        switch (kind) {
            case Kind::evt3: {
                Evt3Sink sink{*this, ev_at};
                if (!evt3.drain(sink)) return;
                cursor += evt3.decode(ev.data() + cursor, (ev.size() - cursor) / 2, cursor, sink) * 2;
                if (cursor == ev.size() && evt3.drain(sink)) have_msg = false;
                return;
            }
            case Kind::libcaer: {
                while (cursor < ev.size() && !full()) {
                    const unsigned char* p = ev.data() + cursor;
                    const std::uint32_t d = load_le32(p);
                    const auto ts = static_cast<std::int32_t>(load_le32(p + 4));
                    if (ts < 0) fail(ev_at + cursor, fmt::format("negative libcaer timestamp {}", ts));
                    // A jump back of more than 2^30 us inside the packet: the 31-bit counter rolled over.
                    if (caer_prev >= 0 && caer_prev - ts > (std::int64_t{1} << 30)) caer_epoch += std::int64_t{1} << 31;
                    caer_prev = ts;
                    push(tb_us + caer_epoch + ts, d >> 17 & 0x7FFF, d >> 2 & 0x7FFF, (d >> 1) & 1, ev_at + cursor);
                    cursor += 8;
                }
                if (cursor == ev.size()) have_msg = false;
                return;
            }
            case Kind::libcaer_cmp:
                decode_cmp();
                return;
            case Kind::dvs:
                decode_dvs();
                return;
        }
    }

    bool drain_cmp() {
        while (pend_mask != 0) {
            if (full()) return false;
            const int bit = std::countr_zero(pend_mask);
            pend_mask &= pend_mask - 1;
            push(tb_us + (std::int64_t{high} << 12 | low), x, pend_y + static_cast<std::uint32_t>(bit), pol, pend_at);
        }
        return true;
    }

    void decode_cmp() {
        if (!drain_cmp()) return;
        while (cursor < ev.size() && !full()) {
            const std::uint32_t w = load_le16(ev.data() + cursor);
            const std::uint64_t at = ev_at + cursor;
            cursor += 2;
            switch (w >> 12) {
                case 0: high = w & 0xFFF; break;
                case 1: low = w & 0xFFF; break;
                case 2: x = w & 0x7FF; break;
                case 3: push(tb_us + (std::int64_t{high} << 12 | low), x, w & 0x7FF, (w >> 11) & 1, at); break;
                case 4:
                    ybase = w & 0x7FF;
                    pol = (w >> 11) & 1;
                    break;
                case 5:
                    pend_mask = w & 0xFF;
                    pend_y = ybase;
                    pend_at = at;
                    ybase += 8;
                    if (!drain_cmp()) return;
                    break;
                default:
                    fail(at, fmt::format("unknown libcaer_cmp word code {} (word 0x{:04x})", w >> 12, w));
            }
        }
        if (cursor == ev.size() && drain_cmp()) have_msg = false;
    }

    void decode_dvs() {
        try {
            MsgCursor c(msg.data, cdr);
            c.seek(cursor);
            while (left > 0 && !full()) {
                const std::size_t at = c.pos();
                const std::uint16_t ex = c.u16("an event's x");
                const std::uint16_t ey = c.u16("an event's y");
                const std::uint32_t sec = c.u32("an event's time");
                const std::uint32_t nsec = c.u32("an event's time");
                const std::uint8_t p = c.u8("an event's polarity");
                if (nsec >= 1'000'000'000u) fail(at, fmt::format("an event's nanoseconds {} are not below 10^9", nsec));
                if (p > 1) fail(at, fmt::format("polarity {} (expected 0 or 1)", p));
                // CDR: time.sec is a signed int32.
                const std::int64_t s = cdr ? std::int64_t{static_cast<std::int32_t>(sec)} : std::int64_t{sec};
                push(s * 1'000'000 + nsec / 1000, ex, ey, p != 0, at);
                --left;
                cursor = c.pos();
            }
        } catch (const MsgError& e) {
            fail(e.at, e.reason);
        }
        if (left == 0) have_msg = false;
    }
};

BagReader::BagReader(std::unique_ptr<detail::BagSource> source, ReaderOptions options)
    : source_(std::move(source)), options_(std::move(options)), impl_(std::make_unique<Impl>()) {
    const auto& topics = source_->topic_types();
    const BagTopic* chosen = nullptr;
    if (!options_.topic.empty()) {
        for (const BagTopic& t : topics)
            if (t.name == options_.topic) chosen = &t;
        if (!chosen)
            throw InputError(source_->name(), fmt::format("no topic '{}' in the bag (topics: {})",
                                                          detail::escaped(options_.topic), topic_list(source_->topics())));
        if (!chosen->events())
            throw InputError(source_->name(),
                             fmt::format("topic {} has type {}, not an event type (event_camera_msgs/EventPacket or "
                                         "dvs_msgs/EventArray)", detail::escaped(chosen->name),
                                         detail::escaped(chosen->type)));
    } else {
        std::size_t count = 0;
        for (const BagTopic& t : topics)
            if (t.events()) {
                if (!chosen) chosen = &t;
                ++count;
            }
        if (count == 0)
            throw InputError(source_->name(), fmt::format("the bag has no topic of an event type (event_camera_msgs/"
                                                          "EventPacket or dvs_msgs/EventArray); topics: {}",
                                                          topic_list(source_->topics())));
        if (count > 1)
            throw InputError(source_->name(), fmt::format("the bag has {} event topics: choose one with {} "
                                                          "(topics: {})", count, option_spelling(options_, "--topic"),
                                                          topic_list(source_->topics())));
    }
    topic_ = *chosen;
    impl_->src = source_.get();
    impl_->topic = topic_.name;
    impl_->skip_invalid = options_.skip_invalid;
    impl_->keyword_spelling = options_.keyword_spelling;
    impl_->skips = &skips_;
    impl_->cdr = topic_.serialization != "ros1";
    source_->select(topic_.name);

    std::optional<SensorSize> from_file;
    if (source_->next(impl_->msg)) {
        ++messages_;
        impl_->have_msg = true;
        impl_->start(topic_.type, true, encoding_, from_file);
    }
    sensor_ = options_.sensor ? options_.sensor : from_file ? from_file : options_.fallback_sensor;
    impl_->sensor = sensor_;
    if (sensor_) {
        impl_->lw = static_cast<std::uint32_t>(sensor_->width);
        impl_->lh = static_cast<std::uint32_t>(sensor_->height);
    }
}

BagReader::~BagReader() = default;

std::string_view BagReader::format() const noexcept { return source_->format(); }
const std::string& BagReader::name() const noexcept { return source_->name(); }
std::uint64_t BagReader::bytes_consumed() const noexcept { return source_->bytes_consumed(); }
std::optional<std::uint64_t> BagReader::bytes_total() const noexcept { return source_->bytes_total(); }
const std::vector<BagTopic>& BagReader::topics() const noexcept { return source_->topics(); }

bool BagReader::next_message() {
    if (!source_->next(impl_->msg)) return false;
    ++messages_;
    impl_->have_msg = true;
    std::optional<SensorSize> unused;
    impl_->start(topic_.type, false, encoding_, unused);
    return true;
}

std::size_t BagReader::read(std::span<Event> out) {
    skips_.new_batch();
    if (error_) std::rethrow_exception(error_);
    if (done_ || out.empty()) return 0;
    Impl& m = *impl_;
    m.out = out;
    m.n = 0;
    try {
        while (m.n < out.size() && skips_.batch().size() < out.size()) {
            if (!m.have_msg && !next_message()) {
                done_ = true;
                break;
            }
            m.decode();
        }
    } catch (const InputError&) {
        error_ = std::current_exception();
        if (m.n == 0 && skips_.batch().empty()) throw;
    }
    return m.n;
}

// ---------------------------------------------------------------- opening

namespace {

namespace fs = std::filesystem;

// metadata.yaml's relative_file_paths entries, in order (empty when it lists none).
std::vector<std::string> listed_files(const fs::path& yaml) {
    std::ifstream in(yaml);
    std::vector<std::string> files;
    std::string line;
    bool in_list = false;
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const auto first = line.find_first_not_of(' ');
        if (first == std::string::npos) continue;
        const std::string_view l = std::string_view(line).substr(first);
        if (l.starts_with("relative_file_paths:")) {
            in_list = true;
            continue;
        }
        if (!in_list) continue;
        if (!l.starts_with("- ")) {
            in_list = false;
            continue;
        }
        std::string_view name = l.substr(2);
        while (!name.empty() && name.back() == ' ') name.remove_suffix(1);
        if (name.size() >= 2 && (name.front() == '\'' || name.front() == '"') && name.back() == name.front())
            name = name.substr(1, name.size() - 2);
        files.emplace_back(name);
    }
    return files;
}

std::unique_ptr<detail::BagSource> open_bag_file(const std::string& path, std::string_view format) {
    auto bytes = detail::open_file_bytes(path, "a ROS bag");
    unsigned char head[16] = {};
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(bytes->size(), sizeof head));
    bytes->read_at(0, n, head);
    const std::string_view kind = detect_bag_format({reinterpret_cast<const char*>(head), n});
    const std::string name = path;
    if (kind.empty())
        throw InputError(name, InputError::Unit::byte, 0,
                         fmt::format("not a ROS bag: it starts with '{}', not the SQLite, MCAP or ROS 1 bag magic bytes",
                                     detail::escaped({reinterpret_cast<const char*>(head), n})));
    const bool agrees = format == "auto" || format == kind || (format == "rosbag2" && kind == "mcap");
    if (!agrees)
        throw InputError(name, fmt::format("--format {} does not match the file, which is {}", format,
                                           kind == "rosbag2" ? "an SQLite (rosbag2) file"
                                           : kind == "mcap"  ? "an MCAP file"
                                                             : "a ROS 1 bag"));
    if (kind == "rosbag2") return detail::open_sqlite_bag(path);
    if (kind == "mcap") return detail::open_mcap(std::move(bytes), name);
    return detail::open_rosbag1(std::move(bytes), name);
}

}  // namespace

std::unique_ptr<BagReader> open_bag_reader(const std::string& path, ReaderOptions options, std::string_view format) {
    std::error_code ec;
    if (!fs::is_directory(path, ec)) return std::make_unique<BagReader>(open_bag_file(path, format), std::move(options));
    if (format != "auto" && format != "rosbag2" && format != "mcap")
        throw InputError(path, fmt::format("a folder is read as a rosbag2 bag, not as {}", format));
    const fs::path dir(path);
    std::vector<std::string> files;
    if (fs::exists(dir / "metadata.yaml", ec))
        for (const std::string& f : listed_files(dir / "metadata.yaml")) files.push_back((dir / f).string());
    if (files.empty()) {
        for (const auto& e : fs::directory_iterator(dir, ec)) {
            const auto ext = e.path().extension();
            if (e.is_regular_file() && (ext == ".db3" || ext == ".mcap")) files.push_back(e.path().string());
        }
        std::sort(files.begin(), files.end());
    }
    if (files.empty())
        throw InputError(path, "a folder with no bag files (no metadata.yaml listing them, no .db3 or .mcap file): "
                               "not a rosbag2 bag");
    std::vector<std::unique_ptr<detail::BagSource>> parts;
    for (const std::string& f : files) parts.push_back(open_bag_file(f, "auto"));
    if (parts.size() == 1) return std::make_unique<BagReader>(std::move(parts.front()), std::move(options));
    const std::string_view kind = parts.front()->format();
    return std::make_unique<BagReader>(detail::chain_bags(std::move(parts), path, kind), std::move(options));
}

std::unique_ptr<BagReader> open_bag_bytes(std::span<const unsigned char> bytes, std::string_view format,
                                          ReaderOptions options, std::string name) {
    std::unique_ptr<detail::BagSource> src;
    if (format == "rosbag2")
        src = detail::sqlite_bag_from_memory(bytes, std::move(name));
    else if (format == "mcap")
        src = detail::open_mcap(detail::memory_bytes(bytes), std::move(name));
    else if (format == "rosbag")
        src = detail::open_rosbag1(detail::memory_bytes(bytes), std::move(name));
    else
        throw std::invalid_argument("open_bag_bytes: unknown bag format " + std::string(format));
    return std::make_unique<BagReader>(std::move(src), std::move(options));
}

}  // namespace evcorner::io
