// detect --with-score into every format that carries scores, and those files read back by
// the commands that take corner files (label, render, info, convert).

#include <gtest/gtest.h>

#include "cli_test_util.hpp"

namespace evcorner::test {
namespace {

class CliScores : public CliTest {};

std::string quoted(const std::string& path) {
    std::string q = "'";
    q.append(path).append("'");  // not "'" + path: GCC 12 -Wrestrict false positive
    return q;
}

TEST_F(CliScores, ScoredCornerFilesReadBackEverywhere) {
    const std::string in = quoted(sample_.string());
    CliResult r = run("detect " + in + " -d harris -q -o plain.txt");
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string plain = slurp(dir_ / "plain.txt");
    ASSERT_GT(count_lines(plain), 100u);
    r = run("label plain.txt -o labels-plain.txt");
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string labels_plain = slurp(dir_ / "labels-plain.txt");
    for (const std::string ext : {"txt", "csv", "npy", "h5"}) {
        SCOPED_TRACE(ext);
        const std::string f = "scored." + ext;
        r = run("detect " + in + " -d harris -q --with-score -o " + f);
        ASSERT_EQ(r.status, 0) << r.err;
        // The same corners as without scores, and the same labels.
        r = run("convert " + f + " back-" + ext + ".txt");
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(slurp(dir_ / ("back-" + ext + ".txt")), plain);
        r = run("label " + f + " -o labels-" + ext + ".txt");
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(slurp(dir_ / ("labels-" + ext + ".txt")), labels_plain);
        r = run("render " + f + " -o r-" + ext + ".png");
        EXPECT_EQ(r.status, 0) << r.err;
        EXPECT_TRUE(fs::exists(dir_ / ("r-" + ext + ".png")));
    }
    // The CSV has a score column in its header.
    EXPECT_EQ(slurp(dir_ / "scored.csv").substr(0, 14), "t,x,y,p,score\n");
    // AEDAT 4.0 cannot hold a score: refused before anything is read or written.
    r = run("detect " + in + " -d harris -q --with-score -o scored.aedat4");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("evcorner: error:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("no field for a score"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "scored.aedat4"));
}

}  // namespace
}  // namespace evcorner::test
