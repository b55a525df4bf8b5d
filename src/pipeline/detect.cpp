#include "evcorner/pipeline/detect.hpp"

#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "evcorner/detector.hpp"
#include "evcorner/error.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/parallel_detect.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/scored_detector.hpp"

namespace evcorner::pipeline {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

// ------------------------------------------------------------------ sinks

CornerEventSink::CornerEventSink(std::unique_ptr<io::EventWriter> out, bool with_score)
    : out_(std::move(out)), with_score_(with_score) {
    if (!out_) throw std::invalid_argument("CornerEventSink: no writer");
}

void CornerEventSink::write(const DetectedBatch& b) {
    const std::size_t n = b.events.size();
    if (corners_.size() < n) corners_.resize(n);
    if (with_score_) {
        if (b.scores.size() < n) throw std::logic_error("CornerEventSink: the run has no scores (with_score)");
        if (scores_.size() < n) scores_.resize(n);
    }
    // Branch-free: corners are a few percent of the events, at data-dependent places.
    std::size_t k = 0;
    if (with_score_) {
        for (std::size_t i = 0; i < n; ++i) {
            corners_[k] = b.events[i];
            scores_[k] = b.scores[i];
            k += b.is_corner[i] != 0;
        }
        out_->write(std::span<const Event>(corners_.data(), k), std::span<const double>(scores_.data(), k));
        return;
    }
    for (std::size_t i = 0; i < n; ++i) {
        corners_[k] = b.events[i];
        k += b.is_corner[i] != 0;
    }
    out_->write(std::span<const Event>(corners_.data(), k));
}

void MaskSink::write(const DetectedBatch& b) {
    static constexpr char kLine[2][2] = {{'0', '\n'}, {'1', '\n'}};
    auto put_zeros = [&](std::uint64_t count) {
        for (std::uint64_t k = 0; k < count; ++k) out_.write({kLine[0], 2});
    };
    std::size_t next_skip = 0;
    for (std::size_t i = 0; i < b.events.size(); ++i) {
        while (next_skip < b.skips.size() && b.skips[next_skip].before == i) put_zeros(b.skips[next_skip++].count);
        out_.write({kLine[b.is_corner[i] != 0], 2});
    }
    while (next_skip < b.skips.size()) put_zeros(b.skips[next_skip++].count);
}

void CollectSink::write(const DetectedBatch& b) {
    for (std::size_t i = 0; i < b.events.size(); ++i)
        if (b.is_corner[i]) {
            corners.push_back(b.events[i]);
            if (!b.scores.empty()) scores.push_back(b.scores[i]);
        }
}

// ------------------------------------------------------------------ summary

double DetectSummary::reduction_percent() const noexcept {
    if (events == 0) return std::numeric_limits<double>::quiet_NaN();
    return 100.0 * (1.0 - static_cast<double>(corners) / static_cast<double>(events));
}

double DetectSummary::ns_per_event() const noexcept {
    if (events == 0) return std::numeric_limits<double>::quiet_NaN();
    return detect_s * 1e9 / static_cast<double>(events);
}

// ------------------------------------------------------------------ checks

void check_detect_options(const DetectOptions& o) {
    const DetectorInfo& info = detector_info(o.detector.name);  // unknown names throw
    check_detector_config(o.detector, o.param_prefix);
    if (o.batch < 1 || o.batch > ParallelDetector<EFast>::kMaxBatch)
        throw std::invalid_argument("batch must be within 1..65536 (got " + std::to_string(o.batch) + ")");
    if (o.threads < 1 || o.threads > 256)
        throw std::invalid_argument("threads must be within 1..256 (got " + std::to_string(o.threads) + ")");
    if (o.with_score && !info.has_score) {
        std::string scored;
        for (const DetectorInfo& d : detector_infos())
            if (d.has_score) scored += (scored.empty() ? "" : ", ") + std::string(d.name);
        throw std::invalid_argument(o.param_prefix("with-score") + ": detector '" + o.detector.name + "' has no score (" +
                                    (scored.empty() ? "none has" : scored + " have one") + ")");
    }
    if (o.threads > 1 && !info.local()) {
        std::string local;
        for (const DetectorInfo& d : detector_infos())
            if (d.local()) local += (local.empty() ? "" : ", ") + std::string(d.name);
        throw std::invalid_argument(o.param_prefix("threads") + ": detector '" + o.detector.name + "' is not local (" +
                                    std::string(info.not_local) + "); " + local + " split the sensor");
    }
    if (o.threads > 1 && o.with_score)
        throw std::invalid_argument(o.param_prefix("threads") + ": " + o.param_prefix("with-score") + " needs one thread");
    if (o.nms) {
        if (!info.has_score)
            throw std::invalid_argument(o.param_prefix("nms") + ": detector '" + o.detector.name +
                                        "' has no score to suppress by");
        check_nms_params(*o.nms);
    }
}

// ------------------------------------------------------------------ the run

namespace {

class Run {
public:
    Run(io::EventReader& reader, const DetectOptions& o, std::span<DetectSink* const> sinks, const ProgressFn& progress,
        DetectSummary& s)
        : reader_(reader), o_(o), sinks_(sinks), progress_(progress), s_(s) {}

