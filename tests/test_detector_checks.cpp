// The library's boundary: every public per-event and batch entry point of every detector
// rejects an event it cannot take (off the sensor, polarity other than 0/1, a time eFAST's
// SAE cannot hold) with InvalidEvent before touching its state; the *_unchecked forms
// give the same answers on valid events. And the memory side: each detector says how
// much its state needs, make_detector refuses what does not fit before allocating, and
// a large sensor with few events commits next to no memory.

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "cli_test_util.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/harris.hpp"
#include "evcorner/harris_global.hpp"
#include "evcorner/parallel_detect.hpp"
#include "evcorner/state_memory.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

std::vector<Event> random_events(SensorSize s, std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<Event> ev;
    std::int64_t t = 0;
    for (std::size_t i = 0; i < n; ++i) {
        t += static_cast<std::int64_t>(rng() % 3);
        ev.push_back({t, static_cast<std::uint16_t>(rng() % static_cast<unsigned>(s.width)),
                      static_cast<std::uint16_t>(rng() % static_cast<unsigned>(s.height)),
                      static_cast<std::uint8_t>(rng() & 1)});
    }
    return ev;
}

// The events eFAST, Harris and Harris-global on a 240x180 sensor must all refuse.
const std::vector<Event>& bad_events() {
    static const std::vector<Event> v{
        {1000, 60000, 60000, 1},  // far off (crashed under ASan)
        {1000, 300, 200, 1},      // off: wrote into the other polarity's plane
        {1000, 240, 0, 0},        // x == width
        {1000, 0, 180, 0},        // y == height
        {1000, 10, 10, 2},        // polarity 2
        {1000, 10, 10, 255},
    };
    return v;
}

// Whole state of a detector, as bytes, to show a refused event changed nothing.
std::vector<std::int64_t> state_of(const EFast& d) {
    const auto& s = d.sae();
    const auto n = static_cast<std::size_t>(s.size().pixels());
    std::vector<std::int64_t> v(s.plane(0), s.plane(0) + n);
    v.insert(v.end(), s.plane(1), s.plane(1) + n);
    return v;
}
template <class H>
std::vector<std::uint64_t> state_of(const H& d) {
    const auto& s = d.sae();
    const std::size_t n = s.index(s.size().width - 1, s.size().height - 1 + s.pad()) + 1;
    std::vector<std::uint64_t> v(s.plane(0), s.plane(0) + n);
    v.insert(v.end(), s.plane(1), s.plane(1) + n);
    v.push_back(s.last());
    return v;
}

template <class D>
void expect_refuses_everything_bad(D& d) {
    const std::vector<Event> warmup = random_events(d.size(), 2000, 5);
    std::vector<std::uint8_t> flags(warmup.size() + 1);
    detect(d, std::span<const Event>(warmup), std::span<std::uint8_t>(flags).first(warmup.size()));
    const auto before = state_of(d);
    for (const Event& bad : bad_events()) {
        SCOPED_TRACE(::testing::Message() << bad.x << "," << bad.y << " p " << int(bad.p));
        // One event.
        try {
            d.process(bad);
            ADD_FAILURE() << "process() took an event it cannot hold";
        } catch (const InvalidEvent& e) {
            EXPECT_EQ(e.event(), bad);
            EXPECT_EQ(e.index(), InvalidEvent::kNoIndex);
            EXPECT_EQ(e.sensor(), d.size());
            EXPECT_NE(std::string(e.what()).find("x=" + std::to_string(bad.x) + " y=" + std::to_string(bad.y)),
                      std::string::npos)
                << e.what();
            EXPECT_NE(std::string(e.what()).find("240x180 sensor"), std::string::npos) << e.what();
        }
        // A batch with it at position 7: nothing of the batch is processed.
        std::vector<Event> batch(warmup.begin(), warmup.begin() + 12);
        batch[7] = bad;
        std::fill(flags.begin(), flags.end(), std::uint8_t{9});
        try {
            detect(d, std::span<const Event>(batch), flags);
            ADD_FAILURE() << "detect() took a batch with an event it cannot hold";
        } catch (const InvalidEvent& e) {
            EXPECT_EQ(e.index(), 7u);
            EXPECT_EQ(e.event(), bad);
            EXPECT_EQ(std::string(e.what()).rfind("event 7 (", 0), 0u) << e.what();
        }
        EXPECT_EQ(flags[0], 9) << "a flag was written";
        EXPECT_TRUE(state_of(d) == before) << "the refused input changed the state";
    }
}

