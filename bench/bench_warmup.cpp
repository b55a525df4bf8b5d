// What a cold start costs, measured without replaying a file.
//
// `evcorner bench` compares a detector's cold pass over a file with the same file replayed
// to millions of events as identical copies. On a 30 000-event file that replay repeats one
// sequence of events every 30 000 events, and a CPU's branch predictors learn it: later
// copies run faster than any real stream of the same kind would (docs/performance.md, "What
// a replay measures"). This program measures the cold start on one continuous recording
// instead, and the learned replay beside it:
//
//   first   ns/event over the recording's first --chunk events, a fresh detector
//   rest    median ns/event of the following chunks of the same pass (same detector, the
//           stream continuing: no copy, no repetition)
//   first/rest  the cold-start factor of a continuous stream
//   learned ns/event over the first chunk run again as identical copies (shifted in time,
//           each with a fresh detector, so that no state is carried over; the median of
//           copies 11-20): the same events once the CPU has seen them ten times
//   first/learned  how much of a cold/replayed factor over a file of --chunk events comes
//           from the CPU learning the repeated events, not from the detector's state
//
// --images: instead, what the CPU learns. One detector runs over 40 copies of the first chunk
// (each shifted in time 100 ms past the previous one), the copies cycling through K of the
// sensor's mirror and polarity images (K = 1: identical copies; 2p: the file and its
// polarity-swapped image, which has the same branch outcomes in the other plane of memory;
// 2x: the file and its x-mirror; 4: the four mirrors; 8: the four mirrors, each also
// polarity-swapped); printed: the median ns/event of copies 9-40.
//
// Each figure is the median over --rounds rounds (each round: the detectors in turn, a fresh
// detector each). Thread CPU time; one thread. Files with fewer than 4 chunks are skipped.
//
// usage: bench_warmup [--chunk N] [--rounds K] [--images] [-d det1,det2,...] [FILE...]
//   default: every registered detector on the real recordings of ../shared/data that hold
//   at least 4 chunks (IMU_rotDisk, IMU_translBoxes of the DAVIS240C set).

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/registry.hpp"
#include "real_files.hpp"
#include "timing.hpp"

namespace {

using namespace evcorner;

using bench::median;

struct Figures {
    double first = 0, rest = 0, learned = 0;
};

/// One round for one detector: a continuous pass timed chunk by chunk, then the first chunk
/// replayed as 20 identical copies with a fresh detector each.
Figures round(const std::string& name, SensorSize sensor, std::span<const Event> events, std::size_t chunk) {
    Figures f;
    std::vector<std::uint8_t> flags(chunk);
    {
        AnyDetector any = make_detector(name, sensor);
        std::vector<double> rest;
        std::visit(
            [&](auto& det) {
                for (std::size_t i = 0; i + chunk <= events.size(); i += chunk) {
                    const double t0 = bench::thread_cpu_ns();
                    detect(det, events.subspan(i, chunk), flags);
                    const double ns = (bench::thread_cpu_ns() - t0) / static_cast<double>(chunk);
                    if (i == 0)
                        f.first = ns;
                    else
                        rest.push_back(ns);
                }
            },
            any);
        f.rest = median(rest);
    }
    const std::span<const Event> head = events.first(chunk);
    const std::int64_t shift = head.back().t - head.front().t + 1 + 100'000;
    std::vector<Event> copy(head.begin(), head.end());
    std::vector<double> learned;
    for (int r = 1; r <= 20; ++r) {
        for (std::size_t i = 0; i < chunk; ++i) copy[i].t = head[i].t + static_cast<std::int64_t>(r) * shift;
        AnyDetector any = make_detector(name, sensor);
        std::visit(
            [&](auto& det) {
                const double t0 = bench::thread_cpu_ns();
                detect(det, std::span<const Event>(copy), flags);
                if (r > 10) learned.push_back((bench::thread_cpu_ns() - t0) / static_cast<double>(chunk));
            },
            any);
    }
    f.learned = median(learned);
    return f;
}

/// The image of `e` under symmetry v: bit 0 mirrors x, bit 1 mirrors y, bit 2 swaps polarity.
Event image(Event e, unsigned v, SensorSize s) {
    if (v & 1u) e.x = static_cast<std::uint16_t>(s.width - 1 - e.x);
    if (v & 2u) e.y = static_cast<std::uint16_t>(s.height - 1 - e.y);
    if (v & 4u) e.p = static_cast<std::uint8_t>(e.p ? 0 : 1);
    return e;
}

/// One detector over 40 copies of `head` cycling through `cycle`'s images; the median
/// ns/event of copies 9-40.
double images_round(const std::string& name, SensorSize sensor, std::span<const Event> head,
                    const std::vector<unsigned>& cycle) {
    const std::int64_t shift = head.back().t - head.front().t + 1 + 100'000;
    std::vector<Event> copy(head.size());
    std::vector<std::uint8_t> flags(head.size());
    std::vector<double> ns;
    AnyDetector any = make_detector(name, sensor);
    std::visit(
        [&](auto& det) {
            for (int r = 0; r < 40; ++r) {
                const unsigned v = cycle[static_cast<std::size_t>(r) % cycle.size()];
                for (std::size_t i = 0; i < head.size(); ++i) {
                    copy[i] = image(head[i], v, sensor);
                    copy[i].t += static_cast<std::int64_t>(r) * shift;
                }
                const double t0 = bench::thread_cpu_ns();
                detect(det, std::span<const Event>(copy), flags);
                if (r >= 8) ns.push_back((bench::thread_cpu_ns() - t0) / static_cast<double>(head.size()));
            }
        },
        any);
    return median(ns);
}

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::size_t a = 0;
    while (a <= s.size()) {
        const std::size_t b = std::min(s.find(',', a), s.size());
        if (b > a) out.push_back(s.substr(a, b - a));
        a = b + 1;
    }
    return out;
}

