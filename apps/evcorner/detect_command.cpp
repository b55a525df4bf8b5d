// evcorner detect: events in, corner events out.
//
// Data flows one way: reader -> detector -> writers. Detection time is measured
// around the detector's batch call only; wall time around the whole run.

#include <chrono>
#include <cstdio>
#include <exception>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "evcorner/any_detector.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/error.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/io/text_writer.hpp"
#include "evcorner/parallel_detect.hpp"
#include "evcorner/scored_detector.hpp"
#include "progress.hpp"

namespace evcorner::cli {

namespace {

using Clock = std::chrono::steady_clock;
constexpr std::size_t kBatch = 1 << 16;

struct DetectOptions {
    std::string input;
    std::string detector = "efast";
    std::string output = "-";
    std::string format = "auto";
    std::string to = "auto";
    std::string csv_columns;
    std::string time_unit;
    std::string chip;
    MoreInputOptions more;
    std::string size;
    std::string mask;
    std::string summary_json;
    bool skip_invalid = false;
    bool allow_damaged = false;
    bool with_score = false;
    DetectorParams params;
    bool quiet = false;
    bool no_progress = false;
    int threads = 1;
};

struct Totals {
    std::uint64_t events = 0;
    std::uint64_t corners = 0;
    std::uint64_t skipped = 0;
    double detect_s = 0;
    double wall_s = 0;
    std::string damaged;  ///< the input error the run stopped at under --allow-damaged
};

void write_mask(io::OutputFile& mask, std::span<const std::uint8_t> flags, std::size_t n,
                std::span<const io::SkipRun> skips) {
    static constexpr char kLine[2][2] = {{'0', '\n'}, {'1', '\n'}};
    auto put_zeros = [&](std::uint64_t count) {
        for (std::uint64_t k = 0; k < count; ++k) mask.write({kLine[0], 2});
    };
    std::size_t next_skip = 0;
    for (std::size_t i = 0; i < n; ++i) {
        while (next_skip < skips.size() && skips[next_skip].before == i) put_zeros(skips[next_skip++].count);
        mask.write({kLine[flags[i] != 0], 2});
    }
    while (next_skip < skips.size()) put_zeros(skips[next_skip++].count);
}

void print_summary(const DetectOptions& o, SensorSize size, const Totals& t) {
    const double events = static_cast<double>(t.events);
    fmt::print(stderr, "evcorner detect: {}\n", o.input == "-" ? "<stdin>" : o.input);
    fmt::print(stderr, "  detector     {} on a {}x{} sensor\n", o.detector, size.width, size.height);
    fmt::print(stderr, "  events       {}\n", t.events);
    if (t.skipped > 0) fmt::print(stderr, "  skipped      {} (outside the sensor)\n", t.skipped);
    fmt::print(stderr, "  corners      {}\n", t.corners);
    if (t.events > 0) {
        fmt::print(stderr, "  reduction    {:.2f} % of events removed\n",
                   100.0 * (1.0 - static_cast<double>(t.corners) / events));
        if (o.threads > 1)
            fmt::print(stderr,
                       "  detection    {:.1f} ns/event ({} threads; {:.2f} M events/s; the rounds overlap "
                       "reading and writing)\n",
                       t.detect_s * 1e9 / events, o.threads, events / t.detect_s / 1e6);
        else
            fmt::print(stderr, "  detection    {:.1f} ns/event (detector alone; {:.2f} M events/s)\n",
                       t.detect_s * 1e9 / events, events / t.detect_s / 1e6);
    }
    if (!t.damaged.empty()) fmt::print(stderr, "  damaged      input ends at: {}\n", t.damaged);
    fmt::print(stderr, "  wall time    {:.3f} s ({:.2f} M events/s end to end)\n", t.wall_s,
               t.wall_s > 0 ? events / t.wall_s / 1e6 : 0.0);
}

void write_summary_json(const DetectOptions& o, SensorSize size, const Totals& t) {
    nlohmann::json j;
    j["input"] = o.input;
    j["detector"] = o.detector;
    j["width"] = size.width;
    j["height"] = size.height;
    j["events"] = t.events;
    j["corners"] = t.corners;
    j["skipped"] = t.skipped;
    const double events = static_cast<double>(t.events);
    if (t.events > 0) {
        j["reduction_rate"] = 100.0 * (1.0 - static_cast<double>(t.corners) / events);
        j["ns_per_event"] = t.detect_s * 1e9 / events;
    } else {
        j["reduction_rate"] = nullptr;
        j["ns_per_event"] = nullptr;
    }
    j["threads"] = o.threads;
    j["detect_s"] = t.detect_s;
    j["wall_s"] = t.wall_s;
    if (t.damaged.empty())
        j["damaged"] = nullptr;
    else
        j["damaged"] = t.damaged;
    io::OutputFile out(o.summary_json);
    out.write(j.dump(2));
    out.write("\n");
    out.close();
}

void run_detect(const DetectOptions& o) {
    const auto wall_start = Clock::now();
    // Before anything is opened: outputs onto the input or onto each other, and the format.
    io::check_output_paths({{"INPUT", o.input}},
                           {{"-o", o.output}, {"--mask", o.mask}, {"--summary-json", o.summary_json}});
    const std::string to = io::resolve_output_format(o.output, o.to);
    io::ReaderOptions ropts;
    ropts.skip_invalid = o.skip_invalid;
    if (!o.size.empty()) ropts.sensor = parse_sensor_size(o.size);  // validated by CLI11
    ropts.csv_columns = o.csv_columns;
    ropts.csv_time_unit = o.time_unit;
    ropts.aedat2_chip = o.chip;
    o.more.apply(ropts);
    const std::unique_ptr<io::EventReader> source = io::open_event_reader(o.input, ropts, o.format);
    io::EventReader& reader = *source;
    const SensorSize size = reader.sensor().value_or(kDavis240);

    AnyDetector detector = make_detector(o.detector, size, o.params);
    if (o.with_score && !has_score(detector))
        throw std::invalid_argument("--with-score: detector '" + o.detector +
                                    "' has no score (harris and harris-global have one)");
    if (o.threads > 1 && o.detector != "efast" && o.detector != "harris")
        throw std::invalid_argument("--threads: detector '" + o.detector +
                                    "' is not local (efast and harris split the sensor; harris-global cannot)");
    if (o.threads > 1 && o.with_score)
        throw std::invalid_argument("--threads: --with-score needs one thread");
    // Scores only fit the text lines ("t x y p score"); every other format takes events,
    // and records the sensor size the detector ran on where it has a field for it.
    std::unique_ptr<io::TextWriter> scored_out;
    std::unique_ptr<io::EventWriter> corners_out;
    if (o.with_score) {
        if (to != "ecd-text")
            throw std::invalid_argument("--with-score writes 't x y p score' text lines; it cannot write " + to);
        scored_out = std::make_unique<io::TextWriter>(o.output);
    } else {
        corners_out = io::open_event_writer(o.output, to, size);
    }
    std::unique_ptr<io::OutputFile> mask_out;
    if (!o.mask.empty()) mask_out = std::make_unique<io::OutputFile>(o.mask);

    Progress progress(!o.quiet && !o.no_progress, reader.bytes_total());
    std::vector<Event> events(kBatch);
    std::vector<std::uint8_t> flags(kBatch);
    std::vector<double> scores(o.with_score ? kBatch : 0);
    std::vector<Event> corners(kBatch);
    Totals totals;

    // Every batch read is detected and written before the next read, so an input
    // error thrown by read() leaves complete, valid outputs for the events before it.
    auto finish_outputs = [&] {
        if (scored_out) scored_out->close();
        if (corners_out) corners_out->close();
        if (mask_out) mask_out->close();
    };
    // The outputs of one detected batch, then the progress bar.
    auto write_batch = [&](std::span<const Event> batch, std::span<const std::uint8_t> flags,
                           std::span<const io::SkipRun> skips, std::uint64_t bytes, std::uint64_t events_so_far) {
        const std::size_t n = batch.size();
        if (scored_out) {
            for (std::size_t i = 0; i < n; ++i)
                if (flags[i]) scored_out->write(batch[i], scores[i]);
        } else {
            // Branch-free: corners are a few percent of the events, at data-dependent places.
            std::size_t k = 0;
            for (std::size_t i = 0; i < n; ++i) {
                corners[k] = batch[i];
                k += flags[i] != 0;
            }
            corners_out->write(std::span<const Event>(corners.data(), k));
        }
        if (mask_out) write_mask(*mask_out, flags, n, skips);
        progress.update(bytes, events_so_far);
    };
    // One batch: read, detect (timed), write. Returns false at the end of the input.
    auto step = [&](auto&& detect_batch) {
        const std::size_t n = reader.read(events);
        const auto skips = reader.skipped_in_batch();
        if (n == 0 && skips.empty()) return false;
        const auto t0 = Clock::now();
        const std::size_t c = detect_batch(std::span<const Event>(events.data(), n));
        totals.detect_s += std::chrono::duration<double>(Clock::now() - t0).count();
        totals.events += n;
        totals.corners += c;
        write_batch(std::span<const Event>(events.data(), n), flags, skips, reader.bytes_consumed(), totals.events);
        return true;
    };
    // Several threads: three batches in flight. While the threads detect batch k, the
    // calling thread first writes batch k - 1, then reads batch k + 1 and sorts it out to
    // the parts (ParallelDetector::prepare), then helps detect. A read error is raised
    // once every batch before it is written.
    struct Batch {
        std::vector<Event> events = std::vector<Event>(kBatch);
        std::vector<std::uint8_t> flags = std::vector<std::uint8_t>(kBatch);
        std::size_t n = 0;
        std::vector<io::SkipRun> skips;
        std::uint64_t bytes = 0;
        std::uint64_t events_so_far = 0;
        bool end = false;
        std::exception_ptr error;
    };
    auto run_parallel = [&](auto& par) {
        auto fetch = [&](Batch& b) {
            try {
                b.n = reader.read(b.events);
                const auto skips = reader.skipped_in_batch();
                b.skips.assign(skips.begin(), skips.end());
                b.bytes = reader.bytes_consumed();
                b.end = b.n == 0 && b.skips.empty();
                if (b.n > 0) par.prepare(std::span<const Event>(b.events.data(), b.n));
            } catch (...) {
                b.error = std::current_exception();
                b.n = 0;
                b.end = true;
            }
        };
        Batch* unwritten = nullptr;  // detected, not yet written
        auto write_unwritten = [&] {
            if (!unwritten) return;
            Batch& w = *unwritten;
            unwritten = nullptr;
            write_batch(std::span<const Event>(w.events.data(), w.n), std::span<const std::uint8_t>(w.flags.data(), w.n),
                        w.skips, w.bytes, w.events_so_far);
        };
        Batch batches[3];
        fetch(batches[0]);
        for (int cur = 0;; cur = (cur + 1) % 3) {
            Batch& b = batches[cur];
            Batch& next = batches[(cur + 1) % 3];
            if (b.end) {
                write_unwritten();
                if (b.error) std::rethrow_exception(b.error);
                break;
            }
            const auto alongside = [&] {
                write_unwritten();
                fetch(next);
            };
            const auto t0 = Clock::now();
            std::size_t c = 0;
            if (b.n > 0)
                c = par.run(std::span<std::uint8_t>(b.flags.data(), b.n), alongside);
            else
                alongside();
            totals.detect_s += std::chrono::duration<double>(Clock::now() - t0).count();
            totals.events += b.n;
            totals.corners += c;
            b.events_so_far = totals.events;
            unwritten = &b;
        }
    };
    try {
        if (o.threads > 1) {
            // Local detectors only: the sensor splits into parts (parallel_detect.hpp).
            if (o.detector == "efast") {
                ParallelDetector<EFast> par(size, o.threads, kCircleMargin, [](SensorSize s, int planes) { return EFast(s, planes); });
                run_parallel(par);
            } else {
                const HarrisParams hp = o.params.harris;
                ParallelDetector<Harris> par(size, o.threads, hp.window / 2, [hp](SensorSize s, int planes) { return Harris(s, hp, planes); });
                run_parallel(par);
            }
        } else {
            std::visit(
                [&](auto& det) {
                    while (step([&](std::span<const Event> batch) {
                        if constexpr (ScoredDetector<std::decay_t<decltype(det)>>) {
                            if (o.with_score) return detect(det, batch, flags, scores);
                        }
                        return detect(det, batch, flags);
                    })) {
                    }
                },
                detector);
        }
    } catch (const InputError& e) {
        progress.finish();
        finish_outputs();
        if (!o.allow_damaged) {
            if (totals.events > 0)
                fmt::print(stderr,
                           "evcorner: the {} events before the error were processed; their {} "
                           "corners are written\n",
                           totals.events, totals.corners);
            throw;
        }
        // --allow-damaged: the valid part before the damage is the result.
        fmt::print(stderr, "evcorner: warning: {}; the {} events before it were processed\n", e.what(),
                   totals.events);
        totals.damaged = e.what();
    }
    if (totals.damaged.empty()) {
        progress.finish();
        finish_outputs();
    }
    totals.skipped = reader.skipped();
    totals.wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();

    if (!o.quiet) print_summary(o, size, totals);
    if (!o.summary_json.empty()) write_summary_json(o, size, totals);
}

}  // namespace

void add_detect_command(CLI::App& app) {
    auto o = std::make_shared<DetectOptions>();
    std::string detectors;
    for (const auto& d : detector_infos()) detectors += fmt::format("\n  {:<13} {}", d.name, d.summary);

    CLI::App* cmd = app.add_subcommand(
        "detect",
        "Detect corner events in an event stream and write them out.\n"
        "Input: any format evcorner reads (see --format), told by the content; '-' reads\n"
        "standard input. Event-Camera-Dataset text is 't x y p' per line, t in seconds,\n"
        "p = 1 ON / 0 OFF. Output: the corner events, as such text lines unless OUTPUT's\n"
        "extension or --to names another format. A summary (events, corners, reduction rate,\n"
        "detection time per event, wall time) goes to standard error.");
    cmd->add_option("INPUT", o->input, "Event file, or - for standard input")->required();
    cmd->add_option("-d,--detector", o->detector, "Detector to run:" + detectors)
        ->capture_default_str()
        ->check([](const std::string& name) {
            for (const auto& d : detector_infos())
                if (d.name == name) return std::string();
            return "unknown detector '" + name + "'";
        });
    cmd->add_option("-o,--output", o->output,
                    "Corner events (- = standard output, as 't x y p' lines); the format follows the "
                    "extension (.txt, .csv, .npy, .aedat4, .h5, .hdf5; others are refused; none = text). "
                    "AEDAT 4.0 and HDF5 record the sensor size the detector ran on")
        ->capture_default_str();
    add_output_format_option(*cmd, o->to);
    add_input_options(*cmd, o->format, o->csv_columns, o->time_unit, o->chip);
    add_more_input_options(*cmd, o->more);
    cmd->add_option("--size", o->size,
                    "Sensor size WxH; events outside it are errors [default: the file's own "
                    "size, else 240x180, the DAVIS240C of the Event-Camera Dataset]")
        ->check([](const std::string& s) {
            return parse_sensor_size(s) ? std::string()
                                        : "expected WxH with sides 1..65536, e.g. 346x260";
        });
    cmd->add_option("--mask", o->mask,
                    "Also write one line per input event: 1 = corner, 0 = not (skipped events: 0)");
    cmd->add_option("--summary-json", o->summary_json,
                    "Also write the summary as JSON (keys include events, corners, "
                    "reduction_rate [%], ns_per_event). No two outputs may share a file or both be - "
                    "(standard output), and none may be the input");
    cmd->add_flag("--with-score", o->with_score,
                  "Append the detector's score to each corner line ('t x y p score'); harris and "
                  "harris-global only");
    cmd->add_option("--harris-window", o->params.harris.window,
                    "Harris (both): patch side, odd, 5..15 [default: 9]")
        ->check(CLI::Range(5, 15));
    cmd->add_option("--harris-nl", o->params.harris.nl,
                    "harris: newest distinct pixels lit in the patch, 1..window^2 [default: 25]")
        ->check(CLI::Range(1, 225));
    cmd->add_option("--harris-n", o->params.harris_global.n,
                    "harris-global: newest distinct pixels lit over the sensor per polarity "
                    "(1000 or 2000 in Vasco et al.) [default: 1000]")
        ->check(CLI::Range(1, 2147483647));
    cmd->add_option("--harris-k", o->params.harris.k, "Harris (both): k in H = det - k trace^2 [default: 0.04]");
    cmd->add_option("--harris-threshold", o->params.harris.threshold,
                    "Harris (both): corner iff score > threshold [default: 8]");
    cmd->add_option("-j,--threads", o->threads,
                    "Detection threads (efast, harris): the sensor splits into bands of rows per polarity, "
                    "each with a halo of the detector's radius, handed out to the threads batch by batch; "
                    "reading and writing overlap detection; output identical to one thread, same order")
        ->capture_default_str()
        ->check(CLI::Range(1, 256));
    cmd->add_flag("--allow-damaged", o->allow_damaged,
                  "A malformed line or a damaged or cut-short file ends the input with a warning "
                  "and exit status 0, instead of an error: the events before it are the result");
    cmd->add_flag("--skip-invalid", o->skip_invalid,
                  "Skip events outside the sensor (counted in the summary) instead of failing");
    cmd->add_flag("-q,--quiet", o->quiet, "No summary and no progress bar");
    cmd->add_flag("--no-progress", o->no_progress, "No progress bar (it shows only on a terminal)");
    cmd->footer(
        "Examples:\n"
        "  evcorner detect events.txt -o corners.txt\n"
        "  evcorner detect recording.raw -o corners.npy      # Prophesee EVT 3 in, numpy out\n"
        "  evcorner detect events.txt --mask is_corner.txt --summary-json summary.json > corners.txt\n"
        "  evcorner detect events.txt -d harris --with-score | head\n"
        "  evcorner detect events.txt -d harris-global --harris-n 2000\n"
        "  evcorner detect hd_recording.raw --threads 2 -o corners.npy\n"
        "  cat events.txt | evcorner detect - --size 346x260 | head");
    cmd->callback([o] {
        // --harris-window, -k and -threshold apply to both Harris detectors.
        o->params.harris_global.window = o->params.harris.window;
        o->params.harris_global.k = o->params.harris.k;
        o->params.harris_global.threshold = o->params.harris.threshold;
        run_detect(*o);
    });
}

}  // namespace evcorner::cli