TEST(DetectorChecks, EFastRefusesEventsOffTheSensorAndLeavesItsStateAlone) {
    EFast d(kDavis240);
    expect_refuses_everything_bad(d);
}
TEST(DetectorChecks, HarrisRefusesEventsOffTheSensorAndLeavesItsStateAlone) {
    Harris d(kDavis240);
    expect_refuses_everything_bad(d);
    // The scored batch too.
    std::vector<Event> batch{{1, 5, 5, 0}, {2, 250, 5, 0}};
    std::vector<std::uint8_t> flags(2);
    std::vector<double> scores(2);
    EXPECT_THROW(detect(d, std::span<const Event>(batch), flags, scores), InvalidEvent);
}
TEST(DetectorChecks, HarrisGlobalRefusesEventsOffTheSensorAndLeavesItsStateAlone) {
    HarrisGlobal d(kDavis240);
    expect_refuses_everything_bad(d);
}

TEST(DetectorChecks, EFastRefusesTimesItsSurfaceCannotHold) {
    EFast d(kDavis240);
    EXPECT_THROW(d.process({INT64_MIN, 10, 10, 1}), InvalidEvent);
    EXPECT_THROW(d.process({Sae::kMaxTime + 1, 10, 10, 1}), InvalidEvent);
    EXPECT_NO_THROW(d.process({Sae::kMinTime, 10, 10, 1}));
    EXPECT_EQ(d.sae().at(1, 10, 10), Sae::kMinTime);
    EXPECT_NO_THROW(d.process({Sae::kMaxTime, 11, 10, 1}));
    EXPECT_EQ(d.sae().at(1, 11, 10), Sae::kMaxTime);
    EXPECT_EQ(d.sae().at(0, 11, 10), Sae::kNever);
    // Harris orders by arrival: any time will do.
    Harris h(kDavis240);
    EXPECT_NO_THROW(h.process({INT64_MIN, 10, 10, 1}));
}

TEST(DetectorChecks, ShortFlagsAreRefused) {
    EFast d(kDavis240);
    const std::vector<Event> ev = random_events(kDavis240, 10, 1);
    std::vector<std::uint8_t> flags(9);
    EXPECT_THROW(detect(d, std::span<const Event>(ev), flags), std::invalid_argument);
    Harris h(kDavis240);
    EXPECT_THROW(detect(h, std::span<const Event>(ev), flags), std::invalid_argument);
}

TEST(DetectorChecks, EveryEFastCodePathChecks) {
    for (const std::string& path : efast_code_paths()) {
        EFast d(kDavis240);
        const std::vector<Event> ev{{1, 5, 5, 0}, {2, 60000, 60000, 1}};
        std::vector<std::uint8_t> flags(2);
        EXPECT_THROW(detect_on_path(path, d, std::span<const Event>(ev), flags), InvalidEvent) << path;
        EXPECT_EQ(d.sae().at(0, 5, 5), Sae::kNever) << path;
    }
}

