// evcorner bench: the paper's Table 2 (time per event, maximum event rate) for this
// machine, on any input, rerunnable by anyone.
//
// Method. Each input is read into memory once. Per input, first the cold figures: --repeat
// rounds, in each the yardstick (with --yardstick) and then every detector run once over the
// file as it is (one pass, a freshly built detector, construction not timed), timed with
// steady_clock around detect() alone: what a user running files as they come gets. Then the
// input is replayed until the stream holds at least --min-events events; repetition r is
// shifted by r x (span + 1 us + --replay-gap), so that time keeps increasing and, with the
// default gap of 100 ms (longer than any registered detector's time window: Arc*'s and
// FA-Harris's 50 ms filter), every copy meets the detectors' time windows as the file's own
// start does: cold and replayed passes then do the same work per event, and cold/replayed
// measures what a cold start costs (caches, first touch), not a filter rejecting more events
// of a copy that follows its predecessor within 50 ms. The identical copies of a short file
// repeat one sequence of events, which the CPU's branch predictors partly learn: the replayed
// figure of a 30 000-event file is faster than a continuous stream of the same kind, and its
// cold/replayed larger than the cold start costs (docs/performance.md, "What a replay
// measures"; bench/bench_warmup.cpp measures the cold start on a continuous recording).
// Per detector:
//  - throughput: --repeat passes over the whole stream, each with a freshly built detector
//    (construction not timed), timed with steady_clock around detect() alone; ns/event
//    median, min and max over the passes; max event rate = 1e9 / median ns/event.
//  - latency: one more pass timing every event on its own with the time-stamp counter
//    (rdtscp ... lfence around each process() call; TSC ticks converted to ns by
//    calibrating against steady_clock over that pass). The median cost of an empty timed
//    section (the clock's own overhead) is measured first and subtracted; it is printed.
//    The timed pass runs slower than the throughput passes (the fences stop events from
//    overlapping), so its percentiles bound a single event's latency from above.
//  - --cpu-time: passes timed by the thread's CPU time instead of steady_clock (for a shared
//    machine: it leaves out the time other processes hold the core).
//  - --threads 1,2,...: the local detectors (the registry says which) also run split over
//    that many threads (parallel_detect.hpp), timed the same way; thread start-up is
//    outside the timing.
// --yardstick: a plain exhaustive eFAST built into the tool (bench_command_yardstick.hpp),
// compiled with the same compiler and flags; per input and detector the ratio of its cold
// ns/event to the detector's cold ns/event (how many times faster than the yardstick), and the
// median of those ratios over the inputs.
// --tracker NAME (repeatable; all = every registered tracker): the trackers instead of the
// detectors, seeded as `evcorner track` seeds them (--seeds FILE, or the corners of the one
// detector -d names). --repeat rounds over each input as it is (no replay); in each, eFAST
// detect (fresh, timed with steady_clock) and then every tracker once through
// pipeline::run_track (a fresh tracker; the pipeline times the tracker's calls alone, by
// steady_clock). Per tracker: ns per event, ns per in-range (event, track) update
// (TrackerStats::updates), live tracks, and its ns per event over eFAST's in the same round;
// medians over the rounds.
// Data flows one way: the timing wraps the loop; the detectors know nothing of it.

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fmt/format.h>
#include <fstream>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#define EVCORNER_HAVE_TSC 1
#endif

#include "commands.hpp"
#include "detector_options.hpp"
#include "eval_common.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/io/memory_reader.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/pipeline/track.hpp"
#include "evcorner/state_memory.hpp"
#include "evcorner/track/tracker.hpp"
#include "evcorner/parallel_detect.hpp"
#include "bench_command_yardstick.hpp"
#include "progress.hpp"
#include "std_streams.hpp"

#ifndef EVCORNER_BUILD_TYPE
#define EVCORNER_BUILD_TYPE "unknown"
#endif
#ifndef EVCORNER_BUILD_FLAGS
#define EVCORNER_BUILD_FLAGS "unknown"
#endif

namespace evcorner::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct BenchOptions {
    std::vector<std::string> inputs;
    std::string detectors = all_detectors_list();
    ParamValues detector_params;
    int repeat = 5;
    std::uint64_t min_events = 10'000'000;
    std::int64_t replay_gap_us = 100'000;
    std::string json;
    InputOptions in;
    std::string threads = "1";
    bool no_latency = false;
    bool yardstick = false;
    bool cpu_time = false;
    bool quiet = false;
    bool no_progress = false;
    // Trackers (--tracker): timed instead of the detectors, seeded from --seeds or -d.
    std::vector<std::string> trackers;
    std::string seeds;
    std::string init = "centered";
    bool detectors_given = false;  // -d on the command line (the default lists every detector)
};

struct Row {
    std::string input;
    std::string detector;
    int threads = 1;
    SensorSize sensor;
    std::uint64_t file_events = 0;
    std::uint64_t events = 0;  // after replay
    std::uint64_t corners = 0;
    std::vector<double> ns_per_event;  // one per pass
    double median = 0, min = 0, max = 0;
    double p50 = 0, p99 = 0, p999 = 0;  // ns; 0 when not measured
    std::size_t memory = 0;
    // Cold: one pass over the file itself per round (one thread only; empty otherwise).
    std::vector<double> cold_ns_per_event;
    double cold_median = 0;
    std::uint64_t cold_corners = 0;
    double yardstick_median = 0;  // the yardstick's cold ns/event on this input; 0 when not asked
    std::uint64_t yardstick_corners = 0;
};

// The cold passes of one input: per round, the yardstick's and each detector's.
struct ColdRuns {
    std::vector<double> yardstick_ns;
    std::uint64_t yardstick_corners = 0;
    std::vector<std::vector<double>> ns;  // per detector, per round
    std::vector<std::uint64_t> corners;   // per detector
};

// One tracker on one input: --repeat rounds, each one pass over the file beside eFAST's.
struct TrackerRow {
    std::string input;
    std::string tracker;
    SensorSize sensor;
    std::uint64_t events = 0;
    std::uint64_t corners = 0;  // the seeding detector's, with -d
    TrackerStats stats;         // of the last round (every round does the same work)
    std::vector<double> ns_per_event, ns_per_update, efast_ns_per_event, efast_ratio;  // per round
    double median_event = 0, median_update = 0, median_efast = 0, median_ratio = 0;
};

