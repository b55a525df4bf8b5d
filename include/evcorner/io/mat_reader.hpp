#pragma once
// MATLAB MAT-files (level 5, "MATLAB 5.0 MAT-file" header, compressed or not; and 7.3,
// which is HDF5 inside), read through libmatio: one numeric variable of N rows and 4
// columns, one event per row.
//
// - The variable: ReaderOptions::mat_var, else the only N x 4 real numeric variable in
//   the file (none, or several: an error that lists the candidates and names --mat-var).
// - The columns: ReaderOptions::mat_columns, a comma-separated order of x, y, p, t ("_"
//   ignores a column; the names of CSV's --csv-columns are accepted), default "x,y,p,t"
//   (the layout of the rpg_event_lifetime recordings).
// - Time: microseconds unless ReaderOptions::csv_time_unit names the unit ("s", "ms",
//   "ns"; then rounded to the nearest microsecond). MATLAB stores numbers as double by
//   default (the rpg_event_lifetime files are double matrices of whole microseconds), so
//   the class does not tell the unit; with the default unit a double time that is not a
//   whole number is an error naming --time-unit, never silently rounded.
//   x, y integral 0..65535; polarity 1 = ON, 0 or -1 = OFF.
// The whole variable is read into memory at open (libmatio reads a compressed variable
// as a whole): 8 bytes per value at most. The file must be a regular file (libmatio
// opens it by its path), not a pipe. Errors name the file, the variable and the row.

#include <cstdint>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "evcorner/io/event_checks.hpp"
#include "evcorner/io/event_reader.hpp"

namespace evcorner::io {

class MatReader final : public EventReader {
public:
    /// Opens `path` and reads the variable. Throws InputError.
    explicit MatReader(const std::string& path, ReaderOptions options = {});
    ~MatReader() override;

    std::size_t read(std::span<Event> out) override;
    [[nodiscard]] std::span<const SkipRun> skipped_in_batch() const noexcept override { return skips_.batch(); }
    [[nodiscard]] std::uint64_t skipped() const noexcept override { return skips_.total(); }
    [[nodiscard]] std::optional<SensorSize> sensor() const noexcept override { return sensor_; }
    [[nodiscard]] std::string_view format() const noexcept override { return "mat"; }
    [[nodiscard]] const std::string& name() const noexcept override { return name_; }
    /// Progress in bytes, estimated as the fraction of rows read times the file size.
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept override;
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() const noexcept override { return file_size_; }
    /// The variable read, and its rows.
    [[nodiscard]] const std::string& variable() const noexcept { return var_; }
    [[nodiscard]] std::uint64_t rows() const noexcept { return rows_; }

private:
    [[noreturn]] void fail_row(std::uint64_t row, const std::string& reason) const;

    std::string name_;
    std::string var_;
    ReaderOptions options_;
    std::optional<SensorSize> sensor_;
    std::uint32_t limit_w_ = 65536, limit_h_ = 65536;
    std::optional<std::uint64_t> file_size_;
    std::uint64_t rows_ = 0, next_ = 0;
    int col_[4] = {0, 1, 2, 3};  // the column of t, x, y, p
    std::vector<double> values_;  // column-major, rows_ x 4 (integers up to 2^53 exact)
    std::vector<std::int64_t> tint_;  // the time column, when it is of an integer class
    bool float_time_ = false;
    bool whole_us_ = false;  // default unit on a float class: times must be whole
    double time_scale_ = 1;
    std::int64_t time_mul_ = 1, time_div_ = 1;
    std::int64_t last_t_ = INT64_MIN;
    SkipLog skips_;
    std::exception_ptr error_;
};

}  // namespace evcorner::io
