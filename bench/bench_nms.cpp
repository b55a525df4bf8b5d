// The cost of eFAST's score and of asynchronous NMS (docs/nms.md) on the real 240x180
// recordings: per pass and file, four loops with fresh state, in rotating order
// (interleaved, so that load changes hit all alike):
//   binary  detect(EFast&, events, flags)                 the published detector
//   scored  detect(EFast&, events, flags, scores)         the score for each corner
//   nms-w   detect(Suppressed<EFast>&, ...)  rule window  scored + NMS (defaults)
//   nms-d   detect(Suppressed<EFast>&, ...)  rule decay
// Checks that the scored flags equal the binary ones on every pass. Prints per file the
// median ns/event of each, the ratios scored/binary, nms-w/binary and nms-w/scored and,
// over the files, the median of the per-file ratios.
// Usage: bench_nms [PASSES=15] [--cpu-time] (--cpu-time: the thread's CPU time instead of
// the wall clock); bench_nms once MODE FILE runs one loop once, for callgrind (modes: load
// binary scored nms-w nms-d arc-binary arc-scored; see once()); bench_nms fingerprint MODE
// FILE the same, printing a hash of the flags and of the scores' bits (old and new code
// must agree).

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <time.h>

#include "evcorner/arcstar.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/nms.hpp"
#include "real_files.hpp"
#include "timing.hpp"

namespace fs = std::filesystem;
using namespace evcorner;

namespace {
using bench::median;
using Clock = std::chrono::steady_clock;
}  // namespace

// One loop once over one file, for callgrind: bench_nms once load|binary|scored|nms-w|nms-d FILE
// (instructions per event = (I(mode) - I(load)) / events); arc-binary|arc-scored: the same
// for Arc* (default parameters, detect(ArcStar&, ...) without and with scores).
int once(const std::string& mode, const std::string& file, bool fingerprint) {
    const std::vector<Event> ev = bench::load_events(file);
    std::vector<std::uint8_t> f(ev.size());
    std::vector<double> sc(ev.size());
    std::size_t c = 0;
    NmsParams d;
    d.rule = NmsRule::decay;
    if (mode == "load") {  // the baseline: loading alone
    } else if (mode == "binary") {
        EFast det(kDavis240);
        c = detect(det, ev, f);
    } else if (mode == "scored") {
        EFast det(kDavis240);
        c = detect(det, ev, f, sc);
    } else if (mode == "arc-binary") {
        ArcStar det(kDavis240);
        c = detect(det, ev, f);
    } else if (mode == "arc-scored") {
        ArcStar det(kDavis240);
        c = detect(det, ev, f, sc);
    } else if (mode == "nms-w" || mode == "nms-d") {
        Suppressed<EFast> det(EFast(kDavis240), mode == "nms-w" ? NmsParams{} : d);
        c = detect(det, ev, f, sc);
    } else {
        std::fprintf(stderr, "bench_nms once: unknown mode %s\n", mode.c_str());
        return 2;
    }
    std::printf("%s: %zu events, %zu corners", mode.c_str(), ev.size(), c);
    if (!fingerprint) {
        std::printf("\n");
        return 0;
    }
    // A fingerprint of the flags and of the scores' bits (FNV-1a): old and new code must
    // print the same one (scores bit-identical, docs/scores.md "Cost").
    std::uint64_t h = 1469598103934665603ull;
    const auto mix = [&h](std::uint64_t v) {
        for (int b = 0; b < 8; ++b) h = (h ^ ((v >> (8 * b)) & 0xff)) * 1099511628211ull;
    };
    for (std::size_t i = 0; i < ev.size(); ++i) {
        mix(f[i]);
        if (f[i] && mode != "binary" && mode != "arc-binary") mix(std::bit_cast<std::uint64_t>(sc[i]));
    }
    std::printf(", fingerprint %016llx (eFAST path %s, NMS path %s)\n", static_cast<unsigned long long>(h),
                efast_code_path(), AsyncNms(kDavis240, NmsParams{}).code_path());
    return 0;
}