// ----------------------------------------------------------------- machine description

std::string cpu_model() {
    std::ifstream in("/proc/cpuinfo");
    std::string line, name, family, model, stepping;
    auto value = [](const std::string& l) {
        const auto c = l.find(':');
        std::string v = c == std::string::npos ? "" : l.substr(c + 1);
        v.erase(0, v.find_first_not_of(" \t"));
        return v;
    };
    while (std::getline(in, line)) {
        if (line.empty() && !name.empty()) break;  // first processor only
        if (line.rfind("model name", 0) == 0) name = value(line);
        else if (line.rfind("cpu family", 0) == 0) family = value(line);
        else if (line.rfind("model", 0) == 0 && line.rfind("model name", 0) != 0) model = value(line);
        else if (line.rfind("stepping", 0) == 0) stepping = value(line);
    }
    if (name.empty()) name = "unknown CPU";
    if (!family.empty()) name += fmt::format(" (family {}, model {}, stepping {})", family, model, stepping);
    return name;
}

std::string compiler() {
#if defined(__clang__)
    return "clang " __clang_version__;
#elif defined(__GNUC__)
    return "g++ " __VERSION__;
#else
    return "unknown compiler";
#endif
}

// ----------------------------------------------------------------- input

/// The file's events repeated until there are at least `min_events`, each repetition
/// shifted in time past the previous one, `gap_us` after its last event.
std::vector<Event> replay(const std::vector<Event>& file, std::uint64_t min_events, std::int64_t gap_us) {
    if (file.empty()) return {};
    const std::uint64_t reps = std::max<std::uint64_t>(1, (min_events + file.size() - 1) / file.size());
    // The replayed stream and one flag per event (the detectors' output).
    require_memory_fits(fmt::format("bench --min-events {}: {} replayed events", min_events, reps * file.size()),
                        reps * file.size() * (sizeof(Event) + 1), " (lower --min-events)");
    const std::int64_t shift = file.back().t - file.front().t + 1 + gap_us;
    std::vector<Event> out;
    out.reserve(reps * file.size());
    for (std::uint64_t r = 0; r < reps; ++r) {
        const std::int64_t dt = static_cast<std::int64_t>(r) * shift;
        for (Event e : file) {
            e.t += dt;
            out.push_back(e);
        }
    }
    return out;
}

// ----------------------------------------------------------------- timing

