// evcorner info: what an event file holds, in one pass over it.
//
// The file is read in batches and summarised with counters only (constant memory):
// format, sensor size, events, time span, mean and peak rate, ON/OFF counts, x/y ranges.

#include <algorithm>
#include <cstdio>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.hpp"
#include "evcorner/error.hpp"
#include "evcorner/io/aedat2_reader.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/output_file.hpp"

namespace evcorner::cli {

namespace {

constexpr std::size_t kBatch = 1 << 16;
constexpr std::int64_t kPeakBinUs = 1000;  // peak rate: the busiest 1 ms bin

struct InfoOptions {
    std::string input;
    std::string format = "auto";
    std::string size;
    std::string csv_columns;
    std::string time_unit = "us";
    std::string chip;
    std::string json;
    bool skip_invalid = false;
};

struct Stats {
    std::uint64_t events = 0, on = 0, skipped = 0;
    std::int64_t t_first = 0, t_last = 0;
    int x_min = 65535, x_max = 0, y_min = 65535, y_max = 0;
    std::uint64_t peak_bin = 0;
};

void run_info(const InfoOptions& o) {
    io::ReaderOptions ropts;
    ropts.skip_invalid = o.skip_invalid;
    ropts.fallback_sensor = std::nullopt;  // describe any file, whatever its size
    if (!o.size.empty()) ropts.sensor = parse_sensor_size(o.size);
    ropts.csv_columns = o.csv_columns;
    ropts.csv_time_unit = o.time_unit;
    ropts.aedat2_chip = o.chip;
    const auto reader = io::open_event_reader(o.input, ropts, o.format);

    Stats s;
    std::vector<Event> buf(kBatch);
    std::int64_t bin = INT64_MIN;
    std::uint64_t in_bin = 0;
    for (;;) {
        const std::size_t n = reader->read(buf);
        if (n == 0 && reader->skipped_in_batch().empty()) break;
        if (n == 0) continue;
        if (s.events == 0) s.t_first = buf[0].t;
        for (std::size_t i = 0; i < n; ++i) {
            const Event& e = buf[i];
            s.on += e.p != 0;
            s.x_min = std::min<int>(s.x_min, e.x);
            s.x_max = std::max<int>(s.x_max, e.x);
            s.y_min = std::min<int>(s.y_min, e.y);
            s.y_max = std::max<int>(s.y_max, e.y);
            const std::int64_t b = (e.t - s.t_first) / kPeakBinUs;
            if (b != bin) {
                bin = b;
                in_bin = 0;
            }
            s.peak_bin = std::max(s.peak_bin, ++in_bin);
        }
        s.t_last = buf[n - 1].t;
        s.events += n;
    }
    s.skipped = reader->skipped();

    const double span_s = static_cast<double>(s.t_last - s.t_first) * 1e-6;
    const double mean_rate = span_s > 0 ? static_cast<double>(s.events) / span_s : 0.0;
    const double peak_rate = static_cast<double>(s.peak_bin) * (1e6 / kPeakBinUs);
    const auto sensor = reader->sensor();

    fmt::print("file         {}\n", reader->name());
    fmt::print("format       {}\n", reader->format());
    if (sensor) fmt::print("sensor       {}x{}\n", sensor->width, sensor->height);
    else fmt::print("sensor       unknown (the file does not say; pass --size to check events)\n");
    fmt::print("events       {}\n", s.events);
    if (s.skipped > 0) fmt::print("skipped      {} (outside the sensor)\n", s.skipped);
    if (s.events > 0) {
        fmt::print("time         {} .. {} us\n", s.t_first, s.t_last);
        fmt::print("span         {:.6f} s\n", span_s);
        fmt::print("mean rate    {:.3f} M events/s\n", mean_rate * 1e-6);
        fmt::print("peak rate    {:.3f} M events/s (busiest 1 ms)\n", peak_rate * 1e-6);
        fmt::print("ON / OFF     {} / {}\n", s.on, s.events - s.on);
        fmt::print("x range      {}..{}\n", s.x_min, s.x_max);
        fmt::print("y range      {}..{}\n", s.y_min, s.y_max);
    }
    if (!o.json.empty()) {
        nlohmann::json j;
        j["file"] = reader->name();
        j["format"] = std::string(reader->format());
        j["width"] = sensor ? nlohmann::json(sensor->width) : nlohmann::json(nullptr);
        j["height"] = sensor ? nlohmann::json(sensor->height) : nlohmann::json(nullptr);
        j["events"] = s.events;
        j["skipped"] = s.skipped;
        if (s.events > 0) {
            j["t_first_us"] = s.t_first;
            j["t_last_us"] = s.t_last;
            j["span_s"] = span_s;
            j["mean_rate_eps"] = mean_rate;
            j["peak_rate_eps"] = peak_rate;
            j["on"] = s.on;
            j["off"] = s.events - s.on;
            j["x_min"] = s.x_min;
            j["x_max"] = s.x_max;
            j["y_min"] = s.y_min;
            j["y_max"] = s.y_max;
        }
        io::OutputFile out(o.json);
        out.write(j.dump(2));
        out.write("\n");
        out.close();
    }
}

}  // namespace

void add_input_options(CLI::App& cmd, std::string& format, std::string& csv_columns, std::string& time_unit,
                       std::string& chip) {
    cmd.add_option("--format", format,
                   "Input format: auto (from the content), " + std::string(io::kInputFormats))
        ->capture_default_str();
    cmd.add_option("--csv-columns", csv_columns,
                   "CSV column order, e.g. x,y,p,t ('_' skips a column) [default: the header row, else t,x,y,p]");
    cmd.add_option("--time-unit", time_unit, "CSV time unit: us, ns, ms or s")
        ->capture_default_str()
        ->check(CLI::IsMember({"us", "ns", "ms", "s"}));
    cmd.add_option("--chip", chip,
                   "AEDAT 2.0: the camera that recorded the file (DVS128, DAVIS240C, DAVIS346, ...), "
                   "instead of the header's '# AEChip' line")
        ->check([](const std::string& s) {
            return io::Aedat2Reader::known_chip(s)
                       ? std::string()
                       : "unknown chip (known: DVS128, DAVIS128, DAVIS208, DAVIS240A/B/C, DAVIS346, DAVIS640)";
        });
}

void add_info_command(CLI::App& app) {
    auto o = std::make_shared<InfoOptions>();
    CLI::App* cmd = app.add_subcommand(
        "info",
        "Describe an event file: format, sensor size, events, time span, rates, ON/OFF.\n"
        "Prints the format, sensor size, events, time span, mean and peak rate, ON/OFF counts\n"
        "and x/y ranges. Reads the whole file once, in constant memory.");
    cmd->add_option("INPUT", o->input, "Event file, or - for standard input")->required();
    add_input_options(*cmd, o->format, o->csv_columns, o->time_unit, o->chip);
    cmd->add_option("--size", o->size, "Sensor size WxH to check events against (overrides the file's)")
        ->check([](const std::string& s) {
            return parse_sensor_size(s) ? std::string() : "expected WxH with sides 1..65536, e.g. 346x260";
        });
    cmd->add_flag("--skip-invalid", o->skip_invalid, "Skip (and count) events outside --size instead of failing");
    cmd->add_option("--json", o->json, "Also write the figures as JSON to this file (- = standard output)");
    cmd->footer("Example:\n  evcorner info recording.raw");
    cmd->callback([o] { run_info(*o); });
}

}  // namespace evcorner::cli
