#pragma once
// Reader for AEDAT 4.0 files (iniVation DV software, "#!AER-DAT4.0"). Layout, from the
// DV file-format documentation and the FlatBuffers schemas it names:
//   "#!AER-DAT4.0\r\n" (14 bytes)
//   IOHeader: a size-prefixed FlatBuffer (file identifier "IOHE") with the fields
//     0 compression (int32: 0 none, 1 LZ4, 2 LZ4 high, 3 ZSTD, 4 ZSTD high),
//     1 dataTablePosition (int64 byte offset of the trailing FileDataTable, -1 = none),
//     2 infoNode (string: XML describing each stream: under <node name="outInfo">, one
//       <node name="ID"> per stream with attr typeIdentifier ("EVTS", "FRME", "IMUS",
//       "TRIG") and a child <node name="info"> with attr sizeX / sizeY).
//   packets until the data table (or the end): int32 stream id, int32 size, then `size`
//     bytes: one LZ4 frame / ZSTD frame / raw bytes (per the IOHeader's compression) that
//     hold a size-prefixed FlatBuffer. For "EVTS" streams it is an EventPacket (identifier
//     "EVTS"), field 0 a vector of 16-byte structs
//     { int64 timestamp [us]; int16 x; int16 y; bool polarity; 3 bytes padding }.
// Only one event stream is decoded: the first EVTS stream the description names, unless
// another id is chosen; frames, IMU, triggers and other event streams are skipped
// unread. Timestamps are taken as stored (microseconds since the epoch for DV cameras).
// The sensor is the stream's sizeX x sizeY.
//
// Every FlatBuffer offset and vector length is checked against its buffer; packets are
// at most kMaxPacketBytes compressed and decompressed.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "evcorner/io/binary_reader.hpp"

namespace evcorner::io {

/// The first bytes of every AEDAT 4.0 file.
inline constexpr std::string_view kAedat4Magic = "#!AER-DAT4.0\r\n";

/// One stream the IOHeader's XML description declares.
struct Aedat4Stream {
    int id = 0;
    std::string type;  ///< typeIdentifier, e.g. "EVTS"
    std::optional<SensorSize> size;
};

class Aedat4Reader final : public BinaryReader {
public:
    enum class Compression : std::int32_t { none = 0, lz4 = 1, lz4_high = 2, zstd = 3, zstd_high = 4 };

    /// Largest packet accepted, compressed or decompressed.
    static constexpr std::size_t kMaxPacketBytes = std::size_t{64} << 20;

    /// Reads `file` from its first unread byte and parses its IOHeader; decodes event
    /// stream `stream_id` (nullopt: the first "EVTS" stream of the description). Reads
    /// front to back only, so a pipe works. Throws InputError.
    explicit Aedat4Reader(InputFile file, ReaderOptions options = {},
                          std::optional<int> stream_id = std::nullopt);
    /// Opens `path` and reads it as above. Throws InputError.
    explicit Aedat4Reader(std::string path, ReaderOptions options = {},
                          std::optional<int> stream_id = std::nullopt)
        : Aedat4Reader(InputFile(std::move(path)), std::move(options), stream_id) {}
    ~Aedat4Reader() override;
    Aedat4Reader(const Aedat4Reader&) = delete;
    Aedat4Reader& operator=(const Aedat4Reader&) = delete;

    [[nodiscard]] std::string_view format() const noexcept override { return "aedat4"; }
    [[nodiscard]] Compression compression() const noexcept { return compression_; }
    [[nodiscard]] const std::vector<Aedat4Stream>& streams() const noexcept { return streams_; }
    /// The stream whose events are returned.
    [[nodiscard]] int event_stream() const noexcept { return stream_id_; }
    /// The IOHeader's data table position (-1: none).
    [[nodiscard]] std::int64_t data_table_position() const noexcept { return table_pos_; }
    /// Packets of other streams skipped so far.
    [[nodiscard]] std::uint64_t other_packets() const noexcept { return other_packets_; }

private:
    bool decode() override;
    bool next_packet();
    void load_packet(std::size_t size);
    void decompress(const unsigned char* src, std::size_t size);
    void parse_event_packet();

    Compression compression_ = Compression::none;
    std::int64_t table_pos_ = -1;
    std::vector<Aedat4Stream> streams_;
    int stream_id_ = 0;
    std::uint64_t other_packets_ = 0;

    std::vector<unsigned char> raw_;      // a compressed packet larger than the read buffer
    std::vector<unsigned char> decoded_;  // the current packet's FlatBuffer
    std::size_t decoded_size_ = 0;
    const unsigned char* events_ = nullptr;  // into decoded_
    std::size_t count_ = 0;
    std::size_t next_ = 0;
    std::uint64_t packet_at_ = 0;

    void* lz4_ = nullptr;   // LZ4F_dctx*
    void* zstd_ = nullptr;  // ZSTD_DCtx*
};

}  // namespace evcorner::io
