#pragma once
// Writer for CSV event files: a header row "t,x,y,p", then one "t,x,y,p" line per
// event with t in integer microseconds, as CsvReader reads by default. With scores the
// header is "t,x,y,p,score" and each line ends in the score, in the shortest form that
// reads back to the same double.

#include <span>
#include <string>

#include "evcorner/event.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/output_file.hpp"

namespace evcorner::io {

class CsvWriter final : public EventWriter {
public:
    /// Creates `path` ("-" = standard output) and writes the header row. Throws OutputError.
    explicit CsvWriter(std::string path, bool with_score = false);
    void write(std::span<const Event> events) override;
    void write(std::span<const Event> events, std::span<const double> scores) override;
    void close() override { out_.close(); }
    [[nodiscard]] const std::string& name() const noexcept override { return out_.name(); }

private:
    OutputFile out_;
    bool with_score_;
};

}  // namespace evcorner::io