double median_of(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

#ifdef EVCORNER_HAVE_TSC
inline std::uint64_t tsc_begin() noexcept {
    _mm_lfence();
    return __rdtsc();
}
inline std::uint64_t tsc_end() noexcept {
    unsigned aux;
    const std::uint64_t t = __rdtscp(&aux);
    _mm_lfence();
    return t;
}
#endif

struct Latency {
    double p50 = 0, p99 = 0, p999 = 0;
    double overhead_ns = 0;
    double resolution_ns = 0;
};

/// Times every event on its own; returns percentiles in ns, clock overhead removed.
template <class D>
Latency time_each_event(D& det, const std::vector<Event>& events) {
    Latency out;
#ifdef EVCORNER_HAVE_TSC
    std::vector<std::uint32_t> ticks(events.size());
    // The timer's own cost: the median of empty timed sections.
    std::vector<std::uint32_t> empty(100'000);
    for (auto& e : empty) {
        const std::uint64_t a = tsc_begin();
        const std::uint64_t b = tsc_end();
        e = static_cast<std::uint32_t>(b - a);
    }
    std::nth_element(empty.begin(), empty.begin() + static_cast<std::ptrdiff_t>(empty.size() / 2), empty.end());
    const std::uint32_t overhead = empty[empty.size() / 2];
    // The counter's step: the typical (median) non-zero difference of back-to-back reads.
    std::vector<std::uint64_t> steps;
    for (int i = 0; i < 10'001; ++i) {
        const std::uint64_t a = __rdtsc();
        const std::uint64_t b = __rdtsc();
        if (b > a) steps.push_back(b - a);
    }
    std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
    const std::uint64_t step = steps.empty() ? UINT64_MAX : steps[steps.size() / 2];

    volatile std::uint8_t sink = 0;
    const auto c0 = Clock::now();
    const std::uint64_t k0 = __rdtsc();
    for (std::size_t i = 0; i < events.size(); ++i) {
        const std::uint64_t a = tsc_begin();
        const bool c = det.process(events[i]);
        const std::uint64_t b = tsc_end();
        sink = sink + static_cast<std::uint8_t>(c);
        const std::uint64_t d = b - a;
        ticks[i] = d > overhead ? static_cast<std::uint32_t>(std::min<std::uint64_t>(d - overhead, UINT32_MAX)) : 0;
    }
    const std::uint64_t k1 = __rdtsc();
    const double seconds = std::chrono::duration<double>(Clock::now() - c0).count();
    const double ns_per_tick = seconds * 1e9 / static_cast<double>(k1 - k0);
    auto pct = [&](double q) {
        const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(ticks.size() - 1));
        std::nth_element(ticks.begin(), ticks.begin() + k, ticks.end());
        return ticks[static_cast<std::size_t>(k)] * ns_per_tick;
    };
    out.p50 = pct(0.5);
    out.p99 = pct(0.99);
    out.p999 = pct(0.999);
    out.overhead_ns = overhead * ns_per_tick;
    out.resolution_ns = step == UINT64_MAX ? 0.0 : static_cast<double>(step) * ns_per_tick;
#else
    (void)det;
    (void)events;
#endif
    return out;
}

// A row of `repeat` throughput passes over `events`. pass(row, flags) builds a fresh
// detector, runs it over the stream inside `time(...)`, and sets the row's corners and
// memory; the row gets ns/event per pass and their median, min and max.
// Called after each pass over a stream (outside the timing) with the events it ran over.
using PassDone = std::function<void(std::uint64_t events)>;

template <class Pass>
Row timed_passes(const std::string& input, const std::string& name, int threads, SensorSize sensor,
                 const std::vector<Event>& events, std::uint64_t file_events, int repeat, bool cpu_time, Pass pass,
                 const PassDone& done) {
    Row row;
    row.input = input;
    row.detector = name;
    row.threads = threads;
    row.sensor = sensor;
    row.file_events = file_events;
    row.events = events.size();
    std::vector<std::uint8_t> flags(events.size());
    const double n = static_cast<double>(events.size());
    for (int r = 0; r < repeat; ++r) {
        pass(row, flags, [&](auto&& run) {
            const double t0 = bench_clock_ns(cpu_time);
            run();
            row.ns_per_event.push_back((bench_clock_ns(cpu_time) - t0) / n);
        });
        done(events.size());
    }
    row.median = median_of(row.ns_per_event);
    row.min = *std::min_element(row.ns_per_event.begin(), row.ns_per_event.end());
    row.max = *std::max_element(row.ns_per_event.begin(), row.ns_per_event.end());
    return row;
}

Row bench_one(const std::string& input, const std::string& name, SensorSize sensor,
              const std::vector<Event>& events, std::uint64_t file_events, const BenchOptions& o,
              Latency& clock, const PassDone& done) {
    Row row = timed_passes(input, name, 1, sensor, events, file_events, o.repeat, o.cpu_time,
                           [&](Row& r, std::vector<std::uint8_t>& flags, auto time) {
                               AnyDetector any = make_detector(config_for(name, o.detector_params), sensor, "--");
                               r.memory = memory_bytes(any);
                               std::visit(
                                   [&](auto& det) {
                                       time([&] { r.corners = detect(det, std::span<const Event>(events), flags); });
                                   },
                                   any);
                           },
                           done);
    if (!o.no_latency) {
        AnyDetector any = make_detector(config_for(name, o.detector_params), sensor, "--");
        std::visit(
            [&](auto& det) {
                const Latency l = time_each_event(det, events);
                row.p50 = l.p50;
                row.p99 = l.p99;
                row.p999 = l.p999;
                clock = l;
            },
            any);
        done(events.size());
    }
    return row;
}

/// The cold figures of one input: --repeat rounds over the file as it is (no replay); in each
/// round the yardstick (when asked), then every detector once with a fresh detector.
ColdRuns cold_runs(const std::vector<Event>& file, SensorSize sensor, const std::vector<std::string>& detectors,
                   const BenchOptions& o, const PassDone& done) {
    ColdRuns cold;
    cold.ns.resize(detectors.size());
    cold.corners.resize(detectors.size());
    std::vector<std::uint8_t> flags(file.size());
    const double n = static_cast<double>(file.size());
    for (int r = 0; r < o.repeat; ++r) {
        if (o.yardstick) {
            const YardstickPass y = plain_efast_pass(std::span<const Event>(file), sensor, o.cpu_time);
            cold.yardstick_ns.push_back(y.ns_per_event);
            cold.yardstick_corners = y.corners;
            done(file.size());
        }
        for (std::size_t d = 0; d < detectors.size(); ++d) {
            AnyDetector any = make_detector(config_for(detectors[d], o.detector_params), sensor, "--");
            std::visit(
                [&](auto& det) {
                    const double t0 = bench_clock_ns(o.cpu_time);
                    cold.corners[d] = detect(det, std::span<const Event>(file), flags);
                    cold.ns[d].push_back((bench_clock_ns(o.cpu_time) - t0) / n);
                },
                any);
            done(file.size());
        }
    }
    return cold;
}

/// Throughput passes with the sensor split over `threads` threads (parallel_detect.hpp).
Row bench_parallel(const std::string& input, const std::string& name, int threads, SensorSize sensor,
                   const std::vector<Event>& events, std::uint64_t file_events, const BenchOptions& o,
                   const PassDone& done) {
    auto passes = [&](auto make_par) {
        return timed_passes(input, name, threads, sensor, events, file_events, o.repeat, o.cpu_time,
                            [&](Row& r, std::vector<std::uint8_t>& flags, auto time) {
                                auto par = make_par();  // threads started outside the timing
                                time([&] { r.corners = par->detect(std::span<const Event>(events), flags); });
                                r.memory = par->memory_bytes([](const auto& d) { return d.memory_bytes(); });
                            },
                            done);
    };
    const DetectorConfig config = config_for(name, o.detector_params);
    return with_detector_entry(name, [&](const auto& entry) {
        using D = typename std::remove_cvref_t<decltype(entry)>::Detector;
        if (entry.split == Split::none)
            throw std::invalid_argument("--threads: detector '" + name + "' is not local (" + std::string(entry.not_local) + ")");
        const auto params = entry.params_of(config.params, "--");
        return passes([&] {
            return std::make_unique<ParallelDetector<D>>(
                sensor, threads, Locality(entry.radius(params), entry.split == Split::by_polarity),
                [&entry, params](SensorSize s, int planes) { return entry.make(s, params, planes); });
        });
    });
}

// ----------------------------------------------------------------- trackers

/// What `evcorner track` would run for `tracker` with these seeds (--seeds), or seeded from
/// the corners of -d's one detector with that command's front-end stopping rules.
pipeline::TrackOptions track_options(const BenchOptions& o, const std::string& tracker,
                                     const std::vector<TrackSeed>& seeds, const std::string& seed_detector) {
    pipeline::TrackOptions t;
    t.tracker = tracker;
    t.config.init = o.init == "centered" ? HasteInit::centered : HasteInit::uncentered;
    if (seed_detector.empty()) {
        t.config.seeds = seeds;
    } else {
        pipeline::DetectOptions d;
        d.detector = config_for(seed_detector, o.detector_params);
        d.param_prefix = "--";
        t.detect = d;
        t.config.stop.max_idle_us = 200000;  // evcorner track -d's defaults (docs/tracking.md, "Front end")
        t.config.stop.min_separation = 3;
    }
    pipeline::check_track_options(t);
    return t;
}

/// --repeat rounds over the file as it is; in each, eFAST detect (a fresh detector; the
/// reference of the ratio) and then every tracker once through pipeline::run_track, which
/// times the tracker's calls alone (steady_clock; with -d the detector in front is not in it).
/// eFAST is timed by the same clock.
std::vector<TrackerRow> tracker_runs(const std::string& input, const std::vector<Event>& file, SensorSize sensor,
                                     const std::vector<pipeline::TrackOptions>& runs, const BenchOptions& o,
                                     const PassDone& done) {
    std::vector<TrackerRow> rows(runs.size());
    for (std::size_t i = 0; i < runs.size(); ++i) {
        rows[i].input = input;
        rows[i].tracker = runs[i].tracker;
        rows[i].sensor = sensor;
    }
    std::vector<std::uint8_t> flags(file.size());
    const double n = static_cast<double>(file.size());
    const auto discard = [](std::span<const TrackState>) {};
    for (int r = 0; r < o.repeat; ++r) {
        double efast_ns = 0;
        AnyDetector efast = make_detector(DetectorConfig{"efast", {}}, sensor, "--");
        std::visit(
            [&](auto& det) {
                const double t0 = bench_clock_ns(false);
                (void)detect(det, std::span<const Event>(file), flags);
                efast_ns = (bench_clock_ns(false) - t0) / n;
            },
            efast);
        done(file.size());
        for (std::size_t i = 0; i < runs.size(); ++i) {
            io::MemoryReader reader(file, sensor, input);
            const pipeline::TrackSummary t = pipeline::run_track(reader, runs[i], discard, sensor);
            TrackerRow& row = rows[i];
            row.events = t.events;
            row.corners = t.corners;
            row.stats = t.stats;
            row.ns_per_event.push_back(t.ns_per_event());
            if (t.stats.updates > 0) row.ns_per_update.push_back(t.ns_per_update());
            row.efast_ns_per_event.push_back(efast_ns);
            row.efast_ratio.push_back(efast_ns > 0 ? t.ns_per_event() / efast_ns : 0.0);
            done(file.size());
        }
    }
    for (TrackerRow& row : rows) {
        row.median_event = median_of(row.ns_per_event);
        row.median_update = median_of(row.ns_per_update);  // 0: no update in range
        row.median_efast = median_of(row.efast_ns_per_event);
        row.median_ratio = median_of(row.efast_ratio);
    }
    return rows;
}

// ----------------------------------------------------------------- report

std::string short_name(const std::string& path) {
    // parent/name is enough to tell the real files apart (ecd-stppp/x/events.txt).
    const auto slash = path.find_last_of('/');
    if (slash == std::string::npos || slash == 0) return path;
    const auto prev = path.find_last_of('/', slash - 1);
    std::string s = path.substr(prev == std::string::npos ? 0 : prev + 1);
    if (s.size() > 34) s = "..." + s.substr(s.size() - 31);
    return s;
}

void print_table(std::FILE* out, const std::vector<Row>& rows, const std::vector<std::string>& detectors,
                 const std::vector<int>& thread_counts, bool latency, bool yardstick) {
    fmt::print(out, "{:<34} {:<13} {:>3} {:>10} {:>7} {:>7} {:>7} {:>8} {:>7} {:>8}", "input", "detector", "thr",
               "events", "median", "min", "max", "Mev/s", "cold", "cold/rep");
    if (yardstick) fmt::print(out, " {:>7} {:>7}", "yard", "x yard");
    if (latency) fmt::print(out, " {:>7} {:>7} {:>7}", "p50", "p99", "p99.9");
    fmt::print(out, " {:>11}\n", "memory [B]");
    fmt::print(out, "{:<34} {:<13} {:>3} {:>10} {:>23} {:>8} {:>16}", "", "", "", "", "replayed ns/event", "max rate",
               "cold ns/event");
    if (yardstick) fmt::print(out, " {:>15}", "yardstick cold");
    if (latency) fmt::print(out, " {:>23}", "latency ns/event");
    fmt::print(out, "\n");
    // cold = 0: not measured (several threads); yard = 0: no yardstick.
    auto line = [&](const std::string& in, const Row& r, double yard_ratio) {
        fmt::print(out, "{:<34} {:<13} {:>3} {:>10} {:>7.1f} {:>7.1f} {:>7.1f} {:>8.2f}", in, r.detector, r.threads,
                   r.events, r.median, r.min, r.max, r.median > 0 ? 1e3 / r.median : 0.0);
        if (r.cold_median > 0)
            fmt::print(out, " {:>7.1f} {:>8.2f}", r.cold_median, r.median > 0 ? r.cold_median / r.median : 0.0);
        else
            fmt::print(out, " {:>7} {:>8}", "-", "-");
        if (yardstick && r.cold_median > 0 && r.yardstick_median > 0)
            fmt::print(out, " {:>7.1f} {:>7.2f}", r.yardstick_median, yard_ratio);
        else if (yardstick)
            fmt::print(out, " {:>7} {:>7}", "-", "-");
        if (latency && r.p50 > 0)
            fmt::print(out, " {:>7.0f} {:>7.0f} {:>7.0f}", r.p50, r.p99, r.p999);
        else if (latency)
            fmt::print(out, " {:>7} {:>7} {:>7}", "-", "-", "-");
        fmt::print(out, " {:>11}\n", r.memory);
    };
    auto ratio = [](const Row& r) { return r.cold_median > 0 ? r.yardstick_median / r.cold_median : 0.0; };
    for (const Row& r : rows) line(short_name(r.input), r, ratio(r));
    std::size_t files = 0;
    for (const Row& r : rows) files += r.detector == detectors.front() && r.threads == thread_counts.front();
    if (files < 2) return;
    fmt::print(out,
               "\nmedian over the {} inputs of the per-input figures (min: smallest min, max: largest max; "
               "x yard: median of the per-input ratios):\n",
               files);
    for (const std::string& d : detectors)
    for (const int thr : thread_counts) {
        std::vector<double> med, p50, p99, p999, cold, yard, ratios;
        Row all;
        all.detector = d;
        all.threads = thr;
        all.min = 1e300;
        for (const Row& r : rows) {
            if (r.detector != d || r.threads != thr) continue;
            all.events += r.events;
            med.push_back(r.median);
            p50.push_back(r.p50);
            p99.push_back(r.p99);
            p999.push_back(r.p999);
            cold.push_back(r.cold_median);
            yard.push_back(r.yardstick_median);
            ratios.push_back(ratio(r));
            all.min = std::min(all.min, r.min);
            all.max = std::max(all.max, r.max);
            all.memory = std::max(all.memory, r.memory);
        }
        if (med.empty()) continue;
        all.median = median_of(med);
        all.p50 = median_of(p50);
        all.p99 = median_of(p99);
        all.p999 = median_of(p999);
        all.cold_median = median_of(cold);
        all.yardstick_median = median_of(yard);
        line("all inputs", all, median_of(ratios));
    }
}

void write_json(const std::string& path, const std::vector<Row>& rows, const std::string& cpu,
                const Latency& clock, const BenchOptions& o) {
    nlohmann::json j;
    j["cpu"] = cpu;
    j["compiler"] = compiler();
    j["build_type"] = EVCORNER_BUILD_TYPE;
    j["build_flags"] = EVCORNER_BUILD_FLAGS;
    j["efast_code_path"] = efast_code_path();
    j["repeat"] = o.repeat;
    j["clock"] = o.cpu_time ? "thread CPU time" : "steady_clock";
    j["yardstick"] = o.yardstick ? nlohmann::json("built-in plain exhaustive eFAST (bench_command_yardstick.cpp), "
                                                  "same compiler and flags")
                                 : nlohmann::json(nullptr);
    j["min_events"] = o.min_events;
    j["replay_gap_us"] = o.replay_gap_us;
    j["latency_clock_overhead_ns"] = o.no_latency ? nlohmann::json(nullptr) : nlohmann::json(clock.overhead_ns);
    j["latency_clock_resolution_ns"] = o.no_latency ? nlohmann::json(nullptr) : nlohmann::json(clock.resolution_ns);
    j["results"] = nlohmann::json::array();
    for (const Row& r : rows) {
        nlohmann::json x;
        x["input"] = r.input;
        x["detector"] = r.detector;
        x["threads"] = r.threads;
        x["width"] = r.sensor.width;
        x["height"] = r.sensor.height;
        x["file_events"] = r.file_events;
        x["events"] = r.events;
        x["corners"] = r.corners;
        x["ns_per_event"] = r.ns_per_event;
        x["ns_per_event_median"] = r.median;
        x["ns_per_event_min"] = r.min;
        x["ns_per_event_max"] = r.max;
        x["max_event_rate_meps"] = r.median > 0 ? 1e3 / r.median : 0.0;
        if (!o.no_latency && r.p50 > 0) {
            x["latency_ns_p50"] = r.p50;
            x["latency_ns_p99"] = r.p99;
            x["latency_ns_p999"] = r.p999;
        }
        x["memory_bytes"] = r.memory;
        if (r.cold_median > 0) {
            x["cold_events"] = r.file_events;
            x["cold_corners"] = r.cold_corners;
            x["cold_ns_per_event"] = r.cold_ns_per_event;
            x["cold_ns_per_event_median"] = r.cold_median;
            x["cold_vs_replayed"] = r.median > 0 ? r.cold_median / r.median : 0.0;
            if (r.yardstick_median > 0) {
                x["yardstick_ns_per_event_median"] = r.yardstick_median;
                x["yardstick_ratio"] = r.yardstick_median / r.cold_median;
                x["yardstick_corners"] = r.yardstick_corners;
            }
        }
        j["results"].push_back(std::move(x));
    }
    io::OutputFile out(path);
    out.write(j.dump(2));
    out.write("\n");
    out.close();
}

void print_tracker_table(std::FILE* out, const std::vector<TrackerRow>& rows, bool with_corners) {
    fmt::print(out, "{:<34} {:<23} {:>10} {:>8} {:>6} {:>12} {:>9} {:>9} {:>8} {:>8}\n", "input", "tracker", "events",
               "started", "live", "updates", "ns/event", "ns/update", "efast", "x efast");
    fmt::print(out, "{:<34} {:<23} {:>10} {:>8} {:>6} {:>12} {:>19} {:>8} {:>8}\n", "", "", "", "tracks", "", "in range",
               "tracking, median", "ns/event", "ns/event");
    for (const TrackerRow& r : rows) {
        fmt::print(out, "{:<34} {:<23} {:>10} {:>8} {:>6} {:>12} {:>9.1f}", short_name(r.input), r.tracker, r.events,
                   r.stats.started, r.stats.live, r.stats.updates, r.median_event);
        if (r.median_update > 0)
            fmt::print(out, " {:>9.1f}", r.median_update);
        else
            fmt::print(out, " {:>9}", "-");
        fmt::print(out, " {:>8.1f} {:>8.2f}\n", r.median_efast, r.median_ratio);
    }
    if (with_corners && !rows.empty())
        fmt::print(out, "(seeding detector: {} corner events on {})\n", rows.front().corners, short_name(rows.front().input));
}

void write_tracker_json(const std::string& path, const std::vector<TrackerRow>& rows, const std::string& cpu,
                        const BenchOptions& o, const std::string& seeding) {
    nlohmann::json j;
    j["cpu"] = cpu;
    j["compiler"] = compiler();
    j["build_type"] = EVCORNER_BUILD_TYPE;
    j["build_flags"] = EVCORNER_BUILD_FLAGS;
    j["efast_code_path"] = efast_code_path();
    j["repeat"] = o.repeat;
    j["clock"] = "steady_clock";
    j["seeding"] = seeding;
    j["init"] = o.init;
    j["results"] = nlohmann::json::array();  // no detector rows with --tracker
    j["trackers"] = nlohmann::json::array();
    for (const TrackerRow& r : rows) {
        nlohmann::json x;
        x["input"] = r.input;
        x["tracker"] = r.tracker;
        x["width"] = r.sensor.width;
        x["height"] = r.sensor.height;
        x["events"] = r.events;
        x["corners"] = r.corners;
        x["tracks_started"] = r.stats.started;
        x["tracks_initialised"] = r.stats.initialised;
        x["seeds_skipped"] = r.stats.skipped_seeds;
        x["live"] = r.stats.live;
        x["updates"] = r.stats.updates;
        x["ns_per_event"] = r.ns_per_event;
        x["ns_per_event_median"] = r.median_event;
        x["ns_per_update"] = r.ns_per_update;
        x["ns_per_update_median"] = r.median_update > 0 ? nlohmann::json(r.median_update) : nlohmann::json(nullptr);
        x["efast_ns_per_event"] = r.efast_ns_per_event;
        x["efast_ns_per_event_median"] = r.median_efast;
        x["efast_ratio"] = r.efast_ratio;
        x["efast_ratio_median"] = r.median_ratio;
        j["trackers"].push_back(std::move(x));
    }
    io::OutputFile out(path);
    out.write(j.dump(2));
    out.write("\n");
    out.close();
}

/// evcorner bench --tracker: the trackers instead of the detectors, each beside eFAST detect.
void run_tracker_bench(const BenchOptions& o) {
    std::FILE* const out = o.json == "-" ? stderr : stdout;
    std::vector<std::string> trackers;
    try {
        trackers = tracker_list(o.trackers);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("--tracker: ") + e.what());
    }
    if (o.threads != "1") throw std::invalid_argument("--threads: trackers run on one thread; drop --threads with --tracker");
    if (o.yardstick) throw std::invalid_argument("--yardstick: not with --tracker (the tracker rows have eFAST's ratio)");
    if (o.cpu_time)
        throw std::invalid_argument("--cpu-time: not with --tracker (the tracking pipeline times the tracker's calls "
                                    "by steady_clock)");
    // Seeds from a file, or the corners of the one detector -d names (as evcorner track).
    if (o.seeds.empty() == !o.detectors_given)
        throw std::invalid_argument("--tracker: give exactly one of --seeds FILE and -d DETECTOR (the detector whose "
                                    "corners seed the tracks, as in evcorner track)");
    std::string seed_detector, seeding;
    std::vector<TrackSeed> seeds;
    if (o.detectors_given) {
        const std::vector<std::string> d = parse_detector_list(o.detectors);
        if (d.size() != 1)
            throw std::invalid_argument("-d: with --tracker, one detector, whose corners seed the tracks; got '" +
                                        o.detectors + "'");
        seed_detector = d.front();
        check_params_taken(d, o.detector_params, "--");
        check_detector_config(config_for(seed_detector, o.detector_params), "--");
        seeding = "corners of " + seed_detector;
    } else {
        seeds = read_seeds_file(o.seeds);
        if (seeds.empty()) throw std::invalid_argument("--seeds: " + o.seeds + " holds no seed");
        seeding = fmt::format("{} seeds from {}", seeds.size(), o.seeds);
    }
    std::vector<pipeline::TrackOptions> runs;
    for (const std::string& t : trackers) runs.push_back(track_options(o, t, seeds, seed_detector));

    const std::string cpu = cpu_model();
    std::string names;
    for (const std::string& t : trackers) names += (names.empty() ? "" : ",") + t;
    fmt::print(out, "evcorner bench: {} input(s), trackers {}, {} round(s) each\n", o.inputs.size(), names, o.repeat);
    fmt::print(out, "CPU      {}\n", cpu);
    fmt::print(out, "build    {} build, {}, flags: {}; eFAST code path: {}\n", EVCORNER_BUILD_TYPE, compiler(),
               EVCORNER_BUILD_FLAGS, efast_code_path());
    fmt::print(out, "method   one thread; per round, eFAST detect and then each tracker once over each file as it is\n"
               "         (no replay), a fresh tracker each (pipeline::run_track), {} start; seeds: {};\n"
               "         steady_clock around the tracker's calls alone; median over the rounds;\n"
               "         x efast: tracker ns/event over eFAST's in the same round (median)\n\n",
               o.init, seeding);
    flush_checked(out);

    const std::uint64_t runs_per_input = static_cast<std::uint64_t>(o.repeat) * (1 + trackers.size());
    Progress progress(!o.quiet && !o.no_progress, runs_per_input * o.inputs.size());
    std::uint64_t passes_done = 0, events_done = 0;
    const PassDone done = [&](std::uint64_t events) {
        ++passes_done;
        events_done += events;
        progress.update(passes_done, events_done);
    };
    std::vector<TrackerRow> rows;
    for (const std::string& input : o.inputs) {
        LoadedEvents file = load_events(input, o.in, !o.quiet && !o.no_progress);
        if (file.events.empty()) {
            progress.finish();
            fmt::print(stderr, "evcorner bench: {}: no events, skipped\n", input);
            passes_done += runs_per_input;
            continue;
        }
        for (TrackerRow& r : tracker_runs(input, file.events, file.size, runs, o, done)) {
            if (!o.quiet) {
                progress.finish();
                fmt::print(stderr, "  {} {}: {:.1f} ns/event, {:.1f} ns/update\n", short_name(input), r.tracker,
                           r.median_event, r.median_update);
            }
            rows.push_back(std::move(r));
        }
    }
    progress.finish();
    if (!o.quiet) fmt::print(stderr, "\n");
    print_tracker_table(out, rows, !seed_detector.empty());
    flush_checked(out);
    if (!o.json.empty()) write_tracker_json(o.json, rows, cpu, o, seeding);
}

