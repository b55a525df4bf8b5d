// evcorner convert: events from any readable format to any writable one.
//
// Streams batch by batch in constant memory. On bad input the events before the error
// are written (a complete, valid output file) and the error is reported.

#include <cstdio>
#include <fmt/format.h>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "evcorner/error.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/open.hpp"

namespace evcorner::cli {

namespace {

constexpr std::size_t kBatch = 1 << 16;

struct ConvertOptions {
    std::string input, output;
    std::string format = "auto";
    std::string to = "auto";
    std::string size;
    std::string csv_columns;
    std::string time_unit = "us";
    std::string chip;
    bool skip_invalid = false;
    bool allow_damaged = false;
    bool quiet = false;
};

void run_convert(const ConvertOptions& o) {
    io::ReaderOptions ropts;
    ropts.skip_invalid = o.skip_invalid;
    ropts.fallback_sensor = std::nullopt;  // converting needs no sensor; --size checks one
    if (!o.size.empty()) ropts.sensor = parse_sensor_size(o.size);
    ropts.csv_columns = o.csv_columns;
    ropts.csv_time_unit = o.time_unit;
    ropts.aedat2_chip = o.chip;
    const auto reader = io::open_event_reader(o.input, ropts, o.format);
    std::string to = o.to;
    if (to == "auto") {
        to = io::output_format_for(o.output);
        if (to.empty())
            throw OutputError(o.output, "cannot tell the output format from the extension; pass --to (" +
                                            std::string(io::kOutputFormats) + ")");
    }
    const auto writer = io::open_event_writer(o.output, to, reader->sensor());
    std::vector<Event> buf(kBatch);
    std::uint64_t events = 0;
    try {
        for (;;) {
            const std::size_t n = reader->read(buf);
            if (n == 0 && reader->skipped_in_batch().empty()) break;
            writer->write(std::span<const Event>(buf.data(), n));
            events += n;
        }
    } catch (const InputError& e) {
        if (!o.allow_damaged) {
            writer->close();
            fmt::print(stderr, "evcorner: the {} events before the error are written to {}\n", events, writer->name());
            throw;
        }
        fmt::print(stderr, "evcorner: warning: {}; the {} events before it are written\n", e.what(), events);
    }
    writer->close();
    if (!o.quiet) {
        fmt::print(stderr, "evcorner convert: {} ({}) -> {} ({}): {} events", reader->name(), reader->format(),
                   writer->name(), to, events);
        if (reader->skipped() > 0) fmt::print(stderr, ", {} skipped (outside the sensor)", reader->skipped());
        fmt::print(stderr, "\n");
    }
}

}  // namespace

void add_convert_command(CLI::App& app) {
    auto o = std::make_shared<ConvertOptions>();
    CLI::App* cmd = app.add_subcommand(
        "convert",
        "Convert an event file to another format.\n"
        "The input format is told by the content (or --format); the output format by OUTPUT's\n"
        "extension (.txt, .csv, .npy, .aedat4, .h5) or --to.");
    cmd->add_option("INPUT", o->input, "Event file, or - for standard input")->required();
    cmd->add_option("OUTPUT", o->output, "Output file (- = standard output, text formats)")->required();
    add_input_options(*cmd, o->format, o->csv_columns, o->time_unit, o->chip);
    cmd->add_option("--to", o->to, "Output format: auto (by extension), " + std::string(io::kOutputFormats))
        ->capture_default_str();
    cmd->add_option("--size", o->size, "Sensor size WxH to check events against (overrides the file's)")
        ->check([](const std::string& s) {
            return parse_sensor_size(s) ? std::string() : "expected WxH with sides 1..65536, e.g. 346x260";
        });
    cmd->add_flag("--skip-invalid", o->skip_invalid, "Skip (and count) events outside --size instead of failing");
    cmd->add_flag("--allow-damaged", o->allow_damaged,
                  "A damaged or cut-short input ends with a warning and exit status 0, instead of an "
                  "error: the events before the damage are the output");
    cmd->add_flag("-q,--quiet", o->quiet, "No summary line");
    cmd->footer("Examples:\n  evcorner convert recording.aedat events.npy\n  evcorner convert events.raw - --to csv | head");
    cmd->callback([o] { run_convert(*o); });
}

}  // namespace evcorner::cli
