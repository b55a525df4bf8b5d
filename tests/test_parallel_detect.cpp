// Parallel detection: identical flags, in input order, to one detector on one thread,
// for 1..4 threads and 1..3 parts per thread, on random HD streams, small sensors and
// the bundled sample; batches queued ahead (prepare/run) as evcorner detect does; for
// every local detector of the registry, split as its entry says, and for a detector
// whose decision reads the other polarity (parts of both polarities).

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <vector>

#include "blob_stream.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/harris.hpp"
#include "evcorner/io/text_reader.hpp"
#include "evcorner/parallel_detect.hpp"
#include "evcorner/registry.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

// Blobs drifting over the sensor (edges and corners), uniform clutter, ties in time.
std::vector<Event> random_stream(SensorSize s, std::size_t n, std::uint32_t seed) {
    return test::blob_stream(s, n, seed,
                             {.blobs = 12, .speed = 4, .spread = 4.0, .drift = 0.01, .clutter = 0.1, .start_t = 0});
}

template <class D, class Make>
void expect_same_as_one_thread(const std::vector<Event>& events, SensorSize s, Locality radius, Make make,
                               std::size_t batch, bool need_corners = true) {
    D one = make(s, 2);
    std::vector<std::uint8_t> expected(events.size());
    const std::size_t corners = detect(one, std::span<const Event>(events), expected);
    if (need_corners) {
        ASSERT_GT(corners, 0u);  // else the comparison is empty
    }
    for (int threads = 1; threads <= 4; ++threads)
        for (int per_thread = 1; per_thread <= 3; ++per_thread) {
            SCOPED_TRACE(testing::Message() << threads << " threads, " << per_thread << " parts per thread");
            {
                // detect() over batches, as evcorner bench does: the state carries over.
                ParallelDetector<D> par(s, threads, radius, make, per_thread);
                std::vector<std::uint8_t> got(events.size(), 7);
                std::size_t c = 0;
                for (std::size_t at = 0; at < events.size(); at += batch) {
                    const std::size_t n = std::min(batch, events.size() - at);
                    c += par.detect(std::span<const Event>(events).subspan(at, n), std::span<std::uint8_t>(got).subspan(at, n));
                }
                EXPECT_EQ(c, corners);
                for (std::size_t i = 0; i < events.size(); ++i) ASSERT_EQ(got[i], expected[i]) << "event " << i;
            }
            if (threads == 1) continue;  // one thread: detect() only
            {
                // prepare() of batch k + 1 alongside run() of batch k, as evcorner detect does.
                ParallelDetector<D> par(s, threads, radius, make, per_thread);
                const std::size_t step = std::min(batch, ParallelDetector<D>::kMaxBatch);
                std::vector<std::uint8_t> got(events.size(), 7);
                std::size_t c = 0;
                par.prepare(std::span<const Event>(events).first(std::min(step, events.size())));
                for (std::size_t at = 0; at < events.size(); at += step) {
                    const std::size_t n = std::min(step, events.size() - at);
                    const std::size_t next = at + n;
                    c += par.run(std::span<std::uint8_t>(got).subspan(at, n), [&] {
                        if (next < events.size())
                            par.prepare(std::span<const Event>(events).subspan(next, std::min(step, events.size() - next)));
                    });
                }
                EXPECT_EQ(c, corners);
                for (std::size_t i = 0; i < events.size(); ++i) ASSERT_EQ(got[i], expected[i]) << "event " << i;
            }
        }
}

TEST(ParallelDetect, EFastRandomHdStreams) {
    const SensorSize hd{1280, 720};
    for (std::uint32_t seed = 1; seed <= 3; ++seed) {
        SCOPED_TRACE(seed);
        const auto events = random_stream(hd, 300000, seed);
        expect_same_as_one_thread<EFast>(events, hd, kCircleMargin, [](SensorSize z, int planes) { return EFast(z, planes); }, 70000);
    }
}

