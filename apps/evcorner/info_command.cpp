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
#include "evcorner/io/formats.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/io/ros_bag.hpp"
#include "progress.hpp"
#include "std_streams.hpp"

namespace evcorner::cli {

namespace {

constexpr std::size_t kBatch = 1 << 16;
constexpr std::int64_t kPeakBinUs = 1000;  // peak rate: the busiest 1 ms

struct InfoOptions {
    std::string input;
    std::string format = "auto";
    std::string size;
    io::ReaderOptions reader;
    std::string json;
    bool skip_invalid = false;
    bool no_progress = false;
    bool formats = false;
};

// The peak rate, streamed. The span t_first..t_last is cut into 1 ms bins from t_first;
// the remainder under 1 ms joins the last bin (a span under 1 ms is one bin). The bins
// tile the span, so the busiest bin's rate (events / its length) is never below the
// mean rate (events / span): the largest of several ratios is at least the ratio of
// their sums.
class PeakRate {
public:
    void add(std::int64_t t_from_first) {
        const std::int64_t b = t_from_first / kPeakBinUs;
        if (b != bin_) {
            // Bin `bin_` is complete; it stays the one before last only if b follows it.
            max_full_ = std::max(max_full_, before_last_);
            before_last_ = b == bin_ + 1 ? in_bin_ : 0;
            if (b != bin_ + 1) max_full_ = std::max(max_full_, in_bin_);
            bin_ = b;
            in_bin_ = 0;
        }
        ++in_bin_;
    }
    /// Events per second; 0 for a span of 0.
    [[nodiscard]] double rate(std::int64_t span_us) const {
        if (span_us <= 0) return 0.0;
        if (bin_ == 0) return static_cast<double>(in_bin_) * 1e6 / static_cast<double>(span_us);
        // Every complete bin but the one before last, then that one merged with the remainder.
        const double full = static_cast<double>(max_full_) * 1e6 / kPeakBinUs;
        const auto merged_us = static_cast<double>(span_us - (bin_ - 1) * kPeakBinUs);
        const double merged = static_cast<double>(before_last_ + in_bin_) * 1e6 / merged_us;
        return std::max(full, merged);
    }

private:
    std::int64_t bin_ = 0;
    std::uint64_t in_bin_ = 0;      // events in bin_
    std::uint64_t before_last_ = 0; // events in bin_ - 1
    std::uint64_t max_full_ = 0;    // the most events in a bin before bin_ - 1
};

struct Stats {
    std::uint64_t events = 0, on = 0, skipped = 0;
    std::int64_t t_first = 0, t_last = 0;
    int x_min = 65535, x_max = 0, y_min = 65535, y_max = 0;
    PeakRate peak;
};

// A ROS bag's topics, the one read marked, and its encoding.
void print_bag_topics(std::FILE* out, const io::BagReader& bag) {
    using io::escape_bytes;
    fmt::print(out, "topic        {} ({}{})\n", escape_bytes(bag.topic().name), escape_bytes(bag.topic().type),
               bag.encoding().empty() ? "" : ", encoding " + escape_bytes(bag.encoding()));
    fmt::print(out, "topics       {}\n", bag.topics().size());
    for (const io::BagTopic& t : bag.topics())
        fmt::print(out, "  {} {}  {}  {} messages\n", t.name == bag.topic().name ? '*' : ' ', escape_bytes(t.name),
                   escape_bytes(t.type), t.messages);
}
void add_bag_topics(nlohmann::json& j, const io::BagReader& bag) {
    j["topic"] = bag.topic().name;
    j["encoding"] = bag.encoding();
    nlohmann::json topics = nlohmann::json::array();
    for (const io::BagTopic& t : bag.topics())
        topics.push_back({{"name", t.name}, {"type", t.type}, {"messages", t.messages}});
    j["topics"] = topics;
}

// The format table (io/formats.hpp), one format per block.
void print_formats() {
    for (const io::InputFormat& f : io::input_formats()) {
        fmt::print("{:<9} {}\n", f.name, f.title);
        if (!f.aliases.empty()) fmt::print("          also --format {}\n", f.aliases);
        fmt::print("          files {}{}{}\n", f.extensions, f.by_seeking ? "; read by seeking (not from a pipe)" : "",
                   f.compressed ? "; also gzip, zstd, bzip2 or xz compressed" : "");
        std::string takes;
        for (const io::ReaderOptionInfo& r : io::reader_option_infos())
            if (f.options & r.bit) takes += (takes.empty() ? "" : " ") + std::string(r.flag);
        if (!takes.empty()) fmt::print("          options {}\n", takes);
    }
}

void run_info(const InfoOptions& o) {
    if (o.formats) {
        if (!o.input.empty()) throw std::invalid_argument("--formats lists the formats: give no INPUT with it");
        print_formats();
        return;
    }
    if (o.input.empty()) throw std::invalid_argument("INPUT is required (or --formats for the list of formats)");
    if (!o.json.empty()) {
        io::check_output_paths({{"INPUT", o.input}}, {{"--json", o.json}});
        io::check_outputs_creatable({{"--json", o.json}});
    }
    io::ReaderOptions ropts = o.reader;
    ropts.skip_invalid = o.skip_invalid;
    ropts.fallback_sensor = std::nullopt;  // describe any file, whatever its size
    if (!o.size.empty()) ropts.sensor = parse_sensor_size(o.size);
    const auto reader = io::open_event_reader(o.input, ropts, o.format);
    // With the JSON on standard output, the table goes to standard error.
    std::FILE* human = o.json == "-" ? stderr : stdout;

    Stats s;
    Progress progress(!o.no_progress, reader->bytes_total());
    std::vector<Event> buf(kBatch);
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
            s.peak.add(e.t - s.t_first);
        }
        s.t_last = buf[n - 1].t;
        s.events += n;
        progress.update(reader->bytes_consumed(), s.events);
    }
    progress.finish();
    s.skipped = reader->skipped();

