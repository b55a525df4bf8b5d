#pragma once
// Writer for AEDAT 4.0 files (iniVation DV), so that DV tools open evcorner's event and
// corner streams: the "#!AER-DAT4.0\r\n" line, an IOHeader (compression, no data table:
// dataTablePosition -1, and an XML description of one stream, id 0, typeIdentifier
// "EVTS", sizeX x sizeY), then packets of stream 0, each an EventPacket FlatBuffer
// (identifier "EVTS", 16-byte events { int64 t; int16 x; int16 y; bool polarity })
// in one LZ4 frame, or stored uncompressed. See aedat4_reader.hpp for the layout.
//
// The sensor size goes in the description. When none is given, the header is written
// with room to spare and rewritten at close() with the size given to set_sensor(), else
// the smallest holding every event (max x + 1, max y + 1); such a file must be seekable
// (not standard output). The file is complete under its name only after close().

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::io {

class Aedat4Writer final : public EventWriter {
public:
    enum class Compression { none, lz4 };

    struct Options {
        std::optional<SensorSize> sensor;
        Compression compression = Compression::lz4;
        /// Events per packet (DV's recorder writes a few thousand).
        std::size_t packet_events = 8192;
    };

    /// Creates `path` and writes the header. Throws OutputError.
    explicit Aedat4Writer(std::string path, Options options);
    explicit Aedat4Writer(std::string path) : Aedat4Writer(std::move(path), Options{}) {}
    ~Aedat4Writer() override;  ///< without close(): no file under the name
    /// Throws OutputError for coordinates an int16 cannot hold, or outside options.sensor.
    void write(std::span<const Event> events) override;
    /// The size to record (the header is rewritten at close() when it changes); every event
    /// written so far and after must lie inside it. Throws OutputError.
    void set_sensor(SensorSize size) override;
    void close() override;
    [[nodiscard]] const std::string& name() const noexcept override { return out_.name(); }

private:
    void flush_packet();

    Options options_;
    OutputFile out_;
    std::vector<unsigned char> packet_;  // the pending EventPacket FlatBuffer
    std::size_t pending_ = 0;
    std::vector<char> compressed_;
    int max_x_ = -1, max_y_ = -1;
    bool rewrite_header_ = false;  // the header's size is not final: rewrite it at close()
    bool closed_ = false;
};

}  // namespace evcorner::io
