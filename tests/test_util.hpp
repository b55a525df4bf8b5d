#pragma once
// Shared helpers for the tests: where the data lives, reading golden index files.

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace evcorner::test {

namespace fs = std::filesystem;

/// ../shared/data beside the checkout (real recordings, golden outputs).
inline fs::path shared_data() { return fs::path(EVCORNER_SHARED_DIR) / "data"; }
inline bool have_shared_data() { return fs::is_directory(shared_data() / "golden"); }

/// Samples bundled with the project (data/ in the source tree).
inline fs::path bundled_data() { return fs::path(EVCORNER_SOURCE_DIR) / "data"; }

/// A golden index file: 0-based positions of corner events, one per line.
inline std::vector<std::uint64_t> read_index_file(const fs::path& p) {
    std::ifstream in(p);
    if (!in) throw std::runtime_error("cannot open " + p.string());
    std::vector<std::uint64_t> v;
    std::uint64_t i;
    while (in >> i) v.push_back(i);
    if (!in.eof()) throw std::runtime_error("malformed index file " + p.string());
    return v;
}

/// The Event-Camera-Dataset text inputs the data README names, keyed by golden prefix.
struct EcdFile {
    std::string golden_prefix;  // e.g. "ecd-stppp.boxes_rotation"
    fs::path events;            // the text file
};
inline std::vector<EcdFile> ecd_text_files() {
    std::vector<EcdFile> files;
    for (const char* seq : {"boxes_rotation", "boxes_translation", "dynamic_rotation",
                            "dynamic_translation", "poster_rotation", "poster_translation",
                            "shapes_rotation", "shapes_translation"})
        files.push_back({std::string("ecd-stppp.") + seq,
                         shared_data() / "real/ecd-stppp" / seq / "events.txt"});
    files.push_back({"ecd-slider-depth-eventsviz.slider_depth",
                     shared_data() / "real/ecd-slider-depth-eventsviz/slider_depth/events_chunk.txt"});
    return files;
}

#define EVCORNER_REQUIRE_SHARED_DATA()                                                   \
    do {                                                                                 \
        if (!::evcorner::test::have_shared_data())                                       \
            GTEST_SKIP() << "../shared/data not found beside the checkout ("               \
                         << ::evcorner::test::shared_data().string()                     \
                         << "); skipping the tests on the full real-data set";           \
    } while (0)

}  // namespace evcorner::test
