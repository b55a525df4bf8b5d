// evcorner eval --tracks: every tracker of the registry under every seeding, on every
// sequence with GT tracks beside it, scored by the feature-track benchmark's metric; and the
// library pipeline behind it (pipeline/track_eval.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "cli_test_util.hpp"
#include "evcorner/pipeline/track_eval.hpp"
#include "evcorner/track/tracker.hpp"

namespace evcorner::test {
namespace {

std::vector<std::string> registry_trackers() {
    std::vector<std::string> v;
    for (const TrackerEntry& t : tracker_registry()) v.emplace_back(t.name);
    return v;
}

class CliEvalTracks : public CliTest {
protected:
    /// A suite folder: `short` (the shapes scene cut to 1.5 s, with its truth and GT tracks,
    /// as simulate --suite writes them) and `square` (events only, no GT tracks).
    void make_suite() {
        const auto scene = run("simulate --preset shapes --print-scene");
        ASSERT_EQ(scene.status, 0) << scene.err;
        nlohmann::json j = nlohmann::json::parse(scene.out);
        j["duration_s"] = 1.5;
        j["name"] = "short";
        fs::create_directories(dir_ / "suite");
        write("suite/short.json", j.dump(2));
        const auto s = run("simulate suite/short.json -o suite/short.events.npy --truth suite/short.truth.csv "
                           "--gt-tracks suite/short.gt-tracks.txt -q");
        ASSERT_EQ(s.status, 0) << s.err;
        ASSERT_EQ(run("simulate --preset square -o suite/square.npy -q").status, 0);
    }
};

TEST_F(CliEvalTracks, TheTrackingTableHasARowPerTrackerAndSeedingInStdoutReportAndJson) {
    make_suite();
    const auto r = run("eval suite -d efast --tracks --repeat 1 --report rep --no-figures -q");
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_NE(r.out.find("Tracking against GT tracks"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("synchronous"), std::string::npos);
    const std::string md = slurp(dir_ / "rep/report.md");
    ASSERT_NE(md.find("## Tracking"), std::string::npos) << md;
    for (const char* protocol : {"synchronous", "pixel-index", "100 Hz", "within 3 px", "GT t0"})
        EXPECT_NE(md.find(protocol), std::string::npos) << protocol;
    const auto trackers = registry_trackers();
    ASSERT_FALSE(trackers.empty());
    for (const auto& t : trackers)
        for (const char* seeding : {"GT t0", "efast"}) {
            EXPECT_NE(md.find("| short | " + t + " | " + seeding + " |"), std::string::npos) << t << " / " << seeding;
            // The text table: one line holding the sequence, the tracker and the seeding.
            bool found = false;
            std::istringstream lines(r.out);
            for (std::string line; std::getline(lines, line);)
                found = found || (line.starts_with("short ") && line.find(" " + t + " ") != std::string::npos &&
                                  line.find(std::string(" ") + seeding + " ") != std::string::npos);
            EXPECT_TRUE(found) << t << " / " << seeding << "\n" << r.out;
        }
    const auto doc = nlohmann::json::parse(slurp(dir_ / "rep/results.json"));
    ASSERT_TRUE(doc.contains("tracking"));
    const auto& rows = doc["tracking"]["rows"];
    ASSERT_EQ(rows.size(), trackers.size() * 2);
    std::set<std::pair<std::string, std::string>> seen;
    for (const auto& row : rows) {
        EXPECT_EQ(row["sequence"], "short");
        seen.insert({row["tracker"].get<std::string>(), row["seeding"].get<std::string>()});
        for (const char* key : {"fa", "efa", "fa_5", "fa_async"}) {
            const double v = row[key].get<double>();
            EXPECT_GE(v, 0.0) << key;
            EXPECT_LE(v, 1.0) << key;
        }
        EXPECT_GE(row["te_5"].get<double>(), 0.0);
        EXPECT_LE(row["te_5"].get<double>(), 5.0);  // tracks within 5 px, by definition
        EXPECT_NEAR(row["gt_rate_hz"].get<double>(), 100.0, 1e-6);
        if (row["seeding"] == "GT t0") {
            EXPECT_EQ(row["seeding_kind"], "gt");
            EXPECT_EQ(row["unmatched_tracks"], 0);  // every prediction is a GT id
            EXPECT_GT(row["counted_tracks"].get<int>(), 0);
        } else {
            EXPECT_EQ(row["seeding_kind"], "detector");
        }
    }
    EXPECT_EQ(seen.size(), rows.size());  // no row twice
    EXPECT_EQ(doc["tracking"]["mode"], "synchronous");
    EXPECT_EQ(doc["tracking"]["association_radius_px"], 3);
}

TEST_F(CliEvalTracks, ASequenceWithoutGtTracksIsListedNotDropped) {
    make_suite();
    const auto r = run("eval suite -d efast --tracks --trackers haste-correlation-star --repeat 1 --report rep "
                       "--no-figures -q");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("Without GT tracks (not tracked): square"), std::string::npos) << r.out;
    EXPECT_NE(slurp(dir_ / "rep/report.md").find("not tracked): square"), std::string::npos);
    const auto doc = nlohmann::json::parse(slurp(dir_ / "rep/results.json"));
    EXPECT_EQ(doc["tracking"]["without_gt_tracks"], nlohmann::json::array({"square"}));
    EXPECT_EQ(doc["tracking"]["rows"].size(), 2u);  // one tracker x (GT t0, efast), on `short` only
    EXPECT_EQ(doc["tracking"]["trackers"], nlohmann::json::array({"haste-correlation-star"}));
}

TEST_F(CliEvalTracks, UsageErrors) {
    make_suite();
    EXPECT_EQ(run("eval suite -d efast --trackers correlation --repeat 1").status, 2);  // needs --tracks
    const auto u = run("eval suite -d efast --tracks --trackers nope --repeat 1");
    EXPECT_EQ(u.status, 2);
    EXPECT_NE(u.err.find("haste-correlation-star"), std::string::npos) << u.err;  // names the trackers there are
    EXPECT_EQ(run("eval suite -d efast --tracks --tracks-golden suite --repeat 1").status, 2);  // no seeds.txt
}

TEST_F(CliEvalTracks, TheAuthorsGoldenRowsMatchOurTrackersFromTheSameSeeds) {
    if (!have_shared_data()) GTEST_SKIP() << "../shared/data is not beside the checkout (golden HASTE outputs)";
    // The goldens' input is the shapes preset, named `shapes` as the suite names it.
    fs::create_directories(dir_ / "suite");
    ASSERT_EQ(run("simulate --preset shapes -o suite/shapes.events.npy --gt-tracks suite/shapes.gt-tracks.txt -q").status,
              0);
    const fs::path g = shared_data() / "golden/haste/sim-shapes";
    const auto r = run("eval suite -d efast --tracks --trackers haste-correlation-star --tracks-golden '" + g.string() +
                       "' --repeat 1 --report rep --no-figures -q");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto doc = nlohmann::json::parse(slurp(dir_ / "rep/results.json"));
    std::map<std::pair<std::string, std::string>, nlohmann::json> by;
    for (const auto& row : doc["tracking"]["rows"]) by[{row["tracker"], row["seeding"]}] = row;
    EXPECT_EQ(by.size(), 4u + 6u);  // ours: GT t0, efast, golden seeds x 2 starts; the authors' six outputs
    for (const char* init : {"uncentered", "centered"}) {
        const std::string seeding = std::string("golden seeds (") + init + ")";
        ASSERT_TRUE(by.count({"authors' haste-correlation-star", seeding})) << seeding;
        ASSERT_TRUE(by.count({"haste-correlation-star", seeding})) << seeding;
        const auto& theirs = by[{"authors' haste-correlation-star", seeding}];
        const auto& ours = by[{"haste-correlation-star", seeding}];
        EXPECT_EQ(theirs["source"], "the authors' HASTE app");
        EXPECT_EQ(theirs["unmatched_tracks"], 0);
        EXPECT_GT(theirs["fa"].get<double>(), 0.2);
        // docs/tracking.md: ours equals the app state for state on sim-shapes.
        EXPECT_NEAR(ours["fa"].get<double>(), theirs["fa"].get<double>(), 0.01) << seeding;
        EXPECT_EQ(ours["counted_tracks"], theirs["counted_tracks"]) << seeding;
    }
    EXPECT_NE(slurp(dir_ / "rep/report.md").find("| shapes | authors' haste-correlation-star | golden seeds (uncentered) |"),
              std::string::npos);
}

TEST_F(CliEvalTracks, LibraryRowsPerTrackerAndSeedingAndGtSeededTracksLive) {
    ASSERT_EQ(run("simulate --preset shapes -o ev.npy --gt-tracks gt.txt -q").status, 0);
    pipeline::TrackEvalFiles f;
    f.sequence = "shapes";
    f.events = (dir_ / "ev.npy").string();
    f.gt = (dir_ / "gt.txt").string();
    const std::vector<std::string> trackers{"haste-correlation-star", "haste-difference-star"};
    const std::vector<pipeline::TrackSeeding> seedings{pipeline::gt_seeding(),
                                                       pipeline::detector_seeding(DetectorConfig{"efast", {}})};
    std::size_t reported = 0;
    const auto rows = pipeline::evaluate_trackers(f, trackers, seedings, {},
                                                  [&](const pipeline::TrackEvalRow&) { ++reported; });
    ASSERT_EQ(rows.size(), trackers.size() * seedings.size());
    EXPECT_EQ(reported, rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto& r = rows[i];
        EXPECT_EQ(r.sequence, "shapes");
        EXPECT_EQ(r.tracker, trackers[i / seedings.size()]);  // tracker-major
        EXPECT_EQ(r.seeding, seedings[i % seedings.size()].name);
        EXPECT_GT(r.updates, 0u);
        EXPECT_TRUE(std::isfinite(r.ns_per_update));
        EXPECT_NEAR(r.gt_rate_hz, 100.0, 1e-6);
        if (r.kind == pipeline::SeedingKind::gt) {
            EXPECT_GT(r.fa, 0.2) << r.tracker;  // HASTE follows the shapes' corners for part of their life
            EXPECT_LT(r.fa, 1.0);
            EXPECT_EQ(r.predicted_tracks, r.gt_tracks);  // a track per GT id
            EXPECT_EQ(r.unmatched_tracks, 0u);
        } else {
            EXPECT_EQ(r.seeding, "efast");
            EXPECT_GT(r.counted_tracks, 0u);  // some front-end tracks start on a GT corner
            EXPECT_EQ(r.counted_tracks + r.skipped_tracks + r.unmatched_tracks, r.predicted_tracks);
        }
        EXPECT_GE(r.fa, r.efa);  // r_e <= 1
    }
    // The GT scored through its own seeds is perfect: the metric's fixed point.
    const auto self = pipeline::evaluate_track_file(f.gt, f.gt, f.gt);
    EXPECT_DOUBLE_EQ(self.fa, 1.0);
    EXPECT_DOUBLE_EQ(self.te_5, 0.0);
    EXPECT_EQ(self.unmatched_tracks, 0u);
    EXPECT_TRUE(std::isnan(self.ns_per_update));
    // A GT corner within half a pixel of the border (pixel 0 in the pixel-index convention,
    // x < 0) is refused by the trackers: it is left out and counted, not an error.
    {
        std::string text = slurp(f.gt);
        text += "999999 0.5 -0.3 50\n999999 0.6 -0.3 51\n";
        pipeline::TrackEvalFiles g = f;
        g.gt = write("gt-border.txt", text);
        const std::vector<std::string> one{"haste-correlation-star"};
        const std::vector<pipeline::TrackSeeding> gt_only{pipeline::gt_seeding()};
        const auto b = pipeline::evaluate_trackers(g, one, gt_only);
        ASSERT_EQ(b.size(), 1u);
        EXPECT_EQ(b[0].unseeded_tracks, 1u);
        EXPECT_EQ(b[0].predicted_tracks + 1, b[0].gt_tracks);
        EXPECT_EQ(b[0].unmatched_tracks, 0u);
        EXPECT_EQ(rows[0].unseeded_tracks, 0u);
    }
    // Names are checked before the events are read.
    const std::vector<std::string> unknown{"nope"};
    EXPECT_THROW(pipeline::evaluate_trackers(f, unknown, seedings), std::invalid_argument);
}

}  // namespace
}  // namespace evcorner::test