TEST(ParallelDetect, EFastSmallSensors) {
    for (const SensorSize s : {SensorSize{9, 9}, SensorSize{17, 11}, SensorSize{64, 48}}) {
        const auto events = random_stream(s, 40000, 11);
        expect_same_as_one_thread<EFast>(events, s, kCircleMargin, [](SensorSize z, int planes) { return EFast(z, planes); }, 4096,
                                         /*need_corners=*/s.width > 32);
    }
}

TEST(ParallelDetect, EFastBundledSample) {
    const auto events = io::read_text_file((test::bundled_data() / "ecd/shapes_translation/events.txt").string());
    expect_same_as_one_thread<EFast>(events, kDavis240, kCircleMargin, [](SensorSize z, int planes) { return EFast(z, planes); }, 1 << 16);
}

// eFAST's parts get each batch's time span (ParallelDetector passes it down), and leave
// out the AVX-512 range check only while every time a part has taken spans less than
// 2^30 us: gaps just under and over that, and far beyond, between batches.
TEST(ParallelDetect, EFastAcrossGapsBeyondTheNarrowRange) {
    const SensorSize s{240, 180};
    std::vector<Event> events = random_stream(s, 60000, 13);
    const std::int64_t narrow = std::int64_t{1} << 30;
    const std::int64_t gaps[] = {narrow - 3, narrow + 1, std::int64_t{1} << 40, 2 * narrow};
    std::int64_t shift = 0;
    for (std::size_t i = 0; i < events.size(); ++i) {
        if (i > 0 && i % 9000 == 0) shift += gaps[(i / 9000) % std::size(gaps)];
        events[i].t += shift;
    }
    expect_same_as_one_thread<EFast>(events, s, kCircleMargin, [](SensorSize z, int planes) { return EFast(z, planes); }, 5000);
}

TEST(ParallelDetect, HarrisRandomHdStream) {
    const SensorSize hd{1280, 720};
    const auto events = random_stream(hd, 40000, 5);
    expect_same_as_one_thread<Harris>(events, hd, HarrisParams{}.window / 2, [](SensorSize z, int planes) { return Harris(z, {}, planes); }, 9000);
}

TEST(ParallelDetect, BatchesThatLeavePartsEmpty) {
    // The first batch spreads over the whole sensor (all parts get events), later ones
    // stay in a few rows of one polarity, so most parts see nothing in them.
    const SensorSize s{240, 180};
    std::vector<Event> events = random_stream(s, 20000, 21);
    std::mt19937_64 rng(5);
    std::int64_t t = events.back().t;
    for (int i = 0; i < 60000; ++i) {
        t += static_cast<std::int64_t>(rng() % 2);
        events.push_back({t, static_cast<std::uint16_t>(20 + rng() % 40), static_cast<std::uint16_t>(30 + rng() % 12), 1});
    }
    expect_same_as_one_thread<EFast>(events, s, kCircleMargin, [](SensorSize z, int planes) { return EFast(z, planes); }, 20000);
}

TEST(ParallelDetect, OnePlaneDetectorsMatchOnOnePolarity) {
    // A part sees one polarity and keeps one state plane: on such a stream, the same flags
    // as the two-plane detector, at half the state.
    const SensorSize s{240, 180};
    std::vector<Event> events;
    for (const Event& e : random_stream(s, 60000, 31))
        if (e.p == 1) events.push_back(e);
    std::vector<std::uint8_t> two(events.size()), one(events.size());
    {
        EFast a(s), b(s, 1);
        EXPECT_GT(detect(a, std::span<const Event>(events), two), 0u);
        detect(b, std::span<const Event>(events), one);
        EXPECT_EQ(one, two);
        EXPECT_EQ(2 * b.memory_bytes(), a.memory_bytes());
    }
    {
        Harris a(s), b(s, {}, 1);
        EXPECT_GT(detect(a, std::span<const Event>(events), two), 0u);
        detect(b, std::span<const Event>(events), one);
        EXPECT_EQ(one, two);
        EXPECT_EQ(2 * b.memory_bytes(), a.memory_bytes());
    }
}