int main(int argc, char** argv) {
    if (argc == 4 && std::string(argv[1]) == "once") return once(argv[2], argv[3], false);
    if (argc == 4 && std::string(argv[1]) == "fingerprint") return once(argv[2], argv[3], true);
    int passes = 15;
    bool cpu_time = false;
    for (int a = 1; a < argc; ++a) {
        if (std::string(argv[a]) == "--cpu-time") cpu_time = true;
        else passes = std::max(1, std::atoi(argv[a]));
    }
    // The thread's CPU time rather than the wall clock: time spent waiting for a core on
    // a shared machine does not count (page faults and other system time do).
    const auto now = [cpu_time] {
        if (!cpu_time) return std::chrono::duration<double, std::nano>(Clock::now().time_since_epoch()).count();
        return bench::thread_cpu_ns();
    };
    const auto real = bench::real_240x180_files(fs::path(EVCORNER_SHARED_DIR) / "data");
    if (real.empty()) {
        std::fprintf(stderr, "bench_nms: ../shared/data not found\n");
        return 1;
    }
    constexpr int kLoops = 4;
    const char* names[kLoops] = {"binary", "scored", "nms-w", "nms-d"};
    std::vector<double> ratio_scored, ratio_nms_w, ratio_nms_d, ratio_nms_w_scored;
    std::printf("%-20s %9s %9s %9s %9s %8s %8s %8s %6s %6s %6s\n", "file", "binary", "scored", "nms-w", "nms-d",
                "corners", "kept-w", "kept-d", "s/b", "w/b", "w/s");
    bool same = true;
    for (const auto& r : real) {
        const std::vector<Event> ev = bench::load_events(r.events);
        const SensorSize size = kDavis240;
        std::vector<std::uint8_t> f0(ev.size()), f1(ev.size());
        std::vector<double> sc(ev.size());
        std::vector<double> ns[kLoops];
        std::size_t counts[kLoops] = {};
        NmsParams w, d;
        d.rule = NmsRule::decay;
        for (int pass = 0; pass < passes; ++pass) {
            for (int j = 0; j < kLoops; ++j) {
                const int loop = (j + pass) % kLoops;
                const double t0 = now();
                std::size_t c = 0;
                if (loop == 0) {
                    EFast det(size);
                    c = detect(det, ev, f0);
                } else if (loop == 1) {
                    EFast det(size);
                    c = detect(det, ev, f1, sc);
                } else {
                    Suppressed<EFast> det(EFast(size), loop == 2 ? w : d);
                    c = detect(det, ev, f1, sc);
                }
                ns[loop].push_back((now() - t0) / static_cast<double>(ev.size()));
                counts[loop] = c;
                if (loop == 1 && f1 != f0 && pass > 0) same = false;
            }
        }
        {  // the decisions once more, side by side
            EFast a(size), b(size);
            detect(a, ev, f0);
            detect(b, ev, f1, sc);
            same = same && f0 == f1;
        }
        const double m[kLoops] = {median(ns[0]), median(ns[1]), median(ns[2]), median(ns[3])};
        std::printf("%-20s %9.2f %9.2f %9.2f %9.2f %8zu %8zu %8zu %6.3f %6.3f %6.3f\n", r.name.c_str(), m[0], m[1], m[2],
                    m[3], counts[0], counts[2], counts[3], m[1] / m[0], m[2] / m[0], m[2] / m[1]);
        ratio_scored.push_back(m[1] / m[0]);
        ratio_nms_w.push_back(m[2] / m[0]);
        ratio_nms_d.push_back(m[3] / m[0]);
        ratio_nms_w_scored.push_back(m[2] / m[1]);
    }
    (void)names;
    std::printf("median over files: scored/binary %.3f, nms-window/binary %.3f, nms-decay/binary %.3f, "
                "nms-window/scored %.3f (ns/event medians of %d interleaved passes, %s; eFAST path %s, NMS path %s)\n",
                median(ratio_scored), median(ratio_nms_w), median(ratio_nms_d), median(ratio_nms_w_scored), passes,
                cpu_time ? "thread CPU time" : "wall clock", efast_code_path(),
                AsyncNms(kDavis240, NmsParams{}).code_path());
    std::printf("scored flags identical to binary on every file: %s\n", same ? "yes" : "NO");
    return same ? 0 : 1;
}
