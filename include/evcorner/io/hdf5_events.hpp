#pragma once
// HDF5 event files, through the HDF5 C library. Two layouts are read:
//   DSEC (Gehrig et al., RA-L 2021): datasets events/x, events/y, events/t, events/p and
//     an optional scalar dataset t_offset; time = t_offset + t, integer microseconds.
//     DSEC stores these Blosc/ZSTD-compressed: reading them needs the Blosc filter plugin
//     (Debian: hdf5-filter-plugin-blosc-serial; LZ4 / BZip2 / Bitshuffle come with
//     hdf5-filter-plugin); a missing plugin is an error that names the package.
//   event_utils (Stoffregen et al., "Reducing the sim-to-real gap", ECCV 2020, and the
//     h5 files of its tools): events/xs, events/ys, events/ts, events/ps, ts in SECONDS
//     as floating point (converted once to microseconds, rounded to the nearest; an
//     integer ts is taken as microseconds), ps 0/1, -1/+1 or bool (> 0 = ON), and the
//     root attribute sensor_resolution = (height, width).
// Integer x / y / p of any width are converted by HDF5; sensor size from the root
// attributes width / height (written by Hdf5Writer) or sensor_resolution.
// Read in chunks of kChunk events per dataset: memory is constant.
//
// The writer writes the DSEC layout: events/{x,y} uint16, events/p uint8, events/t
// int64 (microseconds after t_offset), t_offset int64 (the first event's time),
// extendible chunked datasets, optionally compressed; root attributes width / height
// when the sensor size is known; with scores, events/score float64 (read back by the
// reader, from any numeric events/score dataset of a DSEC-layout file).
//
// Errors name the file and the event index; where HDF5 tells the file address of the
// data (contiguous storage, or the chunk holding the event), also that byte offset.
// Failures give HDF5's reason (the system's error message where there is one, else the
// innermost entry of HDF5's error stack); HDF5's own printing of its error stack is
// switched off for the process the first time a reader or writer is made.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evcorner/io/event_checks.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::io {

/// The first 8 bytes of every HDF5 file (at offset 0, or 512, 1024, ... with a user block).
inline constexpr std::string_view kHdf5Magic = "\x89HDF\r\n\x1a\n";

class Hdf5Reader final : public EventReader {
public:
    enum class Layout { dsec, event_utils };
    static constexpr std::size_t kChunk = std::size_t{1} << 16;

    /// Opens `path` (a regular file) and finds its layout. Throws InputError.
    explicit Hdf5Reader(std::string path, ReaderOptions options = {});
    ~Hdf5Reader() override;
    Hdf5Reader(const Hdf5Reader&) = delete;
    Hdf5Reader& operator=(const Hdf5Reader&) = delete;

    std::size_t read(std::span<Event> out) override;
    [[nodiscard]] std::span<const SkipRun> skipped_in_batch() const noexcept override { return skips_.batch(); }
    /// events/score (DSEC layout), when the file has it.
    [[nodiscard]] std::span<const double> scores_in_batch() const noexcept override {
        return has_score_ ? std::span<const double>(scores_.data(), batch_n_) : std::span<const double>();
    }
    [[nodiscard]] std::uint64_t skipped() const noexcept override { return skips_.total(); }
    [[nodiscard]] std::optional<SensorSize> sensor() const noexcept override { return sensor_; }
    [[nodiscard]] std::string_view format() const noexcept override { return "hdf5"; }
    [[nodiscard]] const std::string& name() const noexcept override { return name_; }
    /// Progress in bytes, estimated as the fraction of events read times the file size.
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept override;
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() const noexcept override { return file_size_; }

    [[nodiscard]] Layout layout() const noexcept { return layout_; }
    /// The events the datasets hold.
    [[nodiscard]] std::uint64_t declared_events() const noexcept { return total_; }

private:
    struct Impl;
    void load_chunk();
    [[noreturn]] void fail_at(std::uint64_t index, int dataset, const std::string& reason) const;

    std::unique_ptr<Impl> impl_;
    std::string name_;
    ReaderOptions options_;
    Layout layout_ = Layout::dsec;
    std::optional<SensorSize> sensor_;
    std::uint32_t limit_w_ = kMaxSensorSide, limit_h_ = kMaxSensorSide;
    std::optional<std::uint64_t> file_size_;
    std::uint64_t total_ = 0;
    std::int64_t t_offset_ = 0;

    // The current chunk: events [chunk_start_, chunk_start_ + chunk_n_).
    std::vector<std::int32_t> x_, y_, p_;
    std::vector<std::int64_t> t_;
    std::vector<double> ts_, s_;
    bool has_score_ = false;
    std::vector<double> scores_;  // the last batch's
    std::size_t batch_n_ = 0;
    std::uint64_t chunk_start_ = 0;
    std::size_t chunk_n_ = 0, next_ = 0;

    std::int64_t last_t_ = INT64_MIN;
    SkipLog skips_;
    std::exception_ptr error_;
};

class Hdf5Writer final : public EventWriter {
public:
    struct Options {
        std::optional<SensorSize> sensor;
        /// 0: none; 1: deflate (built into HDF5); 32001: Blosc with ZSTD (needs the plugin).
        int filter = 0;
        std::size_t chunk_events = std::size_t{1} << 14;
        /// events/score (float64), one per event: write(events, scores).
        bool with_score = false;
    };
    /// Whether HDF5 can use filter `id` (built in, or a plugin it finds).
    static bool filter_available(int id);

    /// Creates `path` (a regular file, written under a temporary name until close();
    /// pending_file.hpp). Throws OutputError.
    explicit Hdf5Writer(std::string path, Options options);
    explicit Hdf5Writer(std::string path) : Hdf5Writer(std::move(path), Options{}) {}
    ~Hdf5Writer() override;  ///< without close(): no file under the name
    void write(std::span<const Event> events) override;
    void write(std::span<const Event> events, std::span<const double> scores) override;
    /// The size written as the root attributes width / height at close().
    void set_sensor(SensorSize size) override;
    void close() override;
    [[nodiscard]] const std::string& name() const noexcept override { return name_; }

private:
    struct Impl;
    void flush();
    void write_events(std::span<const Event> events, std::span<const double> scores);

    std::unique_ptr<Impl> impl_;
    std::string name_;
    Options options_;
    std::vector<std::uint16_t> x_, y_;
    std::vector<std::uint8_t> p_;
    std::vector<std::int64_t> t_;
    std::vector<double> s_;
    std::uint64_t written_ = 0;
    std::optional<std::int64_t> t_offset_;
    bool closed_ = false;
};

}  // namespace evcorner::io
