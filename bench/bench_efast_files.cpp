// eFAST ns/event on each real 240x180 recording, the way a stream meets the detector:
// every pass runs one file once with a fresh detector, passes rotate over the files (so
// no file's data or branch history is warm from its own previous pass), and every
// pass's corners are checked against the golden index files. Prints per-file median
// and minimum and the median over the files. Usage: bench_efast_files [PASSES=41]
// (environment EVCORNER_EFAST_PATH=portable, avx2 or avx512 times that loop).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "real_files.hpp"
#include "timing.hpp"

namespace fs = std::filesystem;
using namespace evcorner;

namespace {

struct File {
    std::string name;
    std::vector<Event> events;
    std::vector<std::size_t> golden;
    std::vector<double> ns;
};

File load(const bench::RealFile& r) {
    File f{r.name, bench::load_events(r.events), {}, {}};
    std::ifstream in(r.golden);
    for (std::size_t i; in >> i;) f.golden.push_back(i);
    return f;
}

using bench::median;

}  // namespace

int main(int argc, char** argv) {
    const int passes = argc > 1 ? std::max(1, std::atoi(argv[1])) : 41;
    const fs::path data = fs::path(EVCORNER_SHARED_DIR) / "data";
    const auto real = bench::real_240x180_files(data);
    if (real.empty() || !fs::is_directory(data / "golden")) {
        std::fprintf(stderr, "bench_efast_files: %s not found\n", data.string().c_str());
        return 1;
    }
    std::vector<File> files;
    for (const auto& r : real) files.push_back(load(r));

    bool golden_ok = true;
    for (int pass = 0; pass < passes; ++pass) {
        for (File& f : files) {
            std::vector<std::uint8_t> flags(f.events.size());
            EFast det(kDavis240);
            const auto t0 = std::chrono::steady_clock::now();
            detect(det, std::span<const Event>(f.events), flags);
            const auto t1 = std::chrono::steady_clock::now();
            f.ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(f.events.size()));
            std::vector<std::size_t> pos;
            for (std::size_t i = 0; i < flags.size(); ++i)
                if (flags[i]) pos.push_back(i);
            if (pos != f.golden) {
                golden_ok = false;
                std::printf("GOLDEN MISMATCH on %s: %zu corners, golden %zu\n", f.name.c_str(), pos.size(), f.golden.size());
            }
        }
    }
    std::printf("eFAST code path: %s; %d passes per file, rotating over the files\n", efast_code_path(), passes);
    std::printf("%-22s %8s %10s %8s\n", "file", "events", "median", "min");
    std::vector<double> medians;
    for (const File& f : files) {
        medians.push_back(median(f.ns));
        std::printf("%-22s %8zu %10.2f %8.2f\n", f.name.c_str(), f.events.size(), medians.back(),
                    *std::min_element(f.ns.begin(), f.ns.end()));
    }
    std::printf("median over the %zu files: %.2f ns/event; goldens %s\n", files.size(), median(medians),
                golden_ok ? "identical" : "DIFFER");
    return golden_ok ? 0 : 1;
}