TEST(ParallelDetect, BandsSplitEachPolarityEvenly) {
    const SensorSize hd{1280, 720};
    const auto events = random_stream(hd, 50000, 9);
    const auto parts = plan_parts(hd, 2, kCircleMargin, events);
    ASSERT_EQ(parts.size(), 4u);
    for (int p = 0; p < 2; ++p) {
        std::size_t in_first = 0, of_p = 0;
        for (const Event& e : events) {
            of_p += e.p == p;
            in_first += parts[2 * static_cast<std::size_t>(p)].owns(e.p, e.y);
        }
        EXPECT_NEAR(static_cast<double>(in_first) / static_cast<double>(of_p), 0.5, 0.01) << "polarity " << p;
    }
}

TEST(ParallelDetect, PartsCoverTheSensorOnceWithHalos) {
    for (const SensorSize s : {SensorSize{1280, 720}, SensorSize{240, 180}, SensorSize{17, 11}, SensorSize{9, 9}}) {
        const auto events = random_stream(s, 20000, 3);
        for (int bands = 1; bands <= 40; ++bands) {
            const int radius = 4;
            const auto parts = plan_parts(s, bands, radius, events);
            ASSERT_GE(parts.size(), 2u);
            ASSERT_LE(parts.size(), 2u * static_cast<std::size_t>(bands));
            for (const auto& part : parts) {
                // A band is at least 2r rows high (or the whole sensor), its halo r rows
                // on each side, clipped to the sensor.
                EXPECT_TRUE(part.y1 - part.y0 >= 2 * radius || (part.y0 == 0 && part.y1 == s.height));
                EXPECT_EQ(part.lo, std::max(0, part.y0 - radius));
                EXPECT_EQ(part.hi, std::min(s.height, part.y1 + radius));
            }
            for (int p = 0; p < 2; ++p)
                for (int y = 0; y < s.height; ++y) {
                    int owners = 0;
                    for (const auto& part : parts) owners += part.owns(p, y);
                    ASSERT_EQ(owners, 1) << s.width << "x" << s.height << ", " << bands << " bands, polarity " << p << ", row " << y;
                }
        }
    }
}

// A detector whose decision reads both polarities within radius 2: an event is a corner
// iff, in the 5x5 window around it (clipped to the sensor), at least 2 other pixels of its
// polarity and 3 of the other polarity fired within the last 60 us. State: the latest
// time per pixel and polarity (both planes always: it cannot work on one polarity).
class CrossPolarity {
public:
    static constexpr int kRadius = 2;
    explicit CrossPolarity(SensorSize s, int /*planes*/ = 2)
        : size_(s), t_(2 * static_cast<std::size_t>(s.pixels()), std::numeric_limits<std::int64_t>::min() / 2) {}
    [[nodiscard]] EventLimits limits() const noexcept { return {size_}; }
    bool process(const Event& e) {
        check_event(e, limits());
        return process_unchecked(e);
    }
    bool process_unchecked(const Event& e) noexcept {
        const int p = e.p & 1;
        t_[at(p, e.x, e.y)] = e.t;
        int own = -1, other = 0;  // own: not counting the event's pixel
        for (int y = std::max(0, e.y - kRadius); y <= std::min(size_.height - 1, e.y + kRadius); ++y)
            for (int x = std::max(0, e.x - kRadius); x <= std::min(size_.width - 1, e.x + kRadius); ++x) {
                own += t_[at(p, x, y)] >= e.t - 60;
                other += t_[at(1 - p, x, y)] >= e.t - 60;
            }
        return own >= 2 && other >= 3;
    }

private:
    [[nodiscard]] std::size_t at(int p, int x, int y) const noexcept {
        return (static_cast<std::size_t>(p) * static_cast<std::size_t>(size_.height) + static_cast<std::size_t>(y)) *
                   static_cast<std::size_t>(size_.width) +
               static_cast<std::size_t>(x);
    }
    SensorSize size_;
    std::vector<std::int64_t> t_;
};
static_assert(Detector<CrossPolarity>);

