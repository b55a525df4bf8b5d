// eFAST, Arc* and FA-Harris ns/event on the 8 real Event-Camera-Dataset cuts, in the same
// run, two ways:
// - cold: every pass runs one file once with a fresh detector, passes rotate over the
//   files and the detectors (so no file's data or branch history is warm from its own
//   previous pass), as users run a file;
// - replayed: the same file run `replays` times back to back, each with a fresh
//   detector, and only the last runs timed (warm caches and branch history).
// Every eFAST and Arc* pass is checked against the golden index files. Prints per file
// the median over the passes and the ratio Arc*/eFAST and FA-Harris/Arc*, and the medians
// over the files. Times are the thread's CPU time (CLOCK_THREAD_CPUTIME_ID), so that on a
// shared machine a run that is preempted is not charged for the other processes' turns;
// EVCORNER_BENCH_WALL=1 times wall-clock (steady_clock) instead.
// Usage: bench_arcstar_files [PASSES=21] [REPLAYS=10]
// (EVCORNER_EFAST_PATH / EVCORNER_ARCSTAR_PATH=portable|avx2|avx512 choose the code paths;
// FA-Harris follows EVCORNER_ARCSTAR_PATH).

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evcorner/arcstar.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/fa_harris.hpp"
#include "real_files.hpp"
#include "timing.hpp"

namespace fs = std::filesystem;
using namespace evcorner;

namespace {

constexpr int kDetectors = 3;
const char* const kNames[kDetectors] = {"eFAST", "Arc*", "FA-Harris"};

struct File {
    std::string name;
    std::vector<Event> events;
    std::vector<std::size_t> golden[2];  // eFAST, Arc*
    std::vector<double> cold[kDetectors], warm[kDetectors];
};

std::vector<std::size_t> read_index(const fs::path& p) {
    std::vector<std::size_t> v;
    std::ifstream in(p);
    for (std::size_t i; in >> i;) v.push_back(i);
    return v;
}

double now_ns() {
    static const bool wall = std::getenv("EVCORNER_BENCH_WALL") != nullptr;
    if (wall)
        return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now().time_since_epoch()).count();
    return bench::thread_cpu_ns();
}

using bench::median;

// One timed run of detector d over f with a fresh detector; ns/event. Checks the goldens.
double run(int d, File& f, std::vector<std::uint8_t>& flags, bool& golden_ok) {
    const std::span<const Event> ev(f.events);
    double ns = 0;
    auto timed = [&](auto& det) {
        const double t0 = now_ns();
        detect(det, ev, flags);
        const double t1 = now_ns();
        ns = (t1 - t0) / static_cast<double>(ev.size());
    };
    if (d == 0) {
        EFast det(kDavis240);
        timed(det);
    } else if (d == 1) {
        ArcStar det(kDavis240);
        timed(det);
    } else {
        FaHarris det(kDavis240);
        timed(det);
    }
    if (d < 2) {
        std::vector<std::size_t> pos;
        for (std::size_t i = 0; i < flags.size(); ++i)
            if (flags[i]) pos.push_back(i);
        if (pos != f.golden[d]) {
            golden_ok = false;
            std::printf("GOLDEN MISMATCH: %s on %s\n", kNames[d], f.name.c_str());
        }
    }
    return ns;
}

}  // namespace

int main(int argc, char** argv) {
    const int passes = argc > 1 ? std::max(1, std::atoi(argv[1])) : 21;
    const int replays = argc > 2 ? std::max(2, std::atoi(argv[2])) : 10;
    const fs::path data = fs::path(EVCORNER_SHARED_DIR) / "data";
    std::vector<File> files;
    for (const auto& r : bench::real_240x180_files(data)) {
        if (!r.ecd || r.name == "slider_depth") continue;  // the 8 cuts with Arc* goldens
        File f{r.name, bench::load_events(r.events), {}, {}, {}};
        f.golden[0] = read_index(r.golden);
        f.golden[1] = read_index(data / "golden" / ("ecd-stppp." + r.name + ".arcstar.idx"));
        files.push_back(std::move(f));
    }
    if (files.empty()) {
        std::fprintf(stderr, "bench_arcstar_files: %s not found\n", data.string().c_str());
        return 1;
    }
    bool golden_ok = true;
    std::vector<std::uint8_t> flags;
    for (int pass = 0; pass < passes; ++pass)
        for (int d = 0; d < kDetectors; ++d)
            for (File& f : files) {
                flags.assign(f.events.size(), 0);
                f.cold[(d + pass) % kDetectors].push_back(run((d + pass) % kDetectors, f, flags, golden_ok));
            }
    for (int pass = 0; pass < passes; ++pass)
        for (File& f : files)
            for (int d = 0; d < kDetectors; ++d) {
                flags.assign(f.events.size(), 0);
                for (int r = 0; r + 1 < replays; ++r) run(d, f, flags, golden_ok);  // warm up
                f.warm[d].push_back(run(d, f, flags, golden_ok));
            }

    std::printf("%s time; code paths: eFAST %s, Arc* %s; %d passes, %d replays\n",
                std::getenv("EVCORNER_BENCH_WALL") ? "wall-clock" : "thread CPU", efast_code_path(),
                arcstar_code_path(), passes, replays);
    std::printf("%-20s | %8s %8s %9s %6s %6s | %8s %8s %9s %6s %6s\n", "ns/event (median)", "eFAST", "Arc*", "FA-Harris",
                "A/eF", "FA/A", "eFAST", "Arc*", "FA-Harris", "A/eF", "FA/A");
    std::printf("%-20s | %42s | %42s\n", "", "cold (one pass per file)", "replayed");
    std::vector<double> med[2][kDetectors];
    for (const File& f : files) {
        double c[kDetectors], w[kDetectors];
        for (int d = 0; d < kDetectors; ++d) {
            c[d] = median(f.cold[d]);
            w[d] = median(f.warm[d]);
            med[0][d].push_back(c[d]);
            med[1][d].push_back(w[d]);
        }
        std::printf("%-20s | %8.2f %8.2f %9.2f %6.2f %6.2f | %8.2f %8.2f %9.2f %6.2f %6.2f\n", f.name.c_str(), c[0], c[1],
                    c[2], c[1] / c[0], c[2] / c[1], w[0], w[1], w[2], w[1] / w[0], w[2] / w[1]);
    }
    double m[2][kDetectors];
    for (int k = 0; k < 2; ++k)
        for (int d = 0; d < kDetectors; ++d) m[k][d] = median(med[k][d]);
    std::printf("%-20s | %8.2f %8.2f %9.2f %6.2f %6.2f | %8.2f %8.2f %9.2f %6.2f %6.2f\n", "median of files", m[0][0],
                m[0][1], m[0][2], m[0][1] / m[0][0], m[0][2] / m[0][1], m[1][0], m[1][1], m[1][2], m[1][1] / m[1][0],
                m[1][2] / m[1][1]);
    std::printf("goldens (eFAST, Arc*) %s\n", golden_ok ? "identical" : "DIFFER");
    return golden_ok ? 0 : 1;
}