// Every pass of first_invalid_event() this CPU runs finds the same first refused event as
// a plain scan: batches of every length up to a few blocks (so every tail length of the
// vector passes), one or two refused events of each kind (x, y, p, t below, t above) at
// random places or none, padding bytes of every value, time limits set or open.
TEST(DetectorChecks, EveryCheckPassFindsTheFirstRefusedEvent) {
    const std::vector<std::string> paths = event_check_paths();
    ASSERT_FALSE(paths.empty());
    EXPECT_EQ(paths.back(), "portable");
    std::mt19937_64 rng(11);
    const SensorSize s{240, 180};
    const EventLimits bounded{s, -1000, 1000000};
    const EventLimits open{s};
    std::size_t refused = 0, cases = 0;
    for (int round = 0; round < 600; ++round) {
        const std::size_t n = round < 40 ? static_cast<std::size_t>(round) : rng() % 2600;
        std::vector<Event> ev(n);
        for (Event& e : ev) {
            // Random padding: fill the bytes first, then the fields.
            std::uint64_t raw[2] = {rng(), rng()};
            std::memcpy(&e, raw, sizeof e);
            e.t = static_cast<std::int64_t>(rng() % 1000000);
            e.x = static_cast<std::uint16_t>(rng() % 240);
            e.y = static_cast<std::uint16_t>(rng() % 180);
            e.p = static_cast<std::uint8_t>(rng() & 1);
        }
        const int bad = n == 0 ? 0 : static_cast<int>(rng() % 3);  // refused events planted
        for (int b = 0; b < bad; ++b) {
            Event& e = ev[rng() % n];
            switch (rng() % 6) {
                case 0: e.x = static_cast<std::uint16_t>(240 + rng() % 65296); break;
                case 1: e.y = static_cast<std::uint16_t>(180 + rng() % 65356); break;
                case 2: e.p = static_cast<std::uint8_t>(2 + rng() % 254); break;
                case 3: e.t = -1001 - static_cast<std::int64_t>(rng() % 5); break;
                case 4: e.t = 1000001 + static_cast<std::int64_t>(rng() % 5); break;
                default: e.t = static_cast<std::int64_t>(rng()); break;  // any 64-bit time
            }
        }
        for (const EventLimits* l : {&bounded, &open}) {
            std::size_t want = n;
            for (std::size_t i = 0; i < n; ++i)
                if (!l->accepts(ev[i])) {
                    want = i;
                    break;
                }
            refused += want != n;
            ++cases;
            // The time span found in the same pass, where every event is accepted.
            TimeSpan plain;
            for (const Event& e : ev) plain = plain.with({e.t, e.t});
            for (const std::string& path : paths) {
                TimeSpan span{1, 0};
                ASSERT_EQ(first_invalid_event_on_path(path, ev, *l, span), want)
                    << path << ", " << n << " events, round " << round;
                if (want == n) {
                    ASSERT_EQ(span, plain) << path << ", " << n << " events, round " << round;
                }
            }
            EXPECT_EQ(first_invalid_event(ev, *l), want);
            TimeSpan span;
            EXPECT_EQ(first_invalid_event(ev, *l, span), want);
            if (want == n) {
                EXPECT_EQ(span, plain);
            }
        }
    }
    EXPECT_GT(refused, cases / 4);  // both outcomes are exercised
    EXPECT_LT(refused, cases);
    TimeSpan span;
    EXPECT_THROW((void)first_invalid_event_on_path("no-such-path", {}, open, span), std::invalid_argument);
}

// The unchecked forms answer as the checked ones on valid events.
template <class D>
void expect_unchecked_same(D a, D b, D c) {
    const std::vector<Event> ev = random_events(a.size(), 50000, 3);
    std::vector<std::uint8_t> fa(ev.size()), fb(ev.size()), fc(ev.size());
    const std::size_t ca = detect(a, std::span<const Event>(ev), fa);
    const std::size_t cb = detect_unchecked(b, std::span<const Event>(ev), fb);
    std::size_t cc = 0;
    for (std::size_t i = 0; i < ev.size(); ++i) {
        fc[i] = c.process_unchecked(ev[i]);
        cc += fc[i];
    }
    EXPECT_GT(ca, 0u);
    EXPECT_EQ(ca, cb);
    EXPECT_EQ(ca, cc);
    EXPECT_EQ(fa, fb);
    EXPECT_EQ(fa, fc);
}
TEST(DetectorChecks, UncheckedFormsGiveTheSameFlags) {
    const SensorSize s{64, 48};
    expect_unchecked_same(EFast(s), EFast(s), EFast(s));
    expect_unchecked_same(Harris(s), Harris(s), Harris(s));
    expect_unchecked_same(HarrisGlobal(s, {.n = 200}), HarrisGlobal(s, {.n = 200}), HarrisGlobal(s, {.n = 200}));
}

