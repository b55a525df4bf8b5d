// The spatially-adaptive Harris detector against the reference outputs on every
// Event-Camera-Dataset text file with a golden: corner positions exactly, and every
// event's score within 1e-6 (the golden writes 10 significant digits, -2 = no score).

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "evcorner/harris.hpp"
#include "evcorner/io/text_reader.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

using test::fs::path;

std::vector<double> read_scores_gz(const path& p) {
    gzFile f = gzopen(p.c_str(), "rb");
    if (f == nullptr) throw std::runtime_error("cannot open " + p.string());
    std::vector<double> v;
    char line[128];
    while (gzgets(f, line, sizeof line) != nullptr) {
        char* end = nullptr;
        const double d = std::strtod(line, &end);
        if (end == line) {
            gzclose(f);
            throw std::runtime_error("malformed score line in " + p.string());
        }
        v.push_back(d);
    }
    gzclose(f);
    return v;
}

class HarrisGolden : public ::testing::TestWithParam<test::EcdFile> {};

TEST_P(HarrisGolden, CornersAndScoresMatchTheReference) {
    EVCORNER_REQUIRE_SHARED_DATA();
    const test::EcdFile& file = GetParam();
    const auto golden_dir = test::shared_data() / "golden";
    const std::vector<Event> events = io::read_text_file(file.events.string());
    const std::vector<std::uint64_t> expected =
        test::read_index_file(golden_dir / (file.golden_prefix + ".harris.idx"));
    const std::vector<double> scores = read_scores_gz(golden_dir / (file.golden_prefix + ".harris.scores.gz"));
    ASSERT_EQ(scores.size(), events.size());

    // Every selection code this CPU runs (harris_select.hpp), the default first.
    for (const std::string& path : harris_code_paths()) {
        Harris det(kDavis240);
        det.set_code_path(harris_path_named(path));
        std::vector<std::uint64_t> corners;
        double worst = 0;
        std::size_t worst_at = 0, score_mismatches = 0;
        for (std::size_t i = 0; i < events.size(); ++i) {
            if (det.process(events[i])) corners.push_back(i);
            const double s = std::isnan(det.last_score()) ? -2.0 : det.last_score();
            const double diff = std::abs(s - scores[i]);
            if (diff > worst) {
                worst = diff;
                worst_at = i;
            }
            if (diff > 1e-6 && ++score_mismatches <= 5)
                ADD_FAILURE() << file.golden_prefix << " " << path << " event " << i << ": score " << s << ", golden "
                              << scores[i];
        }
        EXPECT_EQ(score_mismatches, 0u) << path;
        EXPECT_EQ(corners, expected) << file.golden_prefix << " " << path << ": " << corners.size()
                                     << " corners, golden " << expected.size();
        std::printf("[ harris   ] %-45s %-8s %5zu corners (golden %5zu), largest score difference %.3g (event %zu)\n",
                    file.golden_prefix.c_str(), path.c_str(), corners.size(), expected.size(), worst, worst_at);
    }
}

INSTANTIATE_TEST_SUITE_P(Ecd, HarrisGolden, ::testing::ValuesIn(test::ecd_text_files()),
                         [](const auto& info) {
                             std::string name = info.param.golden_prefix;
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return name;
                         });

}  // namespace
}  // namespace evcorner