    // One thread: read, detect (timed), write, batch after batch.
    template <class D>
    void single(D& det) {
        std::vector<Event> events(o_.batch);
        std::vector<std::uint8_t> flags(o_.batch);
        std::vector<double> scores(o_.with_score ? o_.batch : 0);
        for (;;) {
            const std::size_t n = reader_.read(events);
            const auto skips = reader_.skipped_in_batch();
            if (n == 0 && skips.empty()) return;
            const std::span<const Event> batch(events.data(), n);
            const auto t0 = Clock::now();
            std::size_t c = 0;
            if constexpr (ScoredDetector<D>) {
                if (o_.with_score)
                    c = detect(det, batch, flags, scores);
                else
                    c = detect(det, batch, flags);
            } else {
                c = detect(det, batch, flags);
            }
            s_.detect_s += since(t0);
            s_.events += n;
            s_.corners += c;
            write({batch, std::span<const std::uint8_t>(flags.data(), n),
                   std::span<const double>(scores.data(), o_.with_score ? n : 0), skips},
                  reader_.bytes_consumed(), s_.events, s_.corners);
        }
    }

    // Several threads: three batches in flight. While the threads detect batch k, the
    // calling thread first writes batch k - 1, then reads batch k + 1 and sorts it out to
    // the parts (ParallelDetector::prepare), then helps detect. A read error is raised
    // once every batch before it is written.
    template <class Par>
    void parallel(Par& par) {
        struct Batch {
            std::vector<Event> events;
            std::vector<std::uint8_t> flags;
            std::size_t n = 0;
            std::vector<io::SkipRun> skips;
            std::uint64_t bytes = 0;
            std::uint64_t events_so_far = 0, corners_so_far = 0;
            bool end = false;
            std::exception_ptr error;
        };
        Batch batches[3];
        for (Batch& b : batches) {
            b.events.resize(o_.batch);
            b.flags.resize(o_.batch);
        }
        auto fetch = [&](Batch& b) {
            try {
                b.n = reader_.read(b.events);
                const auto skips = reader_.skipped_in_batch();
                b.skips.assign(skips.begin(), skips.end());
                b.bytes = reader_.bytes_consumed();
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
            write({std::span<const Event>(w.events.data(), w.n), std::span<const std::uint8_t>(w.flags.data(), w.n), {},
                   w.skips},
                  w.bytes, w.events_so_far, w.corners_so_far);
        };
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
            s_.detect_s += since(t0);
            s_.events += b.n;
            s_.corners += c;
            b.events_so_far = s_.events;
            b.corners_so_far = s_.corners;
            unwritten = &b;
        }
    }

private:
    void write(const DetectedBatch& b, std::uint64_t bytes, std::uint64_t events, std::uint64_t corners) {
        for (DetectSink* sink : sinks_) sink->write(b);
        if (progress_) progress_({bytes, reader_.bytes_total(), events, corners});
    }

