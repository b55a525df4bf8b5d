// evcorner convert: events from any readable format to any writable one.
//
// Streams batch by batch in constant memory. On bad input the events before the error
// are written (a complete, valid output file) and the error is reported.

#include <algorithm>
#include <cstdio>
#include <fmt/format.h>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "evcorner/error.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/output_paths.hpp"
#include "progress.hpp"

namespace evcorner::cli {

namespace {

constexpr std::size_t kBatch = 1 << 16;

struct ConvertOptions {
    std::string input, output;
    std::string format = "auto";
    std::string to = "auto";
    std::string size;
    io::ReaderOptions reader;
    bool skip_invalid = false;
    bool allow_damaged = false;
    bool quiet = false;
    bool no_progress = false;
};

// The size recorded for an input that gives none (no --size): the DAVIS240C's, which
// detect would use, when every event fits in it; else the events' bounding box, with a
// warning (only formats with a field for it record either).
SensorSize fallback_size(int max_x, int max_y, const std::string& to, const std::string& output) {
    if (max_x < kDavis240.width && max_y < kDavis240.height) return kDavis240;
    const SensorSize box{max_x + 1, max_y + 1};
    if (to == "aedat4" || to == "hdf5")
        fmt::print(stderr,
                   "evcorner: warning: the input does not give its sensor size and its events do not fit the "
                   "{}x{} default; {} records their bounding box {}x{} (pass --size WxH to record the sensor's)\n",
                   kDavis240.width, kDavis240.height, output, box.width, box.height);
    return box;
}

void run_convert(const ConvertOptions& o) {
    // Before anything is opened: an output onto the input, and the output format.
    io::check_output_paths({{"INPUT", o.input}}, {{"OUTPUT", o.output}});
    io::check_outputs_creatable({{"OUTPUT", o.output}});
    const std::string to = io::resolve_output_format(o.output, o.to);
    io::ReaderOptions ropts = o.reader;
    ropts.skip_invalid = o.skip_invalid;
    ropts.fallback_sensor = std::nullopt;  // converting needs no sensor; --size checks one
    if (!o.size.empty()) ropts.sensor = parse_sensor_size(o.size);
    const auto reader = io::open_event_reader(o.input, ropts, o.format);
    // The input's size (--size included) goes into formats that record one.
    const std::optional<SensorSize> sensor = reader->sensor();
    const auto writer = io::open_event_writer(o.output, to, sensor);
    const bool output_is_file = io::output_is_file(o.output);
    Progress progress(!o.quiet && !o.no_progress, reader->bytes_total());
    std::vector<Event> buf(kBatch);
    std::uint64_t events = 0;
    int max_x = -1, max_y = -1;
    auto finish = [&] {
        progress.finish();
        if (!sensor) writer->set_sensor(fallback_size(max_x, max_y, to, writer->name()));
        writer->close();
    };
    try {
        for (;;) {
            const std::size_t n = reader->read(buf);
            if (n == 0 && reader->skipped_in_batch().empty()) break;
            const std::span<const Event> batch(buf.data(), n);
            if (!sensor)
                for (const Event& e : batch) {
                    max_x = std::max<int>(max_x, e.x);
                    max_y = std::max<int>(max_y, e.y);
                }
            writer->write(batch);
            events += n;
            progress.update(reader->bytes_consumed(), events);
        }
    } catch (const InputError& e) {
        if (!o.allow_damaged) {
            // The writer is left unclosed: a file output is removed, a stream keeps what it got.
            progress.finish();
            if (output_is_file)
                fmt::print(stderr,
                           "evcorner: {} is not written (--allow-damaged keeps the {} events before the error)\n",
                           o.output, events);
            else if (events > 0)
                fmt::print(stderr, "evcorner: the {} events before the error went to {}\n", events, writer->name());
            throw;
        }
        progress.finish();
        fmt::print(stderr, "evcorner: warning: {}; the {} events before it are written\n", e.what(), events);
    }
    finish();
    if (!o.quiet) {
        fmt::print(stderr, "evcorner convert: {} ({}) -> {} ({}): {} events", reader->name(), reader->format(),
                   writer->name(), to, events);
        if (reader->skipped() > 0) fmt::print(stderr, ", {} skipped (outside the sensor)", reader->skipped());
        fmt::print(stderr, "\n");
    }
}

}  // namespace

void add_output_format_option(CLI::App& cmd, std::string& to) {
    cmd.add_option("--to", to,
                   "Output format: auto (by extension; none = ecd-text), " + std::string(io::kOutputFormats))
        ->capture_default_str()
        ->check([](const std::string& name) {
            try {
                if (name != "auto") (void)io::resolve_output_format("", name);
                return std::string();
            } catch (const std::invalid_argument& e) {
                return std::string(e.what());
            }
        });
}

void add_convert_command(CLI::App& app) {
    auto o = std::make_shared<ConvertOptions>();
    CLI::App* cmd = app.add_subcommand(
        "convert",
        "Convert an event file to another format.\n"
        "The input format is told by the content (or --format); the output format by OUTPUT's\n"
        "extension (.txt, .csv, .npy, .aedat4, .h5, .hdf5; another extension is refused) or\n"
        "--to; a name without extension, and - (standard output), get ECD text.\n"
        "AEDAT 4.0 and HDF5 outputs record the sensor size: the input's, else --size, else\n"
        "240x180 (the DAVIS240C, as detect assumes) when every event fits, else the events'\n"
        "bounding box (with a warning). The output appears under its name only when complete.");
    cmd->add_option("INPUT", o->input, "Event file, or - for standard input")->required();
    cmd->add_option("OUTPUT", o->output, "Output file (- = standard output, text formats)")->required();
    add_reader_options(*cmd, o->format, o->reader);
    add_output_format_option(*cmd, o->to);
    cmd->add_option("--size", o->size,
                    "Sensor size WxH to check events against (overrides the file's) and to record")
        ->check([](const std::string& s) {
            return parse_sensor_size(s) ? std::string() : "expected WxH with sides 1..65536, e.g. 346x260";
        });
    cmd->add_flag("--skip-invalid", o->skip_invalid, "Skip (and count) events outside --size instead of failing");
    cmd->add_flag("--allow-damaged", o->allow_damaged,
                  "A damaged or cut-short input ends with a warning and exit status 0, instead of an "
                  "error: the events before the damage are the output");
    cmd->add_flag("-q,--quiet", o->quiet, "No summary line and no progress bar");
    cmd->add_flag("--no-progress", o->no_progress, "No progress bar (it shows only on a terminal)");
    cmd->footer("Examples:\n  evcorner convert recording.aedat events.npy\n  evcorner convert events.raw - --to csv | head");
    cmd->callback([o] { run_convert(*o); });
}

}  // namespace evcorner::cli
