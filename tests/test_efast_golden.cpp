// eFAST against the reference outputs: the positions of the corner events must equal
// the golden index files exactly.

#include <gtest/gtest.h>

#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/io/text_reader.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

std::vector<std::uint64_t> efast_corner_positions(const std::string& events_file) {
    const auto events = io::read_text_file(events_file);
    EFast det(kDavis240);
    std::vector<std::uint8_t> flags(events.size());
    detect(det, std::span<const Event>(events), flags);
    std::vector<std::uint64_t> pos;
    for (std::size_t i = 0; i < flags.size(); ++i)
        if (flags[i]) pos.push_back(i);
    return pos;
}

void expect_same_positions(const std::vector<std::uint64_t>& got,
                           const std::vector<std::uint64_t>& golden, const std::string& what) {
    ASSERT_FALSE(golden.empty()) << what;
    EXPECT_EQ(got.size(), golden.size()) << what;
    const std::size_t n = std::min(got.size(), golden.size());
    for (std::size_t i = 0; i < n; ++i)
        ASSERT_EQ(got[i], golden[i]) << what << ": corner #" << i << " differs";
}

TEST(EFastGolden, BundledSample) {
    const auto dir = test::bundled_data() / "ecd/shapes_translation";
    expect_same_positions(efast_corner_positions((dir / "events.txt").string()),
                          test::read_index_file(dir / "efast.golden.idx"), "bundled shapes_translation");
}

TEST(EFastGolden, EveryEventCameraDatasetTextFile) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const auto& f : test::ecd_text_files()) {
        SCOPED_TRACE(f.golden_prefix);
        const auto golden = test::read_index_file(test::shared_data() / "golden" /
                                                  (f.golden_prefix + ".efast.idx"));
        expect_same_positions(efast_corner_positions(f.events.string()), golden, f.golden_prefix);
    }
}

}  // namespace
}  // namespace evcorner