int run(int argc, char** argv) {
    std::size_t chunk = 30000;
    int rounds = 5;
    bool images = false;
    std::vector<std::string> detectors, files;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if ((a == "--chunk" || a == "--rounds" || a == "-d") && i + 1 < argc) {
            const std::string v = argv[++i];
            if (a == "--chunk") chunk = std::stoul(v);
            if (a == "--rounds") rounds = std::stoi(v);
            if (a == "-d") detectors = split(v);
        } else if (a == "--images") {
            images = true;
        } else if (a == "-h" || a == "--help") {
            std::puts("usage: bench_warmup [--chunk N] [--rounds K] [--images] [-d det1,det2,...] [FILE...]");
            return 0;
        } else {
            files.push_back(a);
        }
    }
    if (chunk < 1000 || rounds < 1) throw std::invalid_argument("--chunk must be >= 1000 and --rounds >= 1");
    if (detectors.empty())
        for (const DetectorInfo& d : detector_infos()) detectors.emplace_back(d.name);
    if (files.empty())
        for (const auto& f : bench::real_240x180_files(std::filesystem::path(EVCORNER_SHARED_DIR) / "data"))
            if (images ? f.name == "shapes_rotation" : !f.ecd) files.push_back(f.events.string());
    if (files.empty()) {
        std::puts("bench_warmup: no files given and ../shared/data is absent: nothing to measure");
        return 0;
    }
    fmt::print("chunk {} events, {} rounds, thread CPU time; figures are medians over the rounds\n", chunk, rounds);
    if (images) {
        const std::vector<std::pair<const char*, std::vector<unsigned>>> cycles{
            {"1", {0}}, {"2p", {0, 4}}, {"2x", {0, 1}}, {"4", {0, 1, 2, 3}}, {"8", {0, 1, 2, 3, 4, 5, 6, 7}}};
        fmt::print("ns/event of copies 9-40, the copies cycling through K images of the first chunk\n");
        fmt::print("{:<24} {:<13}", "file", "detector");
        for (const auto& c : cycles) fmt::print(" {:>7}", std::string("K=") + c.first);
        fmt::print("\n");
        for (const std::string& file : files) {
            const auto reader = io::open_event_reader(file);
            const std::vector<Event> events = io::read_all_events(*reader);
            const SensorSize sensor = reader->sensor().value_or(kDavis240);
            const std::span<const Event> head = std::span<const Event>(events).first(std::min(chunk, events.size()));
            const std::string name = std::filesystem::path(file).parent_path().filename().string();
            for (const std::string& d : detectors) {
                fmt::print("{:<24} {:<13}", name, d);
                for (const auto& c : cycles) {
                    std::vector<double> v;
                    for (int r = 0; r < rounds; ++r) v.push_back(images_round(d, sensor, head, c.second));
                    fmt::print(" {:>7.1f}", median(v));
                }
                fmt::print("\n");
                std::fflush(stdout);
            }
        }
        return 0;
    }
    fmt::print("{:<20} {:<13} {:>6} {:>9} {:>9} {:>10} {:>9} {:>13}\n", "file", "detector", "chunks", "first ns",
               "rest ns", "first/rest", "learned", "first/learned");
    for (const std::string& file : files) {
        const auto reader = io::open_event_reader(file);
        const std::vector<Event> events = io::read_all_events(*reader);
        const SensorSize sensor = reader->sensor().value_or(kDavis240);
        const std::size_t chunks = events.size() / chunk;
        const std::string name = std::filesystem::path(file).filename().string();
        if (chunks < 4) {
            fmt::print("{:<20} skipped: {} events, fewer than 4 chunks\n", name, events.size());
            continue;
        }
        std::vector<std::vector<Figures>> per(detectors.size());
        for (int r = 0; r < rounds; ++r)
            for (std::size_t d = 0; d < detectors.size(); ++d)
                per[d].push_back(round(detectors[d], sensor, events, chunk));
        for (std::size_t d = 0; d < detectors.size(); ++d) {
            std::vector<double> first, rest, learned, fr, fl;
            for (const Figures& f : per[d]) {
                first.push_back(f.first);
                rest.push_back(f.rest);
                learned.push_back(f.learned);
                fr.push_back(f.first / f.rest);
                fl.push_back(f.first / f.learned);
            }
            fmt::print("{:<20} {:<13} {:>6} {:>9.1f} {:>9.1f} {:>10.2f} {:>9.1f} {:>13.2f}\n", name, detectors[d],
                       chunks, median(first), median(rest), median(fr), median(learned), median(fl));
        }
        std::fflush(stdout);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_warmup: %s\n", e.what());
        return 1;
    }
}