TEST(DetectorChecks, AnyDetectorChecks) {
    for (const auto& info : detector_infos()) {
        AnyDetector d = make_detector(info.name, kDavis240);
        const std::vector<Event> ev{{1, 5, 5, 0}, {2, 300, 200, 1}};
        std::vector<std::uint8_t> flags(2);
        EXPECT_THROW(detect(d, std::span<const Event>(ev), flags), InvalidEvent) << info.name;
        const std::vector<Event> good{{1, 5, 5, 0}, {2, 239, 179, 1}};
        EXPECT_EQ(detect(d, std::span<const Event>(good), flags), detect_unchecked(d, std::span<const Event>(good), flags));
    }
}

TEST(DetectorChecks, ParallelDetectorChecksBeforeDetecting) {
    const SensorSize s{120, 90};
    const std::vector<Event> ev = random_events(s, 200000, 9);
    for (int threads : {1, 2}) {
        SCOPED_TRACE(threads);
        auto make = [](SensorSize z, int planes) { return EFast(z, planes); };
        ParallelDetector<EFast> par(s, threads, kCircleMargin, make);
        ParallelDetector<EFast> fresh(s, threads, kCircleMargin, make);
        std::vector<Event> bad = ev;
        bad[150000] = {bad[150000].t, 120, 3, 0};  // in the third batch: the first two must not run
        std::vector<std::uint8_t> flags(ev.size()), expected(ev.size());
        try {
            par.detect(std::span<const Event>(bad), flags);
            ADD_FAILURE() << "ParallelDetector::detect took an event off the sensor";
        } catch (const InvalidEvent& e) {
            EXPECT_EQ(e.index(), 150000u);
            EXPECT_EQ(e.sensor(), s);
        }
        // Unchanged: from here on it answers as a fresh one.
        EXPECT_EQ(par.detect(std::span<const Event>(ev), flags), fresh.detect(std::span<const Event>(ev), expected));
        EXPECT_EQ(flags, expected);
        if (threads > 1) {
            const std::vector<Event> one{{1, 5, 90, 1}};
            EXPECT_THROW(par.prepare(std::span<const Event>(one)), InvalidEvent);
            EXPECT_THROW(par.run(std::span<std::uint8_t>(flags).first(1)), std::logic_error);  // nothing queued
        }
    }
}

TEST(DetectorChecks, SensorSidesOutOfRangeAreRefused) {
    for (const SensorSize s : {SensorSize{0, 10}, SensorSize{10, -1}, SensorSize{65537, 1}}) {
        EXPECT_THROW(EFast{s}, std::invalid_argument);
        EXPECT_THROW(Harris{s}, std::invalid_argument);
        EXPECT_THROW(HarrisGlobal{s}, std::invalid_argument);
        EXPECT_THROW(make_detector("efast", s), std::invalid_argument);
    }
    // parse_sensor_size (the CLI's --size) accepts exactly what the detectors accept.
    for (const char* text : {"1x1", "65536x65536", "240x180"}) {
        const auto s = parse_sensor_size(text);
        ASSERT_TRUE(s) << text;
        EXPECT_NO_THROW(checked_sensor_size(*s, "test")) << text;
    }
    for (const char* text : {"0x5", "65537x1", "-1x5"}) EXPECT_FALSE(parse_sensor_size(text)) << text;
}

// ---------------------------------------------------------------- memory

TEST(StateMemory, EachDetectorSaysWhatItsStateNeeds) {
    const SensorSize big{65536, 65536};
    EXPECT_EQ(EFast::state_bytes(big), 68719476736u);  // 16 B per pixel
    EXPECT_EQ(EFast::state_bytes(big, 1), 34359738368u);
    EXPECT_EQ(Harris::state_bytes(big), std::uint64_t{2} * 65544 * 65544 * 8);  // framed by window/2 = 4
    EXPECT_GT(HarrisGlobal::state_bytes(big), Harris::state_bytes(big));
    // They say what the detectors hold.
    const SensorSize s{320, 240};
    EXPECT_EQ(EFast::state_bytes(s), EFast(s).memory_bytes());
    EXPECT_EQ(EFast::state_bytes(s, 1), EFast(s, 1).memory_bytes());
    EXPECT_EQ(Harris::state_bytes(s, {.window = 11}), Harris(s, {.window = 11}).memory_bytes());
    EXPECT_EQ(HarrisGlobal::state_bytes(s, {.n = 77}), HarrisGlobal(s, {.n = 77}).memory_bytes());
    for (const auto& info : detector_infos())
        EXPECT_EQ(detector_state_bytes(info.name, s), memory_bytes(make_detector(info.name, s))) << info.name;
    EXPECT_THROW(detector_state_bytes("fast", s), std::invalid_argument);
}

