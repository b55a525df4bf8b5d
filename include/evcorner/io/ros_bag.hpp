#pragma once
// Reading the events of ROS bags: ROS 2 bags (rosbag2 folders with metadata.yaml, their
// SQLite `.db3` files, MCAP `.mcap` files) and ROS 1 bags (format 2.0 `.bag` files).
//
// Containers (each read by evcorner's own code, from the format's documentation):
//   rosbag2  SQLite 3 database (Debian's libsqlite3): tables topics(id, name, type,
//            serialization_format, ...) and messages(id, topic_id, timestamp, data); the
//            topic's messages are read in row-id order (the order they were recorded).
//   mcap     "\x89MCAP0\r\n", records (opcode u8, length u64), Schema / Channel /
//            Message records, in Chunks stored uncompressed, LZ4 frame or ZSTD; the
//            summary section (Schema, Channel, Statistics) gives the topics and counts,
//            else they come from a pass over the file. Messages are read in file order.
//   rosbag   "#ROSBAG V2.0\n", records (header fields name=value, data); Chunks stored
//            none / bz2 / lz4 (LZ4 frame), Connection records (topic, type), the index at
//            index_pos (connections, chunk infos with per-connection counts); without
//            an index (a recording cut short) the connections come from a pass over it.
// A rosbag2 folder is read through the files metadata.yaml names (relative_file_paths),
// else every .db3 / .mcap in it, in name order, one after the other.
//
// Messages (CDR, little-endian, for ROS 2 and MCAP channels encoded "cdr"; ROS 1
// serialisation for ROS 1 bags and MCAP channels encoded "ros1"):
//   event_camera_msgs/EventPacket: std_msgs/Header, uint32 height, uint32 width,
//     uint64 seq, uint64 time_base, string encoding, bool/uint8 is_bigendian,
//     uint8[] events, where `encoding` is
//       "evt3"        Prophesee EVT 3.0 words (evt3_reader.hpp); the payloads,
//                     concatenated, are one stream; time = the sensor's, time_base unused
//       "libcaer"     8-byte events {uint32 data, int32 ts}: x = data>>17 & 0x7FFF,
//                     y = data>>2 & 0x7FFF, polarity = data>>1 & 1;
//                     t = time_base/1000 + ts [us], + 2^31 us after a roll-over inside
//                     the packet (ts jumping back by more than 2^30 us)
//       "libcaer_cmp" 16-bit words, code = w>>12: 0 time high (t bits 23..12),
//                     1 time low (bits 11..0), 2 x (w & 0x7FF), 3 y (w & 0x7FF,
//                     polarity bit 11: one event at x, y), 4 vector base y (polarity
//                     bit 11), 5 vector (bits 7..0: events at base y + i; base += 8);
//                     the state starts at 0 in every packet; t = time_base/1000 + time
//   dvs_msgs/EventArray: std_msgs/Header, uint32 height, uint32 width, Event[] with
//     Event = {uint16 x, uint16 y, time ts (sec, nsec), bool polarity}; t = ts in us.
// The sensor is the first message's width x height (options.sensor overrides it).
//
// A bag must be a regular file (or folder): the containers are read by seeking. Its
// messages are read one by one; memory holds one message, or one chunk (at most
// kMaxChunkBytes decompressed). Damage is an error naming the file and the byte offset
// (or, in a compressed chunk or SQLite, the message's index), never raw bytes.

#include <cstdint>
#include <exception>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/io/event_checks.hpp"
#include "evcorner/io/event_reader.hpp"

namespace evcorner::io {

inline constexpr std::string_view kSqliteMagic{"SQLite format 3\0", 16};
inline constexpr std::string_view kMcapMagic = "\x89MCAP0\r\n";
inline constexpr std::string_view kRosbag1Magic = "#ROSBAG V2.0\n";

/// The largest chunk (MCAP or ROS 1), compressed or decompressed, and message accepted.
inline constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 30;

/// One topic of a bag.
struct BagTopic {
    std::string name;
    std::string type;           ///< e.g. "event_camera_msgs/msg/EventPacket"
    std::string serialization;  ///< "cdr" or "ros1"
    std::uint64_t messages = 0;
    /// A type evcorner reads events from (EventPacket, EventArray).
    [[nodiscard]] bool events() const noexcept;
};

/// "rosbag2" (SQLite), "mcap" or "rosbag" (ROS 1) when `head` starts with that
/// container's magic bytes, else empty.
std::string_view detect_bag_format(std::string_view head) noexcept;
/// `s` for a message or a listing: printable ASCII kept, other bytes as \xNN.
std::string escape_bytes(std::string_view s);
/// Whether `format` names a bag format (rosbag2, mcap, rosbag).
bool is_bag_format(std::string_view format) noexcept;

namespace detail {
class BagSource;
}

class BagReader final : public EventReader {
public:
    /// Reads the events of `options.topic`, or of the bag's one event topic. Throws
    /// InputError (naming the topics) when the topic is unknown, not of an event type,
    /// or when several event topics exist and none is named.
    BagReader(std::unique_ptr<detail::BagSource> source, ReaderOptions options);
    ~BagReader() override;
    BagReader(const BagReader&) = delete;
    BagReader& operator=(const BagReader&) = delete;

    std::size_t read(std::span<Event> out) override;
    [[nodiscard]] std::span<const SkipRun> skipped_in_batch() const noexcept override { return skips_.batch(); }
    [[nodiscard]] std::uint64_t skipped() const noexcept override { return skips_.total(); }
    [[nodiscard]] std::optional<SensorSize> sensor() const noexcept override { return sensor_; }
    [[nodiscard]] std::string_view format() const noexcept override;
    [[nodiscard]] const std::string& name() const noexcept override;
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept override;
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() const noexcept override;

    /// Every topic of the bag, with its type and message count.
    [[nodiscard]] const std::vector<BagTopic>& topics() const noexcept;
    /// The topic whose events are read.
    [[nodiscard]] const BagTopic& topic() const noexcept { return topic_; }
    /// The first message's encoding ("evt3", "libcaer", "libcaer_cmp"; "" for EventArray).
    [[nodiscard]] const std::string& encoding() const noexcept { return encoding_; }
    /// Messages read so far.
    [[nodiscard]] std::uint64_t messages() const noexcept { return messages_; }

    // The decoding steps (public for the decoders' sinks; not for callers).
    struct Impl;

private:
    bool next_message();
    void decode_some();

    std::unique_ptr<detail::BagSource> source_;
    ReaderOptions options_;
    BagTopic topic_;
    std::string encoding_;
    std::optional<SensorSize> sensor_;
    std::unique_ptr<Impl> impl_;
    SkipLog skips_;
    std::uint64_t messages_ = 0;
    std::exception_ptr error_;
    bool done_ = false;
};

/// Opens a bag: a rosbag2 folder, or a .db3 / .mcap / .bag file, told by its magic
/// bytes; `format` ("auto", "rosbag2", "mcap", "rosbag") must agree with them. Throws
/// InputError.
std::unique_ptr<BagReader> open_bag_reader(const std::string& path, ReaderOptions options = {},
                                           std::string_view format = "auto");

/// Bag readers over bytes in memory (the fuzz targets): `format` "rosbag2" (an SQLite
/// image), "mcap" or "rosbag". Throws InputError.
std::unique_ptr<BagReader> open_bag_bytes(std::span<const unsigned char> bytes, std::string_view format,
                                          ReaderOptions options = {}, std::string name = "<memory>");

}  // namespace evcorner::io
