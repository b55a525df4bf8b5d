#pragma once
// The detection pipeline: events from a reader, through any registered detector (on one
// thread, or split over several: parallel_detect.hpp), to sinks, batch by batch, with a
// summary. `evcorner detect` is this plus option parsing and printing; the bindings call
// the same functions.
//
//   run_detect(reader, options, sinks)   any EventReader in, any DetectSink out
//   detect_file(files, options)          paths in and out, as `evcorner detect` takes them
//
// Data flows one way: reader -> detector -> sinks. Every batch read is detected and
// written before the next one is (one thread), or before the error of a later read is
// raised (several threads: reading overlaps detection). An input error leaves the sinks
// unclosed and is rethrown: file outputs are then absent (never a partial result under
// the output's name), while a stream (standard output, a FIFO) has had the outputs of the
// events before it. With allow_damaged the run ends there instead: the sinks are closed,
// complete and valid for the events before the damage, and the summary names it.
// Detection time is measured around the detector's batch calls only; wall time around
// the whole run.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evcorner/detector_config.hpp"
#include "evcorner/event.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/io/text_writer.hpp"
#include "evcorner/nms.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::pipeline {

/// One detected batch as the sinks see it.
struct DetectedBatch {
    std::span<const Event> events;
    std::span<const std::uint8_t> is_corner;  ///< one flag per event
    std::span<const double> scores;           ///< one per event with DetectOptions::with_score, else empty
    std::span<const io::SkipRun> skips;       ///< events the reader skipped among these (--skip-invalid)
};

/// Where detected batches go.
class DetectSink {
public:
    virtual ~DetectSink() = default;
    virtual void write(const DetectedBatch& batch) = 0;
    /// After the last batch, or when the input stops at an error: completes the output.
    virtual void close() {}
};

/// The corner events, to any event writer (io/event_writer.hpp); with `with_score`, with
/// their scores (a writer opened with scores, and a run with DetectOptions::with_score).
class CornerEventSink final : public DetectSink {
public:
    explicit CornerEventSink(std::unique_ptr<io::EventWriter> out, bool with_score = false);
    void write(const DetectedBatch& batch) override;
    void close() override { out_->close(); }

private:
    std::unique_ptr<io::EventWriter> out_;
    bool with_score_;
    std::vector<Event> corners_;
    std::vector<double> scores_;
};

/// One line per input event: "1" a corner, "0" not (events the reader skipped: "0").
class MaskSink final : public DetectSink {
public:
    explicit MaskSink(const std::string& path) : out_(path) {}
    void write(const DetectedBatch& batch) override;
    void close() override { out_.close(); }

private:
    io::OutputFile out_;
};

/// The corner events (and their scores, with with_score) kept in memory.
class CollectSink final : public DetectSink {
public:
    void write(const DetectedBatch& batch) override;
    std::vector<Event> corners;
    std::vector<double> scores;
};

struct DetectOptions {
    DetectorConfig detector;     ///< the detector and its parameters (registry.hpp)
    int threads = 1;             ///< > 1: local detectors only (the registry says which)
    bool with_score = false;     ///< pass scores to the sinks (detectors with a score; one thread)
    bool allow_damaged = false;  ///< an input error ends the input (summary.damaged) instead of failing
    /// Asynchronous NMS after the detector (nms.hpp): the corners are the kept ones (with
    /// threads > 1 too: the part halo grows by its radius; output identical to one thread).
    std::optional<NmsParams> nms;
    std::size_t batch = std::size_t{1} << 16;  ///< events per read, 1..65536
    /// How error messages spell parameter keys and the options of this struct (with_score,
    /// threads, nms): "--with-score" on the command line, kIdentifierKeys in a binding.
    KeySpelling param_prefix;
};

/// After every batch written: how far the run is.
struct DetectProgress {
    std::uint64_t bytes_consumed = 0;
    std::optional<std::uint64_t> bytes_total;
    std::uint64_t events = 0;   ///< events detected and written so far
    std::uint64_t corners = 0;  ///< their corners
};
using ProgressFn = std::function<void(const DetectProgress&)>;

struct DetectSummary {
    std::string detector;
    SensorSize sensor;
    int threads = 1;
    std::uint64_t events = 0;
    std::uint64_t corners = 0;
    std::uint64_t skipped = 0;  ///< events outside the sensor skipped by the reader
    double detect_s = 0;        ///< time in the detector's batch calls (several threads: rounds that overlap reading and writing)
    double wall_s = 0;          ///< the whole run
    std::string damaged;        ///< with allow_damaged: the input error the run stopped at, else empty

    /// Percent of events that are not corners; NaN without events.
    [[nodiscard]] double reduction_percent() const noexcept;
    /// Detection time per event; NaN without events.
    [[nodiscard]] double ns_per_event() const noexcept;
};

/// Throws std::invalid_argument (a usage error) for an unknown detector, a parameter it
/// does not take or out of range, with_score on a detector without a score or with
/// threads > 1, nms on a detector without a score or with parameters out of range, threads outside 1..256 or on a detector that is not local (the message
/// says why, from the registry), a batch outside 1..65536.
void check_detect_options(const DetectOptions& options);

/// Runs the configured detector over every event of `reader` (sensor: reader.sensor(),
/// else `fallback`), each batch to every sink in order; closes the sinks at the end.
/// Throws as check_detect_options() does before reading anything; InputError from the
/// reader (sinks left unclosed; with allow_damaged it ends the run instead); InvalidEvent
/// for an event the detector cannot take; whatever a sink throws (sinks left unclosed).
DetectSummary run_detect(io::EventReader& reader, const DetectOptions& options, std::span<DetectSink* const> sinks,
                         const ProgressFn& progress = {}, SensorSize fallback = kDavis240);

/// Paths and formats, as `evcorner detect` takes them.
struct DetectFiles {
    std::string input;                ///< a file, or "-" for standard input
    std::string format = "auto";      ///< input format (io/open.hpp)
    io::ReaderOptions reader;         ///< sensor, --skip-invalid, CSV columns, ...
    std::string output = "-";         ///< corner events ("-": standard output; "" none)
    std::string to = "auto";          ///< output format; auto: from the extension
    std::string mask;                 ///< "" none
};

/// Opens the input and the outputs (after checking that no output is the input or
/// another output, that every output can be created, and that outputs which must seek
/// back are not streams), runs run_detect() and returns its summary. On any error the
/// output files are left absent (an existing file under the name is left as it was). Outputs are events in the
/// format `to` names (with_score: with their scores, io::kScoredOutputFormats), recording
/// the sensor size where the format has a field for it.
DetectSummary detect_file(const DetectFiles& files, const DetectOptions& options, const ProgressFn& progress = {});

}  // namespace evcorner::pipeline