TEST(ParallelDetect, BothPolarityPartsForADetectorReadingBoth) {
    const auto make = [](SensorSize z, int planes) { return CrossPolarity(z, planes); };
    for (const SensorSize s : {SensorSize{240, 180}, SensorSize{1280, 720}, SensorSize{13, 9}}) {
        SCOPED_TRACE(testing::Message() << s.width << "x" << s.height);
        const auto events = random_stream(s, 120000, 17);
        expect_same_as_one_thread<CrossPolarity>(events, s, Locality(CrossPolarity::kRadius, false), make, 30000,
                                                 /*need_corners=*/s.width > 13);
    }
    // Split by polarity, the parts never see the other polarity: different flags (the
    // stream does exercise the cross-polarity reads, so the test above could fail).
    const SensorSize s{240, 180};
    const auto events = random_stream(s, 120000, 17);
    CrossPolarity one(s);
    std::vector<std::uint8_t> expected(events.size()), wrong(events.size());
    ASSERT_GT(detect(one, std::span<const Event>(events), expected), 0u);
    ParallelDetector<CrossPolarity> par(s, 2, Locality(CrossPolarity::kRadius, true), make);
    EXPECT_TRUE(par.split_polarity());
    par.detect(std::span<const Event>(events), wrong);
    EXPECT_NE(wrong, expected);
}

TEST(ParallelDetect, BothPolarityBandsCoverEachRowOnce) {
    const SensorSize s{240, 180};
    const auto events = random_stream(s, 20000, 3);
    for (int bands = 1; bands <= 30; ++bands) {
        const auto parts = plan_parts(s, bands, 4, events, /*split_polarity=*/false);
        ASSERT_GE(parts.size(), 1u);
        ASSERT_LE(parts.size(), static_cast<std::size_t>(bands));
        for (const auto& part : parts) EXPECT_EQ(part.p, -1);
        for (int p = 0; p < 2; ++p)
            for (int y = 0; y < s.height; ++y) {
                int owners = 0;
                for (const auto& part : parts) owners += part.owns(p, y);
                ASSERT_EQ(owners, 1) << bands << " bands, polarity " << p << ", row " << y;
            }
    }
}

// Every local detector of the registry, built and split as its entry says (what
// evcorner detect --threads and bench --threads do), on a random stream.
TEST(ParallelDetect, EveryLocalDetectorOfTheRegistry) {
    const SensorSize s{320, 240};
    const auto events = random_stream(s, 150000, 23);
    int local = 0;
    for_each_detector_entry([&](const auto& entry) {
        using D = typename std::remove_cvref_t<decltype(entry)>::Detector;
        if (entry.split == Split::none) return;
        ++local;
        SCOPED_TRACE(std::string(entry.name));
        const auto params = entry.params_of({});
        expect_same_as_one_thread<D>(events, s, Locality(entry.radius(params), entry.split == Split::by_polarity),
                                     [&](SensorSize z, int planes) { return entry.make(z, params, planes); }, 40000);
    });
    EXPECT_GE(local, 2);
}

TEST(ParallelDetect, AnErrorAlongsideComesAfterTheBatch) {
    const SensorSize s{64, 48};
    const auto events = random_stream(s, 5000, 4);
    EFast one(s);
    std::vector<std::uint8_t> expected(events.size());
    detect(one, std::span<const Event>(events), expected);
    ParallelDetector<EFast> par(s, 2, kCircleMargin, [](SensorSize z, int planes) { return EFast(z, planes); });
    par.prepare(events);
    std::vector<std::uint8_t> got(events.size(), 7);
    EXPECT_THROW(par.run(got, [] { throw std::runtime_error("read failed"); }), std::runtime_error);
    EXPECT_EQ(got, expected);  // the batch itself was detected in full
}

}  // namespace
}  // namespace evcorner
