// Arc* against its authors' outputs: the positions of the corner events must equal
// ../shared/data/golden/*.arcstar.idx exactly on every file that has one (the 8 ECD cuts
// and the 2 DAVIS240C AEDAT 2.0 recordings, read as stored, no flip), with the fast
// path, with each code path, and with the oracle.

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "evcorner/arcstar.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/io/aedat2_reader.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/text_reader.hpp"
#include "evcorner/naive/arcstar_naive.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

std::vector<std::uint64_t> positions(const std::vector<std::uint8_t>& flags) {
    std::vector<std::uint64_t> pos;
    for (std::size_t i = 0; i < flags.size(); ++i)
        if (flags[i]) pos.push_back(i);
    return pos;
}

std::vector<std::uint64_t> arcstar_positions(const std::vector<Event>& events, const ArcStarParams& params = {}) {
    ArcStar det(kDavis240, params);
    std::vector<std::uint8_t> flags(events.size());
    detect(det, std::span<const Event>(events), flags);
    return positions(flags);
}

std::vector<std::uint64_t> arcstar_positions_one_by_one(const std::vector<Event>& events) {
    ArcStar det(kDavis240);
    std::vector<std::uint8_t> flags(events.size());
    for (std::size_t i = 0; i < events.size(); ++i) flags[i] = det.process(events[i]);
    return positions(flags);
}

std::vector<std::uint64_t> oracle_positions(const std::vector<Event>& events) {
    naive::ArcStarNaive det(kDavis240);
    std::vector<std::uint8_t> flags(events.size());
    for (std::size_t i = 0; i < events.size(); ++i) flags[i] = det.process(events[i]);
    return positions(flags);
}

struct GoldenFile {
    std::string prefix;  // golden file prefix
    std::vector<Event> (*load)(const std::string&);
    std::string events;  // relative to shared data
};

std::vector<Event> load_text(const std::string& path) { return io::read_text_file(path); }
std::vector<Event> load_aedat2(const std::string& path) {
    io::Aedat2Reader reader(path);  // x, y, polarity as stored: the goldens' layout
    return io::read_all_events(reader);
}

class ArcStarGolden : public ::testing::TestWithParam<GoldenFile> {};

TEST_P(ArcStarGolden, CornerPositionsEqualTheAuthorsOutput) {
    EVCORNER_REQUIRE_SHARED_DATA();
    const GoldenFile& f = GetParam();
    const auto events = f.load((test::shared_data() / f.events).string());
    const auto golden = test::read_index_file(test::shared_data() / "golden" / (f.prefix + ".arcstar.idx"));
    ASSERT_FALSE(golden.empty());
    const auto got = arcstar_positions(events);
    EXPECT_EQ(got.size(), golden.size());
    EXPECT_EQ(got, golden);
    // process() one event at a time (the portable search) and the oracle agree too.
    EXPECT_EQ(arcstar_positions_one_by_one(events), golden);
    EXPECT_EQ(oracle_positions(events), golden);
    // The authors' zero-initialised filter gives the same: every file starts after 50 ms.
    ASSERT_GT(events.front().t, 50000);
    EXPECT_EQ(arcstar_positions(events, {.zero_init = true}), golden);
}

std::vector<GoldenFile> golden_files() {
    std::vector<GoldenFile> files;
    for (const char* seq : {"boxes_rotation", "boxes_translation", "dynamic_rotation", "dynamic_translation",
                            "poster_rotation", "poster_translation", "shapes_rotation", "shapes_translation"})
        files.push_back({std::string("ecd-stppp.") + seq, load_text, std::string("real/ecd-stppp/") + seq + "/events.txt"});
    for (const char* rec : {"IMU_rotDisk", "IMU_translBoxes"})
        files.push_back({std::string("davis240c-imu-pyaedattools.") + rec, load_aedat2,
                         std::string("real/davis240c-imu-pyaedattools/") + rec + ".aedat"});
    return files;
}

INSTANTIATE_TEST_SUITE_P(Files, ArcStarGolden, ::testing::ValuesIn(golden_files()),
                         [](const auto& info) {
                             std::string n = info.param.prefix.substr(info.param.prefix.find('.') + 1);
                             for (char& c : n)
                                 if (c == '-' || c == '.') c = '_';
                             return n;
                         });

// The portable loop (EVCORNER_ARCSTAR_PATH=portable is read once per process, so this
// compares the templated loops directly).
TEST(ArcStarGoldenPaths, PortableLoopEqualsGolden) {
    EVCORNER_REQUIRE_SHARED_DATA();
    const auto files = golden_files();
    const GoldenFile& f = files.front();
    const auto events = f.load((test::shared_data() / f.events).string());
    ArcStar det(kDavis240);
    std::vector<std::uint8_t> flags(events.size());
    det.run_unchecked<ScalarSearch>(events, flags);
    EXPECT_EQ(positions(flags), test::read_index_file(test::shared_data() / "golden" / (f.prefix + ".arcstar.idx")));
}

// The AVX2 loop (detect() runs the AVX-512 one on a CPU that has it), every golden file.
#ifdef EVCORNER_HAVE_AVX2_SEARCH
[[gnu::target("avx2"), gnu::flatten]] void run_avx2(ArcStar& det, std::span<const Event> events,
                                                    std::span<std::uint8_t> flags) {
    det.run_unchecked<Avx2Search>(events, flags);
}
TEST(ArcStarGoldenPaths, Avx2LoopEqualsGolden) {
    EVCORNER_REQUIRE_SHARED_DATA();
    __builtin_cpu_init();
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2 on this CPU";
    for (const GoldenFile& f : golden_files()) {
        const auto events = f.load((test::shared_data() / f.events).string());
        ArcStar det(kDavis240);
        std::vector<std::uint8_t> flags(events.size());
        run_avx2(det, events, flags);
        EXPECT_EQ(positions(flags), test::read_index_file(test::shared_data() / "golden" / (f.prefix + ".arcstar.idx")))
            << f.prefix;
    }
}
#endif

}  // namespace
}  // namespace evcorner