std::vector<std::string> split_list(const std::string& s) {
    std::vector<std::string> v;
    std::stringstream in(s);
    std::string item;
    while (std::getline(in, item, ','))
        if (!item.empty()) v.push_back(item);
    return v;
}

void run_bench(const BenchOptions& o) {
    {
        std::vector<io::NamedPath> inputs;
        for (const auto& in : o.inputs) inputs.push_back({"FILE", in});
        if (!o.json.empty()) {
            io::check_output_paths(inputs, {{"--json", o.json}});
            io::check_outputs_creatable({{"--json", o.json}});
        }
    }
    if (!o.trackers.empty()) {
        run_tracker_bench(o);
        return;
    }
    if (!o.seeds.empty()) throw std::invalid_argument("--seeds: only with --tracker");
    // With the JSON on standard output, the human-readable report goes to standard error.
    std::FILE* const out = o.json == "-" ? stderr : stdout;
    const std::vector<std::string> detectors = parse_detector_list(o.detectors);  // unknown names fail now
    check_params_taken(detectors, o.detector_params, "--");
    for (const auto& d : detectors) check_detector_config(config_for(d, o.detector_params), "--");
    std::vector<int> thread_counts;
    for (const auto& t : split_list(o.threads)) {
        const int k = std::atoi(t.c_str());
        if (k < 1 || k > 256) throw std::invalid_argument("--threads: expected counts 1..256, got '" + t + "'");
        thread_counts.push_back(k);
    }
    if (thread_counts.empty()) thread_counts.push_back(1);
    if (o.cpu_time && std::any_of(thread_counts.begin(), thread_counts.end(), [](int k) { return k > 1; }))
        throw std::invalid_argument("--cpu-time: one thread's CPU time does not time several threads; use --threads 1");

    const std::string cpu = cpu_model();
    fmt::print(out, "evcorner bench: {} input(s), detectors {}, {} pass(es) each over >= {} events\n",
               o.inputs.size(), o.detectors, o.repeat, o.min_events);
    fmt::print(out, "CPU      {}\n", cpu);
    fmt::print(out, "build    {} build, {}, flags: {}; eFAST code path: {}\n", EVCORNER_BUILD_TYPE, compiler(),
               EVCORNER_BUILD_FLAGS, efast_code_path());
    fmt::print(out, "method   one thread; throughput: {} around detect() over the replayed stream\n"
               "         (copies {} us apart),\n",
               o.cpu_time ? "thread CPU time" : "steady_clock", o.replay_gap_us);
    fmt::print(out, "         fresh detector per pass; cold: the same over each file once (no replay){};\n"
               "         latency: rdtscp/lfence around each event, clock overhead\n"
               "         subtracted (fenced, so an upper bound)\n\n",
               o.yardstick ? ", beside the yardstick (a built-in plain eFAST)" : "");
    flush_checked(out);

    // The progress bar counts passes: per input, each detector and thread count runs
    // --repeat passes, plus one latency pass on one thread.
    std::uint64_t runs_per_input = 0;
    for (const std::string& d : detectors)
        for (const int thr : thread_counts) {
            if (thr > 1 && !detector_info(d).local()) continue;
            runs_per_input += static_cast<std::uint64_t>(o.repeat) * (thr == 1 ? 2 : 1) + (thr == 1 && !o.no_latency ? 1 : 0);
        }
    if (o.yardstick) runs_per_input += static_cast<std::uint64_t>(o.repeat);
    Progress progress(!o.quiet && !o.no_progress, runs_per_input * o.inputs.size());
    std::uint64_t passes_done = 0, events_done = 0;
    const PassDone done = [&](std::uint64_t events) {
        ++passes_done;
        events_done += events;
        progress.update(passes_done, events_done);
    };
    std::vector<Row> rows;
    Latency clock;
    for (const std::string& input : o.inputs) {
        SensorSize sensor;
        std::vector<Event> stream, file_stream;
        std::uint64_t file_events = 0;
        {
            LoadedEvents file = load_events(input, o.in, !o.quiet && !o.no_progress);  // its own bar while reading
            sensor = file.size;
            file_events = file.events.size();
            stream = replay(file.events, o.min_events, o.replay_gap_us);
            file_stream = std::move(file.events);
        }
        if (stream.empty()) {
            progress.finish();
            fmt::print(stderr, "evcorner bench: {}: no events, skipped\n", input);
            passes_done += runs_per_input;
            continue;
        }
        const ColdRuns cold = cold_runs(file_stream, sensor, detectors, o, done);
        progress.finish();
        if (o.yardstick && !o.quiet)
            fmt::print(stderr, "  {} yardstick: {:.1f} ns/event\n", short_name(input), median_of(cold.yardstick_ns));
        for (std::size_t di = 0; di < detectors.size(); ++di)
            for (const int thr : thread_counts) {
                const std::string& d = detectors[di];
                if (thr > 1 && !detector_info(d).local()) continue;  // not local: one thread only
                rows.push_back(thr == 1 ? bench_one(input, d, sensor, stream, file_events, o, clock, done)
                                        : bench_parallel(input, d, thr, sensor, stream, file_events, o, done));
                if (thr == 1) {
                    Row& row = rows.back();
                    row.cold_ns_per_event = cold.ns[di];
                    row.cold_median = median_of(cold.ns[di]);
                    row.cold_corners = cold.corners[di];
                    row.yardstick_median = o.yardstick ? median_of(cold.yardstick_ns) : 0.0;
                    row.yardstick_corners = cold.yardstick_corners;
                }
                progress.finish();
                flush_checked(out);
                if (!o.quiet)
                    fmt::print(stderr, "  {} {} x{}: {:.1f} ns/event\n", short_name(input), d, thr, rows.back().median);
            }
    }
    progress.finish();
    if (!o.quiet) fmt::print(stderr, "\n");
    print_table(out, rows, detectors, thread_counts, !o.no_latency, o.yardstick);
    if (!o.no_latency)
        fmt::print(out, "\nlatency clock: overhead {:.1f} ns (subtracted), resolution {:.1f} ns\n", clock.overhead_ns,
                   clock.resolution_ns);
    flush_checked(out);
    if (!o.json.empty()) write_json(o.json, rows, cpu, clock, o);
}

}  // namespace