    io::EventReader& reader_;
    const DetectOptions& o_;
    std::span<DetectSink* const> sinks_;
    const ProgressFn& progress_;
    DetectSummary& s_;
};

}  // namespace

DetectSummary run_detect(io::EventReader& reader, const DetectOptions& o, std::span<DetectSink* const> sinks,
                         const ProgressFn& progress, SensorSize fallback) {
    const auto wall_start = Clock::now();
    check_detect_options(o);
    DetectSummary s;
    s.detector = o.detector.name;
    s.sensor = reader.sensor().value_or(fallback);
    s.threads = o.threads;
    Run run(reader, o, sinks, progress, s);
    auto close_sinks = [&] {
        for (DetectSink* sink : sinks) sink->close();
    };
    with_detector_entry(o.detector.name, [&](const auto& entry) {
        using D = typename std::remove_cvref_t<decltype(entry)>::Detector;
        const auto params = entry.params_of(o.detector.params, o.param_prefix);
        // The detector is built (and its errors raised) before anything is read. With NMS,
        // the detector is Suppressed<D> (nms.hpp), local with the radius grown by NMS's.
        auto go = [&](auto tag, int radius, auto make) {
            using R = typename decltype(tag)::type;
            std::unique_ptr<R> single;
            std::unique_ptr<ParallelDetector<R>> par;
            if (o.threads > 1)
                par = std::make_unique<ParallelDetector<R>>(
                    s.sensor, o.threads, Locality(radius, entry.split == Split::by_polarity), make);
            else
                single = std::make_unique<R>(make(s.sensor, 2));
            try {
                if (par)
                    run.parallel(*par);
                else
                    run.single(*single);
            } catch (const InputError& e) {
                // Without allow_damaged the sinks stay unclosed: a file output is then left
                // absent (writers remove an unfinished file), never a partial result under its name.
                if (!o.allow_damaged) throw;
                close_sinks();  // the outputs of the events before the damage are the result
                s.damaged = e.what();
            }
        };
        const int radius = o.threads > 1 ? entry.radius(params) : 0;
        if constexpr (ScoredDetector<D>) {
            if (o.nms) {
                const NmsParams nms = *o.nms;
                go(std::type_identity<Suppressed<D>>{}, radius + nms.radius,
                   [&entry, params, nms](SensorSize z, int planes) {
                       return Suppressed<D>(entry.make(z, params, planes), nms, planes);
                   });
                return;
            }
        }
        go(std::type_identity<D>{}, radius,
           [&entry, params](SensorSize z, int planes) { return entry.make(z, params, planes); });
    });
    if (s.damaged.empty()) close_sinks();
    s.skipped = reader.skipped();
    s.wall_s = since(wall_start);
    return s;
}

DetectSummary detect_file(const DetectFiles& f, const DetectOptions& o, const ProgressFn& progress) {
    const auto wall_start = Clock::now();
    // Before anything is opened: outputs onto the input or onto each other, the options.
    io::check_output_paths({{"input", f.input}}, {{"output", f.output}, {"mask", f.mask}});
    io::check_outputs_creatable({{"output", f.output}, {"mask", f.mask}});
    check_detect_options(o);
    const std::string to = f.output.empty() ? std::string() : io::resolve_output_format(f.output, f.to);
    if (o.with_score && to == "aedat4")
        throw std::invalid_argument(o.param_prefix("with-score") +
                                    ": AEDAT 4.0 event packets have no field for a score (formats that carry "
                                    "scores: " + std::string(io::kScoredOutputFormats) + ")");
    const std::unique_ptr<io::EventReader> reader = io::open_event_reader(f.input, f.reader, f.format);
    const SensorSize size = reader->sensor().value_or(kDavis240);
    // The output records the sensor size the detector ran on where it has a field for it.
    std::vector<std::unique_ptr<DetectSink>> owned;
    if (!f.output.empty())
        owned.push_back(
            std::make_unique<CornerEventSink>(io::open_event_writer(f.output, to, size, o.with_score), o.with_score));
    if (!f.mask.empty()) owned.push_back(std::make_unique<MaskSink>(f.mask));
    std::vector<DetectSink*> sinks;
    for (const auto& p : owned) sinks.push_back(p.get());
    DetectSummary s = run_detect(*reader, o, sinks, progress, size);
    s.wall_s = since(wall_start);
    return s;
}

}  // namespace evcorner::pipeline
