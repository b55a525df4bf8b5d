// evcorner simulate from the command line: round trip through the files it writes, errors,
// and the example scenes in data/scenes.

#include <gtest/gtest.h>

#include <algorithm>

#include "cli_test_util.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/sim/presets.hpp"
#include "evcorner/sim/scene.hpp"
#include "evcorner/sim/truth.hpp"

namespace evcorner::test {
namespace {

using SimulateCli = CliTest;

std::vector<Event> read_events(const fs::path& p) {
    auto reader = io::open_event_reader(p.string(), {}, "auto");
    return io::read_all_events(*reader);
}

TEST_F(SimulateCli, PresetRoundTripsThroughEventsAndTruth) {
    const CliResult r = run("simulate --preset square -o ev.npy --truth truth.csv");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("19200 (9600 ON, 9600 OFF"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("M simulated events/s"), std::string::npos) << r.err;
    const std::vector<Event> ev = read_events(dir_ / "ev.npy");
    ASSERT_EQ(ev.size(), 19200u);
    EXPECT_TRUE(std::is_sorted(ev.begin(), ev.end(), [](const Event& a, const Event& b) { return a.t < b.t; }));
    EXPECT_EQ(std::count_if(ev.begin(), ev.end(), [](const Event& e) { return e.p == 1; }), 9600);
    // 4 corners, sampled at 0, 100, ..., 400000 us.
    const auto truth = sim::read_truth_csv((dir_ / "truth.csv").string());
    ASSERT_EQ(truth.size(), 4u * 4001u);
    EXPECT_EQ(truth.back().t_us, 400000);
    EXPECT_NEAR(truth.back().x, 60 + 100 * 0.4, 1e-6);  // corner 3 started at (60, 110)
    EXPECT_NEAR(truth.back().y, 110, 1e-6);
    EXPECT_EQ(slurp(dir_ / "truth.csv").rfind(std::string(sim::kTruthHeader) + "\n", 0), 0u);
}

TEST_F(SimulateCli, SameSceneSameBytesOtherSeedOtherBytes) {
    write("a.json", R"({"sensor": [64, 48], "duration_s": 0.5, "seed": 1, "camera": {"noise_hz": 5, "contrast_sigma": 0.05},
      "objects": [{"polygon": [[10, 10], [30, 12], [20, 30]], "intensity": 0.9, "motion": {"velocity": [40, 10]}}]})");
    write("b.json", R"({"sensor": [64, 48], "duration_s": 0.5, "seed": 2, "camera": {"noise_hz": 5, "contrast_sigma": 0.05},
      "objects": [{"polygon": [[10, 10], [30, 12], [20, 30]], "intensity": 0.9, "motion": {"velocity": [40, 10]}}]})");
    ASSERT_EQ(run("simulate a.json -o a1.txt -q").status, 0);
    ASSERT_EQ(run("simulate a.json -o a2.txt -q").status, 0);
    ASSERT_EQ(run("simulate b.json -o b.txt -q").status, 0);
    const std::string a1 = slurp(dir_ / "a1.txt"), a2 = slurp(dir_ / "a2.txt"), b = slurp(dir_ / "b.txt");
    EXPECT_GT(count_lines(a1), 1000u);
    EXPECT_EQ(a1, a2);
    EXPECT_NE(a1, b);
}

TEST_F(SimulateCli, BadSceneNamesTheFileAndKeyWithStatus1) {
    write("bad.json", R"({"sensor": [64, 48], "duration_s": 1, "objects": [{"polygon": [[0, 0], [5, 0], [0, 5]], "intensity": 2}]})");
    const CliResult r = run("simulate bad.json -o ev.txt");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("bad.json: /objects/0/intensity: 2 is out of range"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "ev.txt"));
    const CliResult m = run("simulate missing.json -o ev.txt");
    EXPECT_EQ(m.status, 1);
    EXPECT_NE(m.err.find("missing.json"), std::string::npos) << m.err;
}

TEST_F(SimulateCli, UsageErrorsHaveStatus2) {
    EXPECT_EQ(run("simulate --preset square").status, 2);                              // no -o
    EXPECT_EQ(run("simulate --preset nope -o x.txt").status, 2);                      // unknown preset
    EXPECT_EQ(run("simulate --preset square -o same.csv --truth same.csv").status, 2);  // one file twice
    EXPECT_EQ(run("simulate --preset square --suite dir").status, 2);                 // two sources
    EXPECT_EQ(run("simulate --preset square -o x.json").status, 2);                   // not an event format
    write("s.json", "{}");
    EXPECT_EQ(run("simulate s.json -o s.json").status, 2);  // output onto the scene
}

TEST_F(SimulateCli, PrintSceneGivesThePresetThatRunsAsAFile) {
    const CliResult p = run("simulate --preset square --print-scene");
    ASSERT_EQ(p.status, 0);
    write("square.json", p.out);
    ASSERT_EQ(run("simulate square.json -o f.txt -q").status, 0);
    ASSERT_EQ(run("simulate --preset square -o p.txt -q").status, 0);
    EXPECT_EQ(slurp(dir_ / "f.txt"), slurp(dir_ / "p.txt"));
}

TEST_F(SimulateCli, ExampleScenesInTheRepositoryAreThePresetsAndParse) {
    // data/scenes/NAME.json is `evcorner simulate --preset NAME --print-scene`; regenerate it
    // when a preset changes on purpose.
    for (const auto& p : sim::presets()) {
        const fs::path file = bundled_data() / "scenes" / (p.name + ".json");
        ASSERT_TRUE(fs::exists(file)) << file;
        EXPECT_EQ(slurp(file), sim::preset_scene_json(p.name)) << file;
    }
    const sim::Scene ex = sim::load_scene_file((bundled_data() / "scenes" / "example.json").string());
    EXPECT_EQ(ex.objects.size(), 3u);
    EXPECT_EQ(ex.camera.hot_pixels, 2);
    EXPECT_TRUE(ex.objects[1].motion.profile.ramp);
}

}  // namespace
}  // namespace evcorner::test
