#pragma once
// What the bag reader (ros_bag.hpp) needs from a container: its topics, then the bytes of
// one topic's messages in order. Each container (rosbag2 SQLite, MCAP, ROS 1) is one
// BagSource; the byte sources below let the MCAP and ROS 1 containers read a file by
// seeking, or bytes in memory (the fuzz targets).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/error.hpp"
#include "evcorner/io/ros_bag.hpp"

namespace evcorner::io::detail {

/// One message of the chosen topic.
struct BagMessage {
    std::span<const unsigned char> data;
    /// 0-based among the topic's messages read.
    std::uint64_t index = 0;
    /// File offset of data[0] when the message lies in the file as stored (not in a
    /// compressed chunk, not in SQLite).
    std::optional<std::uint64_t> offset;
    /// Where the message is when it has no offset, e.g. "in the lz4 chunk at byte 4096".
    std::string where;
    /// File offset of the (compressed) chunk that holds it, when it has no offset.
    std::optional<std::uint64_t> chunk_at;
};

class BagSource {
public:
    virtual ~BagSource() = default;
    /// The topics with their message counts (which a container may count on the first call).
    [[nodiscard]] virtual const std::vector<BagTopic>& topics() const noexcept = 0;
    /// The topics' names, types and serialisations; the counts may not be filled in.
    [[nodiscard]] virtual const std::vector<BagTopic>& topic_types() const noexcept { return topics(); }
    /// Restricts next() to the messages of `topic` (one of topics()), from the start.
    virtual void select(const std::string& topic) = 0;
    /// The next message of the topic; false at the end. The bytes stay valid until the
    /// next call. Throws InputError.
    virtual bool next(BagMessage& m) = 0;
    [[nodiscard]] virtual std::string_view format() const noexcept = 0;
    [[nodiscard]] virtual const std::string& name() const noexcept = 0;
    [[nodiscard]] virtual std::uint64_t bytes_consumed() const noexcept = 0;
    [[nodiscard]] virtual std::optional<std::uint64_t> bytes_total() const noexcept = 0;
};

/// Random access to a file's (or a buffer's) bytes.
class ByteSource {
public:
    virtual ~ByteSource() = default;
    [[nodiscard]] virtual std::uint64_t size() const noexcept = 0;
    /// Copies n bytes at `offset` into `dst`; the caller checked offset + n <= size().
    /// Throws InputError on a read error.
    virtual void read_at(std::uint64_t offset, std::size_t n, unsigned char* dst) = 0;
    /// The bytes themselves when they are in memory (no copy needed), else empty.
    [[nodiscard]] virtual std::span<const unsigned char> memory() const noexcept { return {}; }
};

/// A regular file read with pread(). Throws InputError when `path` cannot be opened or
/// is not a regular file (a pipe, standard input), naming `what` ("an MCAP file").
std::unique_ptr<ByteSource> open_file_bytes(const std::string& path, std::string_view what);
/// Bytes in memory (not copied: they must outlive the source).
std::unique_ptr<ByteSource> memory_bytes(std::span<const unsigned char> bytes);

std::unique_ptr<BagSource> open_sqlite_bag(const std::string& path);
std::unique_ptr<BagSource> sqlite_bag_from_memory(std::span<const unsigned char> bytes, std::string name);
std::unique_ptr<BagSource> open_mcap(std::unique_ptr<ByteSource> bytes, std::string name);
std::unique_ptr<BagSource> open_rosbag1(std::unique_ptr<ByteSource> bytes, std::string name);
/// Several sources read one after the other (a rosbag2 folder of split files); topics
/// merged by name, their counts summed.
std::unique_ptr<BagSource> chain_bags(std::vector<std::unique_ptr<BagSource>> parts, std::string name,
                                      std::string_view format);

/// Little-endian fields of a record, each read checked against its end. A read past
/// the end throws Truncated, which the container turns into an InputError.
struct Truncated {
    std::size_t at;
};
class FieldReader {
public:
    FieldReader(const unsigned char* p, std::size_t size) : p_(p), size_(size) {}
    std::uint8_t u8() { return *take(1); }
    std::uint16_t u16();
    std::uint32_t u32();
    std::uint64_t u64();
    /// A u32-length-prefixed string.
    std::string_view str32();
    /// `n` bytes.
    std::span<const unsigned char> bytes(std::size_t n) {
        const unsigned char* b = take(n);
        return {b, n};
    }
    void skip(std::size_t n) { take(n); }
    [[nodiscard]] std::size_t pos() const noexcept { return pos_; }
    [[nodiscard]] std::size_t left() const noexcept { return size_ - pos_; }

private:
    const unsigned char* take(std::size_t n) {
        if (n > size_ - pos_) throw Truncated{pos_};
        const unsigned char* b = p_ + pos_;
        pos_ += n;
        return b;
    }
    const unsigned char* p_;
    std::size_t size_;
    std::size_t pos_ = 0;
};

/// A string shown in a message: printable ASCII kept, anything else escaped (\xNN).
std::string escaped(std::string_view s);

}  // namespace evcorner::io::detail

namespace evcorner::io::detail {

/// Decompresses `src` ("lz4": an LZ4 frame, "zstd", "bz2") into exactly `size` bytes
/// of `dst`. Returns an empty string, or why it failed (corrupt data, a size that
/// does not match, an unknown method).
std::string decompress(std::string_view method, std::span<const unsigned char> src, std::vector<unsigned char>& dst,
                       std::size_t size);

}  // namespace evcorner::io::detail
