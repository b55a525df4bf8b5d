#pragma once
// What every event-file reader offers: events in file order, in batches, with
// constant memory. Formats differ; this contract does not.
//
// read(out) fills `out` and returns how many events it wrote; 0 means the end, once
// skipped_in_batch() is empty too. Bad input throws InputError naming the file and the
// position (line, or byte offset). Events decoded before the damage are returned first,
// the error is thrown by the next call, so callers keep everything that was valid.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::io {

/// The unit of a file's time values (ReaderOptions::csv_time_unit names one).
enum class TimeUnit : std::uint8_t { ns, us, ms, s };

struct ReaderOptions {
    /// Sensor size to validate events against; overrides the file's own metadata.
    std::optional<SensorSize> sensor;
    /// Skip events outside the sensor instead of failing; they are counted.
    bool skip_invalid = false;
    /// Sensor to validate against when neither `sensor` nor the file's metadata gives
    /// one (text, CSV, a DAT or RAW file without geometry). nullopt: validate only
    /// against what the format can encode, and sensor() reports nullopt.
    std::optional<SensorSize> fallback_sensor = kDavis240;
    /// CSV only: the column order, a comma-separated permutation of t, x, y, p (more
    /// names allowed, "_" ignores a column), e.g. "x,y,p,t". Empty: from the file's
    /// header row when it has one, else "t,x,y,p".
    std::string csv_columns;
    /// AEDAT 2.0 only: the camera that recorded the file, as a jAER chip name ("DVS128",
    /// "DAVIS240C", "DAVIS346", ...; see aedat2_reader.hpp), used instead of the header's
    /// "# AEChip:" line for the address layout and the sensor size. Empty: the header's.
    std::string aedat2_chip;
    /// The unit of the time values ("us", "ns", "ms" or "s") of CSV's t column and .npy /
    /// .mat time fields. Empty: the float-time rule (docs/formats.md, "Times"): floats are
    /// seconds (CSV: the first time has a decimal point), integers microseconds (.mat: us).
    std::string csv_time_unit;
    /// .npy only: the meaning of the 4 columns of a plain (N, 4) array, e.g. "x,y,p,t"
    /// ("_" ignores one). Empty: "t,x,y,p".
    std::string npy_columns;
    /// MATLAB .mat only: the variable holding the N x 4 events (empty: the only N x 4
    /// numeric one), and the meaning of its columns (empty: "x,y,p,t").
    std::string mat_var;
    std::string mat_columns;
    /// ROS bags only: the topic to read (ros_bag.hpp). Empty: the bag's one event topic.
    std::string topic;
    /// How messages name these options: as the CLI's flags ("--time-unit", "--size"), or
    /// as Python's keywords ("time_unit=", "sensor=") for the Python package.
    bool keyword_spelling = false;
};

/// The option `flag` ("--time-unit", "--size", "--skip-invalid", "--format", or a flag of
/// io::reader_option_infos()) as `o`'s messages spell it: "--time-unit", or "time_unit".
std::string option_spelling(const ReaderOptions& o, std::string_view flag);

/// `count` consecutive events skipped as outside the sensor, which stood just before
/// out[before] of the last read() (before == n: after the last one returned).
struct SkipRun {
    std::size_t before;
    std::uint64_t count;
};

class EventReader {
public:
    virtual ~EventReader() = default;

    virtual std::size_t read(std::span<Event> out) = 0;
    [[nodiscard]] virtual std::span<const SkipRun> skipped_in_batch() const noexcept = 0;
    /// The scores of the events the last read() returned, one each, for a file that holds
    /// them (corner files written with scores: text's fifth column, CSV's and .npy's
    /// `score`, HDF5's events/score); empty when it holds none.
    [[nodiscard]] virtual std::span<const double> scores_in_batch() const noexcept { return {}; }
    /// Events skipped so far.
    [[nodiscard]] virtual std::uint64_t skipped() const noexcept = 0;
    /// The sensor events are validated against (options, else file metadata), if known.
    [[nodiscard]] virtual std::optional<SensorSize> sensor() const noexcept = 0;
    /// A short name of the format, e.g. "ecd-text", "aedat2".
    [[nodiscard]] virtual std::string_view format() const noexcept = 0;
    /// The name to show in messages.
    [[nodiscard]] virtual const std::string& name() const noexcept = 0;
    /// Bytes of the file consumed so far, and its size when known (progress bars).
    [[nodiscard]] virtual std::uint64_t bytes_consumed() const noexcept = 0;
    [[nodiscard]] virtual std::optional<std::uint64_t> bytes_total() const noexcept = 0;
};

/// The whole stream into memory (tools and tests that need every event at once), read
/// by the contract: batches until one is empty with no skip runs. `after_batch(all)` is
/// called after each batch (a progress bar). Throws InputError.
template <class AfterBatch>
std::vector<Event> read_all_events(EventReader& reader, AfterBatch&& after_batch) {
    std::vector<Event> all;
    std::vector<Event> batch(std::size_t{1} << 16);
    for (;;) {
        const std::size_t n = reader.read(batch);
        if (n == 0 && reader.skipped_in_batch().empty()) return all;
        all.insert(all.end(), batch.begin(), batch.begin() + static_cast<std::ptrdiff_t>(n));
        after_batch(static_cast<const std::vector<Event>&>(all));
    }
}
inline std::vector<Event> read_all_events(EventReader& reader) {
    return read_all_events(reader, [](const std::vector<Event>&) {});
}

}  // namespace evcorner::io
