#pragma once
// Reader for comma-separated event files: one event per line with the columns t, x, y,
// p in the order ReaderOptions::csv_columns gives, or the file's header row names
// (e.g. "x,y,p,t" as Metavision and tonic write; "timestamp", "ts", "polarity", "pol"
// are recognised too), else t,x,y,p. t is in ReaderOptions::csv_time_unit; without one,
// seconds when the first time has a decimal point, else microseconds (docs/formats.md,
// "Times": rounding to the nearest microsecond, and the times refused);
// p is 1 or 0 (-1 also means OFF). Spaces around fields, '#' comment lines, blank lines
// and CRLF are accepted. A column named `score` holds a number per event (corners written
// with their scores), given by scores_in_batch(). Errors name the file and the 1-based line.

#include <array>
#include <exception>
#include <string>
#include <vector>

#include "evcorner/io/event_checks.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/line_source.hpp"

namespace evcorner::io {

class CsvReader final : public EventReader {
public:
    /// Reads `file` from its first unread byte. Throws InputError (also for bad options).
    explicit CsvReader(InputFile file, ReaderOptions options = {});
    /// Opens `path` ("-" = standard input). Throws InputError (also for bad options).
    explicit CsvReader(std::string path, ReaderOptions options = {})
        : CsvReader(InputFile(std::move(path)), std::move(options)) {}

    std::size_t read(std::span<Event> out) override;
    [[nodiscard]] std::span<const SkipRun> skipped_in_batch() const noexcept override { return skips_.batch(); }
    /// A `score` column's values (named in the header row or ReaderOptions::csv_columns).
    [[nodiscard]] std::span<const double> scores_in_batch() const noexcept override {
        return has_score_ ? std::span<const double>(scores_.data(), batch_n_) : std::span<const double>();
    }
    [[nodiscard]] std::uint64_t skipped() const noexcept override { return skips_.total(); }
    [[nodiscard]] std::optional<SensorSize> sensor() const noexcept override { return sensor_; }
    /// "csv", or "csv+gzip" (zstd, bzip2, xz) for a compressed file.
    [[nodiscard]] std::string_view format() const noexcept override { return format_; }
    [[nodiscard]] const std::string& name() const noexcept override { return lines_.file().name(); }
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept override { return lines_.file().consumed(); }
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() const noexcept override { return lines_.file().size(); }

private:
    enum Field : std::uint8_t { kT, kX, kY, kP, kIgnore, kScore };
    void set_columns(const std::string& spec, bool from_header);
    bool parse(const char* b, const char* e, Event& ev, const char*& why);
    enum class Tri : std::uint8_t { unknown, no, yes };

    LineSource lines_;
    std::string format_;
    ReaderOptions options_;
    std::optional<SensorSize> sensor_;
    std::vector<Field> columns_;
    TimeUnit time_unit_ = TimeUnit::us;  // as given (csv_time_unit), else us
    bool unit_given_ = false;
    Tri float_time_ = Tri::unknown;  // without a unit given: whether the first time had a decimal point
    bool columns_known_ = false;
    bool has_score_ = false;
    double score_ = 0;            // the line being parsed
    std::vector<double> scores_;  // the last batch's
    std::size_t batch_n_ = 0;
    bool seen_row_ = false;  // a header row may only come first
    std::int64_t last_t_ = INT64_MIN;
    SkipLog skips_;
    std::exception_ptr error_;
};

}  // namespace evcorner::io
