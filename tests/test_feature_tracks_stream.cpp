// The streaming labeller (FeatureTrackStream) against the whole-stream labeller and the
// reference implementation (tests/feature_tracks_reference.hpp): the same labels and counts
// however the stream is cut into batches, in memory bounded by the max-duration window,
// time order enforced; and `evcorner label`, which streams, against the library.

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "evcorner/eval/feature_tracks.hpp"
#include "evcorner/io/text_reader.hpp"
#include "feature_tracks_reference.hpp"

namespace evcorner::eval {
namespace {

Event at(double x, double y, std::int64_t t, int p) {
    return Event{t, static_cast<std::uint16_t>(std::clamp<long>(std::lround(x), 0, 239)),
                 static_cast<std::uint16_t>(std::clamp<long>(std::lround(y), 0, 179)), static_cast<std::uint8_t>(p)};
}

// A long stream in time order on 240x180: tracks (straight, +-1 px jitter) starting all
// along it, clutter everywhere (also beside the tracks), exact ties in time.
std::vector<Event> long_stream(unsigned seed, std::int64_t span_us, int tracks, int clutter) {
    std::mt19937 rng(seed);
    std::vector<Event> out;
    std::uniform_real_distribution<double> px(10, 229), py(10, 169), v(-1.0, 1.0);
    std::uniform_int_distribution<std::int64_t> t0(0, span_us - 1);
    std::uniform_int_distribution<int> count(20, 70), step(200, 1500), pol(0, 1), jit(-1, 1);
    for (int k = 0; k < tracks; ++k) {
        const double x0 = px(rng), y0 = py(rng), vx = v(rng), vy = v(rng);
        const std::int64_t start = t0(rng), dt = step(rng);
        const int n = count(rng), p = pol(rng);
        for (int i = 0; i < n; ++i) {
            const double ms = static_cast<double>(i * dt) / 1000.0;
            out.push_back(at(x0 + vx * ms + jit(rng), y0 + vy * ms + jit(rng), start + i * dt, p));
        }
    }
    std::uniform_int_distribution<int> x(0, 239), y(0, 179);
    for (int k = 0; k < clutter; ++k) out.push_back(at(x(rng), y(rng), t0(rng), pol(rng)));
    for (int k = 0; k < clutter / 10; ++k) {
        Event e = out[static_cast<std::size_t>(k) * 13 % out.size()];
        e.x = static_cast<std::uint16_t>(std::min(239, e.x + 2));
        out.push_back(e);  // the same time as another corner, 2 px away
    }
    std::stable_sort(out.begin(), out.end(), [](const Event& a, const Event& b) { return a.t < b.t; });
    return out;
}

struct Streamed {
    std::vector<std::uint8_t> on_track;
    std::uint64_t labelled = 0, hypotheses = 0, accepted = 0;
    std::size_t max_retained = 0;
    std::size_t labels_before_finish = 0;
};

// Pushes `corners` in batches of `batch` (the last one shorter), collecting the labels.
Streamed stream_in_batches(const std::vector<Event>& corners, std::size_t batch, const FeatureTrackParams& p,
                           const std::string& path = {}) {
    FeatureTrackStream s(p, path);
    Streamed r;
    for (std::size_t at = 0; at < corners.size(); at += batch) {
        const std::size_t n = std::min(batch, corners.size() - at);
        const auto got = s.push(std::span<const Event>(corners).subspan(at, n));
        r.on_track.insert(r.on_track.end(), got.begin(), got.end());
        // Labels come out in input order and never ahead of the input.
        EXPECT_LE(r.on_track.size(), at + n);
        EXPECT_EQ(s.retained(), at + n - r.on_track.size()) << "every corner pushed is held or labelled";
    }
    r.labels_before_finish = r.on_track.size();
    const auto rest = s.finish();
    r.on_track.insert(r.on_track.end(), rest.begin(), rest.end());
    EXPECT_EQ(s.retained(), 0u);
    EXPECT_EQ(s.corners(), corners.size());
    r.labelled = s.labelled();
    r.hypotheses = s.hypotheses();
    r.accepted = s.accepted();
    r.max_retained = s.max_retained();
    return r;
}

// The most corner events within any closed interval of `duration` us (time-ordered input).
std::size_t densest_window(const std::vector<Event>& corners, std::int64_t duration) {
    std::size_t best = 0, lo = 0;
    for (std::size_t hi = 0; hi < corners.size(); ++hi) {
        while (corners[hi].t - corners[lo].t > duration) ++lo;
        best = std::max(best, hi - lo + 1);
    }
    return best;
}

void expect_stream_matches(const std::vector<Event>& corners, const FeatureTrackParams& p, const std::string& what,
                           const std::vector<std::size_t>& batches) {
    const FeatureTrackResult ref = label_feature_tracks_reference(corners, p);
    const FeatureTrackResult whole = label_feature_tracks(corners, p);
    EXPECT_EQ(whole.on_track, ref.on_track) << what;
    EXPECT_EQ(whole.hypotheses, ref.hypotheses) << what;
    EXPECT_EQ(whole.accepted, ref.accepted) << what;
    const std::size_t w = densest_window(corners, p.max_duration_us);
    for (const std::string& path : feature_track_code_paths()) {
        for (const std::size_t batch : batches) {
            const std::string in = what + ", batches of " + std::to_string(batch) + " on " + path;
            const Streamed s = stream_in_batches(corners, batch, p, path);
            EXPECT_EQ(s.on_track, ref.on_track) << in;
            EXPECT_EQ(s.labelled, ref.labelled) << in;
            EXPECT_EQ(s.hypotheses, ref.hypotheses) << in;
            EXPECT_EQ(s.accepted, ref.accepted) << in;
            // Memory: bounded by the window, not by the stream's length.
            EXPECT_LE(s.max_retained, 4 * w + 4096) << in;
        }
    }
}

TEST(FeatureTrackStream, SameAsWholeStreamAndReferenceOnSyntheticStreams) {
    for (unsigned seed = 1; seed <= 2; ++seed) {
        // 3 s: many windows of 100 ms, so the stream runs its anchors in many rounds.
        const std::vector<Event> corners = long_stream(seed, 3'000'000, 600, 30'000);
        FeatureTrackParams p;
        const FeatureTrackResult ref = label_feature_tracks_reference(corners, p);
        ASSERT_GT(ref.accepted, 0u) << "tracks to find";
        ASSERT_LT(ref.labelled, corners.size()) << "clutter to reject";
        const std::vector<std::size_t> batches = {1, 7, 4099, 65'537, corners.size()};
        const std::string s = ", seed " + std::to_string(seed);
        expect_stream_matches(corners, p, "defaults" + s, batches);
        p.overlap = TrackOverlap::exclusive;
        expect_stream_matches(corners, p, "exclusive" + s, batches);
        p = {};
        p.same_polarity = true;
        p.min_inner = 10;
        expect_stream_matches(corners, p, "per polarity, 10 inner" + s, {13, 5000});
        p = {};
        p.inner_radius = 2.5;
        p.outer_radius = 6.5;
        p.max_length = 33;
        p.max_outer_ratio = 0.5;
        p.min_inner = 12;
        p.cell_size = 5;
        p.max_duration_us = 20'000;  // a short window: many more rounds
        expect_stream_matches(corners, p, "other radii, 20 ms" + s, {3, 1000});
        p.overlap = TrackOverlap::exclusive;
        expect_stream_matches(corners, p, "other radii, 20 ms, exclusive" + s, {3, 1000});
    }
}

TEST(FeatureTrackStream, SameAsReferenceOnRealCornersInOddBatches) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(EVCORNER_SHARED_DIR) / "data/real/ecd-stppp";
    const fs::path golden = fs::path(EVCORNER_SHARED_DIR) / "data/golden";
    if (!fs::is_directory(dir)) GTEST_SKIP() << "no " << dir << " (the shared data folder)";
    for (const std::string seq : {"shapes_rotation", "dynamic_translation"}) {
        const std::vector<Event> events = io::read_text_file((dir / seq / "events.txt").string());
        std::vector<Event> corners;
        std::ifstream idx(golden / ("ecd-stppp." + seq + ".efast.idx"));
        for (std::size_t i; idx >> i;) corners.push_back(events.at(i));
        ASSERT_FALSE(corners.empty()) << seq;
        FeatureTrackParams p;
        expect_stream_matches(corners, p, seq, {1, 97, 1013, 65'537});
        p.overlap = TrackOverlap::exclusive;
        expect_stream_matches(corners, p, seq + " exclusive", {1, 97, 1013});
    }
}

TEST(FeatureTrackStream, MemoryStaysWithinTheWindowOnALongStream) {
    // 20 s of corners: the stream holds a few windows' worth, never the whole.
    const std::vector<Event> corners = long_stream(7, 20'000'000, 2000, 150'000);
    FeatureTrackParams p;
    const std::size_t w = densest_window(corners, p.max_duration_us);
    ASSERT_LT(4 * w + 4096, corners.size() / 4) << "the bound is well below the stream";
    for (const std::size_t batch : {std::size_t{1}, std::size_t{500}, std::size_t{65'536}}) {
        const Streamed s = stream_in_batches(corners, batch, p);
        EXPECT_LE(s.max_retained, 4 * w + 4096) << batch;
        // Labels leave while the stream goes on: all but the last window's before finish().
        EXPECT_GE(s.labels_before_finish + s.max_retained, corners.size()) << batch;
        EXPECT_EQ(s.on_track, label_feature_tracks(corners, p).on_track) << batch;
    }
}

TEST(FeatureTrackStream, RefusesTimeDisorderAndKeepsItsState) {
    const std::vector<Event> corners = long_stream(3, 400'000, 60, 2000);
    FeatureTrackParams p;
    FeatureTrackStream s(p);
    const std::size_t half = corners.size() / 2;
    std::vector<std::uint8_t> got;
    auto take = [&](std::span<const std::uint8_t> l) { got.insert(got.end(), l.begin(), l.end()); };
    take(s.push(std::span<const Event>(corners).first(half)));
    // A batch whose third event goes back in time: refused whole, naming the position.
    std::vector<Event> bad(corners.begin() + static_cast<std::ptrdiff_t>(half),
                           corners.begin() + static_cast<std::ptrdiff_t>(half) + 5);
    bad[2].t = corners[half - 1].t - 1;
    try {
        s.push(bad);
        ADD_FAILURE() << "disorder accepted";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("corner event " + std::to_string(half + 2)), std::string::npos) << what;
        EXPECT_NE(what.find("time order"), std::string::npos) << what;
    }
    EXPECT_EQ(s.corners(), half);
    take(s.push(std::span<const Event>(corners).subspan(half)));
    take(s.finish());
    EXPECT_EQ(got, label_feature_tracks_reference(corners, p).on_track);
    EXPECT_THROW(s.push(corners), std::logic_error);
    EXPECT_TRUE(s.finish().empty());
    EXPECT_THROW(FeatureTrackStream(p, "no-such-path"), std::invalid_argument);
    p.min_inner = 1;
    EXPECT_THROW(FeatureTrackStream{p}, std::invalid_argument);
}

TEST(FeatureTrackStream, WholeStreamLabellerTakesAnyOrder) {
    // label_feature_tracks() still sorts for itself: shuffled input, labels in input order.
    std::vector<Event> corners = long_stream(5, 500'000, 80, 3000);
    std::mt19937 rng(5);
    std::shuffle(corners.begin(), corners.end(), rng);
    const FeatureTrackResult ref = label_feature_tracks_reference(corners);
    const FeatureTrackResult r = label_feature_tracks(corners);
    EXPECT_EQ(r.on_track, ref.on_track);
    EXPECT_EQ(r.hypotheses, ref.hypotheses);
    EXPECT_GT(r.labelled, 0u);
}

#ifdef EVCORNER_CLI
std::string slurp(const std::filesystem::path& f) {
    std::ifstream in(f);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

TEST(FeatureTrackStream, LabelCommandStreamsTheSameLabels) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("evcorner-ftstream-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::vector<Event> corners = long_stream(11, 1'500'000, 300, 15'000);
    {
        std::ofstream f(dir / "corners.txt");
        for (const Event& e : corners)
            f << e.t / 1'000'000 << '.' << std::setw(6) << std::setfill('0') << e.t % 1'000'000 << ' ' << e.x << ' '
              << e.y << ' ' << int(e.p) << '\n';
    }
    auto run = [&](const std::string& args) {
        const std::string cmd = "cd '" + dir.string() + "' && '" EVCORNER_CLI "' label " + args +
                                " --no-progress >out.stdout 2>out.stderr </dev/null";
        const int raw = std::system(cmd.c_str());
        return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    };
    ASSERT_EQ(run("corners.txt -o labels.txt"), 0) << slurp(dir / "out.stderr");
    const FeatureTrackResult ref = label_feature_tracks_reference(corners);
    std::string expected;
    for (const std::uint8_t l : ref.on_track) expected += l ? "1\n" : "0\n";
    EXPECT_EQ(slurp(dir / "labels.txt"), expected);
    EXPECT_NE(slurp(dir / "out.stdout").find(std::to_string(ref.hypotheses) + " hypotheses"), std::string::npos)
        << slurp(dir / "out.stdout");
    // Out of time order: a data error naming the file and the position (the reader's
    // message where the format's reader checks the order, else the labeller's).
    {
        std::ofstream f(dir / "unsorted.txt");
        f << "0.000100 5 5 1\n0.000300 6 6 1\n0.000200 7 7 1\n";
    }
    EXPECT_EQ(run("unsorted.txt -o bad.txt"), 1);
    const std::string err = slurp(dir / "out.stderr");
    EXPECT_NE(err.find("unsorted.txt"), std::string::npos) << err;
    EXPECT_TRUE(err.find(":3:") != std::string::npos || err.find("corner event 2") != std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir / "bad.txt")) << "no partial output";
    fs::remove_all(dir);
}
#endif

}  // namespace
}  // namespace evcorner::eval