void add_bench_command(CLI::App& app) {
    auto o = std::make_shared<BenchOptions>();
    CLI::App* cmd = app.add_subcommand(
        "bench",
        "Benchmark the detectors on event files: the paper's Table 2 for this machine.\n"
        "Cold: each detector runs --repeat times over each input as it is (one pass per\n"
        "file, fresh detector). Replayed: each input is replayed (each copy shifted in time\n"
        "to start --replay-gap after the previous one ends) to at least --min-events\n"
        "events; each detector runs --repeat times\n"
        "over it, one thread. Prints ns/event (replayed median, min, max; cold median and\n"
        "cold/replayed), the maximum sustainable event rate, per-event latency percentiles\n"
        "(p50, p99, p99.9), detector memory, the CPU model and build flags; with\n"
        "--yardstick also the cold speed as a multiple of a plain eFAST timed in the same run.\n"
        "Note: a short file replayed as identical copies is partly learned by the CPU's branch\n"
        "predictors, so its replayed figure is faster than a continuous stream of the same kind\n"
        "(docs/performance.md, \"What a replay measures\"; bench/bench_warmup.cpp measures the\n"
        "cold start on a continuous recording instead).\n"
        "With --tracker NAME the trackers are timed instead (seeded by --seeds FILE or -d DETECTOR):\n"
        "ns per event, ns per in-range (event, track) update, live tracks, and the ratio to eFAST\n"
        "detect's ns per event timed in the same rounds (docs/tracking.md, \"Speed\").");
    cmd->add_option("FILE", o->inputs, "Event files (any format evcorner reads)")->required();
    CLI::Option* detectors_opt =
        cmd->add_option("-d,--detectors", o->detectors,
                        "Comma-separated detectors to run, or all [default: all registered, each with its defaults "
                        "unless the parameter options below are given]; with --tracker, the one detector whose "
                        "corners seed the tracks (as evcorner track -d):" +
                            detectors_help());
    std::string trackers;
    for (const TrackerEntry& t : tracker_registry()) trackers += fmt::format("\n  {:<24}{}", t.name, t.summary);
    cmd->add_option("--tracker", o->trackers,
                    "Time this tracker instead of the detectors (repeatable or comma-separated; all = every "
                    "registered tracker), seeded by --seeds FILE or -d DETECTOR; each round runs eFAST detect and "
                    "then every tracker once over each input as it is (no replay) through the tracking pipeline, "
                    "and the report gives per tracker ns per event, ns per in-range (event, track) update and the "
                    "ratio to eFAST's ns per event in the same round, medians over --repeat rounds. Not with "
                    "--threads, --yardstick or --cpu-time; --min-events, --replay-gap and --no-latency do not "
                    "apply:" +
                        trackers)
        ->delimiter(',')
        ->allow_extra_args(false);
    cmd->add_option("--seeds", o->seeds,
                    "With --tracker: the seeds file, as evcorner track --seeds takes it (HASTE's 't,x,y,theta[,id]' "
                    "tokens, or a track file's 'id t x y' rows: each id's first row seeds it)");
    cmd->add_option("--init", o->init,
                    "With --tracker: how a HASTE track's first window is filled, centered or uncentered (as "
                    "evcorner track --init)")
        ->capture_default_str()
        ->check(CLI::IsMember({"centered", "uncentered"}));
    add_param_options(*cmd, o->detector_params);
    cmd->add_option("--repeat", o->repeat, "Timed passes per detector and input")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000));
    cmd->add_option("--min-events", o->min_events, "Replay each input until it holds at least this many events")
        ->capture_default_str()
        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 40));
    cmd->add_option("--replay-gap", o->replay_gap_us,
                    "Microseconds between the end of one replayed copy and the start of the next. The default, "
                    "longer than any detector's time window (Arc*'s and FA-Harris's 50 ms filter), makes every "
                    "copy meet the detectors as the file's own start does, so that cold and replayed passes do "
                    "the same work per event; 0 replays back to back, where a short file's copies follow each "
                    "other within the filter window and the filter rejects more events")
        ->capture_default_str()
        ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40));
    cmd->add_option("--json", o->json,
                    "Also write every figure as JSON to this file (- = standard output; the report then goes "
                    "to standard error)");
    add_load_options(*cmd, o->in);
    std::string local;
    for (const DetectorInfo& d : detector_infos())
        if (d.local()) local += (local.empty() ? "" : ", ") + std::string(d.name);
    cmd->add_option("--threads", o->threads,
                    "Comma-separated thread counts, e.g. 1,2: the local detectors (" + local +
                        ") also run split over that many threads (parallel_detect.hpp; no latency pass); others "
                        "run on one")
        ->capture_default_str();
    cmd->add_flag("--no-latency", o->no_latency, "Skip the per-event latency pass");
    cmd->add_flag("--yardstick", o->yardstick,
                  "Also time the yardstick, a plain exhaustive eFAST built into the tool (same compiler and "
                  "flags; the computation of ../shared/tools/plain-efast.cpp), cold on each input in the same "
                  "rounds, and report each detector's cold speed as a multiple of it (x yard)");
    cmd->add_flag("--cpu-time", o->cpu_time,
                  "Time the throughput and cold passes (and the yardstick) by the thread's CPU time instead of "
                  "the wall clock: on a shared machine it leaves out the time other processes hold the core "
                  "(not what they do to the caches)");
    cmd->add_flag("-q,--quiet", o->quiet, "No per-run progress lines and no progress bar on standard error");
    cmd->add_flag("--no-progress", o->no_progress, "No progress bar (it shows only on a terminal)");
    cmd->footer(
        "Examples:\n"
        "  evcorner bench ../shared/data/real/ecd-stppp/*/events.txt\n"
        "  evcorner bench ../shared/data/real/ecd-stppp/*/events.txt --min-events 1 --no-latency   # cold only (no replay)\n"
        "  evcorner bench ../shared/data/real/ecd-stppp/*/events.txt -d efast --yardstick --no-latency\n"
        "  evcorner bench recording.raw -d efast --repeat 9 --min-events 20000000 --json bench.json\n"
        "  evcorner bench hd.raw -d efast --threads 1,2          # multi-core speed-up\n"
        "  evcorner bench ev.npy --size 640x480 --tracker all --seeds gt.txt --init uncentered   # trackers\n"
        "  evcorner bench events.txt --tracker haste-correlation-star -d arcstar --repeat 9");
    cmd->callback([o, detectors_opt] {
        o->detectors_given = detectors_opt->count() > 0;
        run_bench(*o);
    });
}

}  // namespace evcorner::cli