    const double span_s = static_cast<double>(s.t_last - s.t_first) * 1e-6;
    const double mean_rate = span_s > 0 ? static_cast<double>(s.events) / span_s : 0.0;
    const double peak_rate = s.peak.rate(s.t_last - s.t_first);
    const auto sensor = reader->sensor();

    fmt::print(human, "file         {}\n", reader->name());
    fmt::print(human, "format       {}\n", reader->format());
    if (sensor) fmt::print(human, "sensor       {}x{}\n", sensor->width, sensor->height);
    else fmt::print(human, "sensor       unknown (the file does not say; pass --size to check events)\n");
    fmt::print(human, "events       {}\n", s.events);
    if (s.skipped > 0) fmt::print(human, "skipped      {} (outside the sensor)\n", s.skipped);
    if (s.events > 0) {
        fmt::print(human, "time         {} .. {} us\n", s.t_first, s.t_last);
        fmt::print(human, "span         {:.6f} s\n", span_s);
        fmt::print(human, "mean rate    {:.3f} M events/s\n", mean_rate * 1e-6);
        fmt::print(human, "peak rate    {:.3f} M events/s (busiest 1 ms)\n", peak_rate * 1e-6);
        fmt::print(human, "ON / OFF     {} / {}\n", s.on, s.events - s.on);
        fmt::print(human, "x range      {}..{}\n", s.x_min, s.x_max);
        fmt::print(human, "y range      {}..{}\n", s.y_min, s.y_max);
    }
    const auto* bag = dynamic_cast<const io::BagReader*>(reader.get());
    if (bag) print_bag_topics(human, *bag);
    flush_checked(human);
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
        if (bag) add_bag_topics(j, *bag);
        io::OutputFile out(o.json);
        out.write(j.dump(2));
        out.write("\n");
        out.close();
    }
}

}  // namespace

void add_reader_options(CLI::App& cmd, std::string& format, io::ReaderOptions& reader) {
    const char* group = "Input";
    cmd.add_option("--format", format, "Input format: auto (from the content), " + io::input_format_names())
        ->capture_default_str()
        ->group(group)
        ->check([](const std::string& name) {
            if (name == "auto" || io::find_input_format(name)) return std::string();
            return "unknown input format '" + name + "' (known: auto, " + io::input_format_names() + ")";
        });
    for (const io::ReaderOptionInfo& info : io::reader_option_infos()) {
        CLI::Option* opt = cmd.add_option_function<std::string>(
                                  std::string(info.flag), [&reader, &info](const std::string& v) { info.set(reader, v); },
                                  std::string(info.help))
                               ->type_name("TEXT")
                               ->group(group);
        // Values the table's readers cannot take are usage errors at once.
        if (info.flag == "--time-unit") opt->check(CLI::IsMember({"us", "ns", "ms", "s"}));
        if (info.flag == "--chip")
            opt->check([](const std::string& s) {
                return io::Aedat2Reader::known_chip(s)
                           ? std::string()
                           : "unknown chip (known: DVS128, DAVIS128, DAVIS208, DAVIS240A/B/C, DAVIS346, DAVIS640)";
            });
    }
}

void add_info_command(CLI::App& app) {
    auto o = std::make_shared<InfoOptions>();
    CLI::App* cmd = app.add_subcommand(
        "info",
        "Describe an event file: format, sensor size, events, time span, rates, ON/OFF.\n"
        "Prints the format, sensor size, events, time span, mean and peak rate, ON/OFF counts\n"
        "and x/y ranges (a ROS bag: also its topics, types and message counts, the one read\n"
        "marked *). Reads the whole file once, in constant memory.\n"
        "Mean rate: events / (last time - first time). Peak rate: the busiest 1 ms bin, bins\n"
        "cut from the first event, the remainder under 1 ms joined to the last bin (a span\n"
        "under 1 ms is one bin), in events per second of the bin's length: never below the mean.");
    cmd->add_option("INPUT", o->input, "Event file, or - for standard input");
    cmd->add_flag("--formats", o->formats,
                  "List the formats evcorner reads instead (name, aliases, file names, options they take)");
    add_reader_options(*cmd, o->format, o->reader);
    cmd->add_option("--size", o->size, "Sensor size WxH to check events against (overrides the file's)")
        ->check([](const std::string& s) {
            return parse_sensor_size(s) ? std::string() : "expected WxH with sides 1..65536, e.g. 346x260";
        });
    cmd->add_flag("--skip-invalid", o->skip_invalid, "Skip (and count) events outside --size instead of failing");
    cmd->add_option("--json", o->json,
                    "Also write the figures as JSON to this file (- = standard output; the table then "
                    "goes to standard error)");
    cmd->add_flag("--no-progress", o->no_progress, "No progress bar (it shows only on a terminal)");
    cmd->footer("Examples:\n  evcorner info recording.raw\n  evcorner info --formats");
    cmd->callback([o] { run_info(*o); });
}

}  // namespace evcorner::cli