TEST(StateMemory, TheRefusalSaysWhatIsNeededAndWhatIsAvailable) {
    const SensorSize big{65536, 65536};
    try {
        require_state_fits("efast", big, EFast::state_bytes(big), 21'300'000'000u);
        ADD_FAILURE() << "68.7 GB fitted into 21.3 GB";
    } catch (const StateTooLarge& e) {
        EXPECT_STREQ(e.what(),
                     "a 65536x65536 sensor needs 68.7 GB for efast's state (16 B per pixel); 21.3 GB is available");
    }
    EXPECT_NO_THROW(require_state_fits("efast", big, EFast::state_bytes(big), 70'000'000'000u));
    EXPECT_NO_THROW(require_state_fits("efast", big, EFast::state_bytes(big), 0));  // unknown: not refused
    EXPECT_EQ(format_bytes(0), "0 B");
    EXPECT_EQ(format_bytes(999), "999 B");
    EXPECT_EQ(format_bytes(1000), "1.00 kB");
    EXPECT_EQ(format_bytes(14'400'000'000u), "14.4 GB");
    EXPECT_EQ(format_bytes(345'600), "346 kB");
}

TEST(StateMemory, MakeDetectorRefusesBeforeAllocating) {
    const std::uint64_t avail = available_memory_bytes();
    ASSERT_GT(avail, 0u) << "neither /proc/meminfo nor sysconf gave the available memory";
    const SensorSize big{65536, 65536};
    if (avail >= HarrisGlobal::state_bytes(big)) GTEST_SKIP() << "this machine has room for a 65536x65536 state";
    for (const auto& info : detector_infos()) {
        try {
            (void)make_detector(info.name, big);
            ADD_FAILURE() << info.name << " was built";
        } catch (const StateTooLarge& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.rfind("a 65536x65536 sensor needs ", 0), 0u) << m;
            EXPECT_NE(m.find(" for " + std::string(info.name) + "'s state ("), std::string::npos) << m;
            EXPECT_NE(m.find(" is available"), std::string::npos) << m;
        }
    }
}

// Resident memory of this process now, bytes.
std::uint64_t resident_bytes() {
    std::ifstream in("/proc/self/statm");
    std::uint64_t size = 0, resident = 0;
    in >> size >> resident;
    return resident * static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE));
}

TEST(StateMemory, ALargeSensorWithFewEventsCommitsLittleMemory) {
    if (resident_bytes() == 0) GTEST_SKIP() << "no /proc/self/statm";
    const SensorSize s{8000, 8000};  // 1 GB of eFAST state, 1 GB of Harris state
    const std::uint64_t before = resident_bytes();
    EFast e(s);
    Harris h(s);
    for (std::uint16_t k = 0; k < 100; ++k) {
        const Event ev{k, static_cast<std::uint16_t>(k * 79 % 8000), static_cast<std::uint16_t>(k * 31 % 8000),
                       static_cast<std::uint8_t>(k & 1)};
        e.process(ev);
        h.process(ev);
    }
    EXPECT_EQ(e.memory_bytes(), 1'024'000'000u);
    EXPECT_LT(resident_bytes() - before, 64u << 20) << "the state planes were written in full";
    EXPECT_EQ(e.sae().at(1, 79, 31), 1);
    EXPECT_EQ(e.sae().at(0, 79, 31), Sae::kNever);
}

// The command line refuses a size whose state cannot fit, with the figures, exit 1.
class DetectorChecksCli : public test::CliTest {};
TEST_F(DetectorChecksCli, HugeSensorIsRefusedWithTheMemoryItNeeds) {
    if (available_memory_bytes() >= EFast::state_bytes({65536, 65536})) GTEST_SKIP() << "room for 68.7 GB here";
    write("one.txt", "0.001 100 100 1\n");
    const auto r = run("detect one.txt --size 65536x65536 -o c.txt");
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("a 65536x65536 sensor needs 68.7 GB for efast's state (16 B per pixel); "), std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("bad_alloc"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace evcorner
