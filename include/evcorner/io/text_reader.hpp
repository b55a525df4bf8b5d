#pragma once
// Streaming reader for the Event-Camera-Dataset text format (Mueggler et al., IJRR 2017):
// one event per line, "t x y p", t in seconds (up to 9 decimals read exactly; a nonzero
// digit past the 9th is an error: docs/formats.md, "Times"), x and y pixel coordinates,
// p = 1 (ON) or 0 (OFF), separated by spaces or tabs. A fifth column is a score ("t x y p
// score", as evcorner writes corners with their scores): the first event line says
// whether every line has one, and scores_in_batch() gives them.
// Blank lines and lines starting with '#' are skipped; CRLF line ends are accepted.
//
// Time is rounded to the nearest microsecond (halves away from zero) with integer
// arithmetic. Memory is constant whatever the file size. Every error names the file,
// the 1-based line and the offending text.

#include <cstdint>
#include <exception>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/io/event_checks.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/line_source.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::io {

/// When options.sensor is set, an event outside it is an error (or skipped).
class TextReader final : public EventReader {
public:
    /// Reads `file` from its first unread byte. Throws InputError.
    explicit TextReader(InputFile file, ReaderOptions options = {});
    /// Opens `path` ("-" = standard input). Throws InputError.
    explicit TextReader(std::string path, ReaderOptions options = {})
        : TextReader(InputFile(std::move(path)), std::move(options)) {}

    /// Fills `out` with the next events; returns how many (0 at the end).
    /// Throws InputError on bad input. Events parsed before a bad line are
    /// returned first; the error is thrown by the following call.
    std::size_t read(std::span<Event> out) override;

    [[nodiscard]] std::span<const SkipRun> skipped_in_batch() const noexcept override { return skips_.batch(); }
    [[nodiscard]] std::span<const double> scores_in_batch() const noexcept override {
        return scored_ == Scored::yes ? std::span<const double>(scores_.data(), batch_n_) : std::span<const double>();
    }
    [[nodiscard]] std::uint64_t skipped() const noexcept override { return skips_.total(); }
    [[nodiscard]] std::optional<SensorSize> sensor() const noexcept override { return options_.sensor; }
    /// "ecd-text", or "ecd-text+gzip" (zstd, bzip2, xz) for a compressed file.
    [[nodiscard]] std::string_view format() const noexcept override { return format_; }
    [[nodiscard]] const std::string& name() const noexcept override { return lines_.file().name(); }
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept override { return lines_.file().consumed(); }
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() const noexcept override { return lines_.file().size(); }
    [[nodiscard]] std::uint64_t events() const noexcept { return events_; }
    /// Lines consumed so far.
    [[nodiscard]] std::uint64_t line() const noexcept { return lines_.line(); }

private:
    LineSource lines_;
    std::string format_;
    ReaderOptions options_;
    std::uint64_t events_ = 0;
    enum class Scored : std::uint8_t { unknown, no, yes } scored_ = Scored::unknown;
    std::vector<double> scores_;  // the last batch's, with a score column
    std::size_t batch_n_ = 0;
    std::int64_t last_t_ = INT64_MIN;
    SkipLog skips_;
    std::exception_ptr pending_;
};

/// Reads a whole text file into memory (tests, small tools).
std::vector<Event> read_text_file(const std::string& path, ReaderOptions options = {});

}  // namespace evcorner::io
