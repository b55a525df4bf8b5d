// AEDAT 2.0 reader: the real jAER recordings (figures from their READMEs), the eFAST
// goldens of the DAVIS240C recordings, and crafted damaged files.

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <map>
#include <stdexcept>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/io/aedat2_reader.hpp"
#include "evcorner/io/open.hpp"
#include "io_test_util.hpp"
#include "test_util.hpp"

namespace evcorner::test {
namespace {

using io::Aedat2Reader;

// data/real/davis240c-imu-pyaedattools/README.md and dvs128-walking-ouyang/README.md.
const std::map<std::string, Figures> kDavis240Files = {
    {"IMU_translBoxes", {162771, 294976755, 297049406, 0, 239, 0, 179, 82944, 79827}},
    {"IMU_rotDisk", {374296, 341678, 3508437, 0, 239, 0, 179, 163098, 211198}},
};
const std::map<std::string, Figures> kDvs128Files = {
    {"alex_walking_again", {19182, 41306606, 48193156, 0, 127, 0, 127, 7102, 12080}},
    {"alex_walking_for_10secs", {125028, 262847757, 270891631, 0, 127, 0, 127, 55976, 69052}},
    {"cam255_alex_standing_up", {290292, 136635479, 161721146, 0, 127, 0, 127, 159004, 131288}},
    {"cam255_alex_standing_up2", {295301, 184148526, 214199365, 0, 127, 0, 127, 163224, 132077}},
    {"cam255_neal_standing_up", {209564, 314384738, 335182415, 0, 127, 0, 127, 114089, 95475}},
    {"cam255_neal_standing_up2", {264804, 48865216, 76354295, 0, 127, 0, 127, 144477, 120327}},
    {"cam255_right_clamp_test1", {110228, 52965624, 70984609, 0, 127, 0, 127, 59036, 51192}},
    {"cam289_right_clamp_test1", {336913, 14240887, 27854271, 0, 127, 0, 127, 175908, 161005}},
    {"cam298_left_clamp_test1_alex", {323902, 875179084, 887299883, 0, 127, 0, 127, 163634, 160268}},
    {"cam300_fix_lense_alex_standing_up", {155766, 63137881, 76178163, 0, 127, 0, 127, 81567, 74199}},
    {"neal_walking", {70304, 135707767, 144951371, 0, 127, 0, 127, 34031, 36273}},
};

std::string davis_path(const std::string& name) {
    return (shared_data() / "real/davis240c-imu-pyaedattools" / (name + ".aedat")).string();
}

TEST(Aedat2Real, Davis240cFiguresMatchReadme) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const auto& [name, fig] : kDavis240Files) {
        auto reader = io::open_event_reader(davis_path(name));
        EXPECT_EQ(reader->format(), "aedat2");
        ASSERT_TRUE(reader->sensor());
        EXPECT_EQ(*reader->sensor(), (SensorSize{240, 180}));
        const ReadResult r = read_all(*reader);
        ASSERT_FALSE(r.failed) << r.error;
        expect_figures(r.events, fig, name);
    }
}

TEST(Aedat2Real, SkipsApsAndImuWordsAsCountedInReadme) {
    EVCORNER_REQUIRE_SHARED_DATA();
    // README: IMU_rotDisk 51 688 bit-31 words of 425 984; IMU_translBoxes 33 837 of 196 608.
    const std::map<std::string, std::pair<std::uint64_t, std::uint64_t>> words = {
        {"IMU_rotDisk", {51688, 425984}}, {"IMU_translBoxes", {33837, 196608}}};
    for (const auto& [name, w] : words) {
        Aedat2Reader reader(davis_path(name));
        const ReadResult r = read_all(reader);
        ASSERT_FALSE(r.failed) << r.error;
        EXPECT_EQ(r.events.size() + reader.other_words(), w.second) << name;
        EXPECT_GE(reader.other_words(), w.first) << name;  // plus any bit-10 special events
    }
}

TEST(Aedat2Real, Dvs128FiguresMatchReadme) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const auto& [name, fig] : kDvs128Files) {
        const auto path = (shared_data() / "real/dvs128-walking-ouyang" / (name + ".aedat")).string();
        Aedat2Reader reader(path);
        EXPECT_EQ(reader.layout(), Aedat2Reader::Layout::dvs128);
        ASSERT_TRUE(reader.sensor());
        EXPECT_EQ(*reader.sensor(), (SensorSize{128, 128}));
        const ReadResult r = read_all(reader, 1000);  // a batch size that splits records
        ASSERT_FALSE(r.failed) << r.error;
        expect_figures(r.events, fig, name);
    }
}

std::vector<std::uint64_t> efast_corner_positions(const std::vector<Event>& events) {
    EFast det(SensorSize{240, 180});
    std::vector<std::uint8_t> flags(events.size());
    detect(det, std::span<const Event>(events), flags);
    std::vector<std::uint64_t> pos;
    for (std::size_t i = 0; i < flags.size(); ++i)
        if (flags[i]) pos.push_back(i);
    return pos;
}

// data/README.md: the goldens index the DVS events in file order with the stored layout.
TEST(Aedat2Real, Davis240cEfastMatchesGolden) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const auto& [name, fig] : kDavis240Files) {
        SCOPED_TRACE(name);
        Aedat2Reader reader(davis_path(name));
        const ReadResult r = read_all(reader);
        ASSERT_FALSE(r.failed) << r.error;
        const auto golden = read_index_file(shared_data() / "golden" /
                                            ("davis240c-imu-pyaedattools." + name + ".efast.idx"));
        ASSERT_FALSE(golden.empty());
        EXPECT_EQ(efast_corner_positions(r.events), golden);

        // Flipping y to a top-left origin (or x, as jAER displays) mirrors the scene; the
        // eFAST circles are symmetric, so the corner set must not change.
        std::vector<Event> flipped = r.events;
        for (Event& e : flipped) e.y = static_cast<std::uint16_t>(179 - e.y);
        EXPECT_EQ(efast_corner_positions(flipped), golden);
        for (Event& e : flipped) e.x = static_cast<std::uint16_t>(239 - e.x);
        EXPECT_EQ(efast_corner_positions(flipped), golden);
    }
}

// ---- crafted files

const std::string kDavisHeader =
    "#!AER-DAT2.0\r\n# crafted by the evcorner tests\r\n# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n";
const std::string kDvs128Header = "#!AER-DAT2.0\r\n# AEChip: ch.unizh.ini.jaer.chip.retina.DVS128\r\n";

std::uint32_t davis(int x, int y, bool on) {
    return std::uint32_t(y) << 22 | std::uint32_t(x) << 12 | std::uint32_t(on) << 11;
}
void record(std::string& s, std::uint32_t a, std::uint32_t t) {
    put_be32(s, a);
    put_be32(s, t);
}

TEST(Aedat2Crafted, DavisLayoutAndSkippedWords) {
    TempDir tmp;
    std::string f = kDavisHeader;
    record(f, davis(3, 4, true), 100);
    record(f, 0x8000'0000u | davis(5, 6, true), 101);  // APS sample
    record(f, davis(7, 8, false) | 0x400, 102);        // external event
    record(f, davis(239, 179, false), 103);
    const auto path = tmp.write("a.aedat", f);
    auto reader = io::open_event_reader(path);
    const ReadResult r = read_all(*reader);
    ASSERT_FALSE(r.failed) << r.error;
    const std::vector<Event> want = {{100, 3, 4, 1}, {103, 239, 179, 0}};
    EXPECT_EQ(r.events, want);
}

TEST(Aedat2Crafted, Dvs128Layout) {
    TempDir tmp;
    std::string f = kDvs128Header;
    record(f, (5u << 8) | (9u << 1) | 0u, 10);  // ON: bit 0 = 0
    record(f, (127u << 8) | (127u << 1) | 1u, 11);
    record(f, 0x8000u | (1u << 8), 12);  // external event
    const auto path = tmp.write("d.aedat", f);
    Aedat2Reader reader(path);
    const ReadResult r = read_all(reader);
    ASSERT_FALSE(r.failed) << r.error;
    const std::vector<Event> want = {{10, 9, 5, 1}, {11, 127, 127, 0}};
    EXPECT_EQ(r.events, want);
}

TEST(Aedat2Crafted, TimeWrapIsUnrolled) {
    TempDir tmp;
    std::string f = kDavisHeader;
    record(f, davis(1, 1, true), 0xFFFF'FFF0u);
    record(f, davis(2, 2, true), 0xFFFF'FFFFu);
    record(f, davis(3, 3, true), 0x0000'0005u);
    const auto path = tmp.write("w.aedat", f);
    Aedat2Reader reader(path);
    const ReadResult r = read_all(reader);
    ASSERT_FALSE(r.failed) << r.error;
    ASSERT_EQ(r.events.size(), 3u);
    EXPECT_EQ(r.events[0].t, 0xFFFF'FFF0LL);
    EXPECT_EQ(r.events[1].t, 0xFFFF'FFFFLL);
    EXPECT_EQ(r.events[2].t, (1LL << 32) + 5);
}

TEST(Aedat2Crafted, TruncatedRecordKeepsEventsBefore) {
    TempDir tmp;
    std::string f = kDavisHeader;
    record(f, davis(1, 1, true), 10);
    record(f, davis(2, 2, false), 20);
    f += std::string("\x00\x01\x02", 3);
    const auto path = tmp.write("t.aedat", f);
    Aedat2Reader reader(path);
    const ReadResult r = read_all(reader);
    EXPECT_EQ(r.events.size(), 2u);
    ASSERT_TRUE(r.failed);
    const std::uint64_t at = kDavisHeader.size() + 16;
    EXPECT_EQ(r.error_unit, InputError::Unit::byte);
    EXPECT_EQ(r.error_position, at);
    EXPECT_NE(r.error.find(path), std::string::npos) << r.error;
    EXPECT_NE(r.error.find("byte " + std::to_string(at)), std::string::npos) << r.error;
    // The error stays: the stream is not resynchronised.
    std::vector<Event> buf(8);
    EXPECT_THROW(reader.read(buf), InputError);
}

TEST(Aedat2Crafted, CorruptAddressOutsideSensor) {
    TempDir tmp;
    std::string f = kDavisHeader;
    record(f, davis(1, 1, true), 10);
    record(f, davis(1000, 1, true), 11);  // x = 1000 on a 240-wide sensor
    record(f, davis(2, 2, true), 12);
    const auto path = tmp.write("c.aedat", f);
    {
        Aedat2Reader reader(path);
        const ReadResult r = read_all(reader);
        ASSERT_TRUE(r.failed);
        EXPECT_EQ(r.events.size(), 1u);
        EXPECT_EQ(r.error_position, kDavisHeader.size() + 8);
        EXPECT_NE(r.error.find("x=1000"), std::string::npos) << r.error;
    }
    {
        io::ReaderOptions o;
        o.skip_invalid = true;
        Aedat2Reader reader(path, o);
        const ReadResult r = read_all(reader);
        ASSERT_FALSE(r.failed) << r.error;
        EXPECT_EQ(r.events.size(), 2u);
        EXPECT_EQ(r.skipped, 1u);
    }
}

TEST(Aedat2Crafted, BackwardsTimestampIsAnError) {
    TempDir tmp;
    std::string f = kDavisHeader;
    record(f, davis(1, 1, true), 1000);
    record(f, davis(1, 2, true), 900);
    const auto path = tmp.write("b.aedat", f);
    Aedat2Reader reader(path);
    const ReadResult r = read_all(reader);
    ASSERT_TRUE(r.failed);
    EXPECT_EQ(r.events.size(), 1u);
    EXPECT_EQ(r.error_position, kDavisHeader.size() + 8);
    EXPECT_NE(r.error.find("backwards"), std::string::npos) << r.error;
}

TEST(Aedat2Crafted, HeaderProblems) {
    TempDir tmp;
    EXPECT_THROW(Aedat2Reader(tmp.write("n.aedat", "#!AER-DAT3.1\r\n")), InputError);
    std::string unknown = "#!AER-DAT2.0\r\n# AEChip: some.OtherChip\r\n";
    record(unknown, 0, 0);
    const auto p = tmp.write("u.aedat", unknown);
    try {
        Aedat2Reader r(p);
        ADD_FAILURE() << "an unknown chip must need --size";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("some.OtherChip"), std::string::npos) << e.what();
    }
    io::ReaderOptions o;
    o.sensor = SensorSize{64, 64};
    Aedat2Reader r(p, o);
    EXPECT_EQ(read_all(r).events.size(), 1u);
    // Header only, no records: the format has no end-of-header mark, so this is a file
    // cut short at the end of a header line, not an empty stream.
    try {
        Aedat2Reader empty(tmp.write("e.aedat", kDavisHeader));
        ADD_FAILURE() << "a header without records must be an error";
    } catch (const InputError& e) {
        EXPECT_EQ(e.unit(), InputError::Unit::byte);
        EXPECT_EQ(e.position(), kDavisHeader.size());
        EXPECT_NE(std::string(e.what()).find("cut short"), std::string::npos) << e.what();
    }
}


// ---- a "# AEChip" line that does not name the camera

// `bytes` with its "# AEChip: ..." line replaced by "# AEChip: `chip`".
std::string with_chip_line(std::string bytes, const std::string& chip) {
    const auto at = bytes.find("# AEChip:");
    const auto end = bytes.find('\r', at);
    if (at == std::string::npos || end == std::string::npos) throw std::runtime_error("no AEChip line");
    return bytes.replace(at, end - at, "# AEChip: " + chip);
}

std::string read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The error names the problem and both ways out.
void expect_chip_error(const std::string& path, const io::ReaderOptions& o, const std::string& words) {
    try {
        auto reader = io::open_event_reader(path, o);
        const ReadResult r = read_all(*reader);
        ADD_FAILURE() << "read " << r.events.size() << " events without an error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.unit(), InputError::Unit::byte);
        EXPECT_NE(what.find("AEChip"), std::string::npos) << what;
        EXPECT_NE(what.find("--chip"), std::string::npos) << what;
        EXPECT_NE(what.find(words), std::string::npos) << what;
    }
}

TEST(Aedat2Chip, Davis240cRecordingLabelledDvs128IsAnErrorNotThreeEvents) {
    EVCORNER_REQUIRE_SHARED_DATA();
    TempDir tmp;
    const auto path = tmp.write("boxes.aedat", with_chip_line(read_bytes(davis_path("IMU_translBoxes")),
                                                              "ch.unizh.ini.jaer.chip.retina.DVS128"));
    expect_chip_error(path, {}, "--size");
    io::ReaderOptions skip;  // skipping invalid events does not hide it either
    skip.skip_invalid = true;
    expect_chip_error(path, skip, "outside the 128x128 sensor");

    // Naming the camera, or a size only a DAVIS layout can address, reads every event.
    const Figures& fig = kDavis240Files.at("IMU_translBoxes");
    io::ReaderOptions chip;
    chip.aedat2_chip = "DAVIS240C";
    io::ReaderOptions size;
    size.sensor = SensorSize{240, 180};
    for (const auto& o : {chip, size}) {
        auto reader = io::open_event_reader(path, o);
        EXPECT_EQ(*reader->sensor(), (SensorSize{240, 180}));
        const ReadResult r = read_all(*reader);
        ASSERT_FALSE(r.failed) << r.error;
        expect_figures(r.events, fig, "IMU_translBoxes relabelled DVS128");
    }
}

TEST(Aedat2Chip, Dvs128RecordingLabelledDavisIsAnError) {
    EVCORNER_REQUIRE_SHARED_DATA();
    TempDir tmp;
    const auto original = (shared_data() / "real/dvs128-walking-ouyang/neal_walking.aedat").string();
    const auto path = tmp.write("walk.aedat", with_chip_line(read_bytes(original), "eu.seebetter.ini.chips.davis.DAVIS240C"));
    expect_chip_error(path, {}, "DVS128");
    io::ReaderOptions o;
    o.aedat2_chip = "dvs128";
    auto reader = io::open_event_reader(path, o);
    const ReadResult r = read_all(*reader);
    ASSERT_FALSE(r.failed) << r.error;
    expect_figures(r.events, kDvs128Files.at("neal_walking"), "neal_walking relabelled DAVIS240C");
}

TEST(Aedat2Chip, CraftedMismatchesAndTheThreshold) {
    TempDir tmp;
    // 100 DAVIS240C events labelled DVS128: every address has bits above 15.
    std::string davis_as_dvs = kDvs128Header;
    for (int i = 0; i < 100; ++i) record(davis_as_dvs, davis(100 + i % 100, 50 + i % 100, i % 2), 10 + i);
    expect_chip_error(tmp.write("a.aedat", davis_as_dvs), {}, "100 of the first 100 address words");

    // DAVIS346 events on a DAVIS240C header, skipped as invalid: still an error.
    std::string big = kDavisHeader;
    for (int i = 0; i < 100; ++i) record(big, davis(300, 200, true), 10 + i);
    io::ReaderOptions skip;
    skip.skip_invalid = true;
    expect_chip_error(tmp.write("b.aedat", big), skip, "outside the 240x180 sensor");
    io::ReaderOptions chip346 = skip;
    chip346.aedat2_chip = "DAVIS346";
    auto r346 = io::open_event_reader(tmp.path("b.aedat"), chip346);
    EXPECT_EQ(read_all(*r346).events.size(), 100u);

    // Half the words off the sensor is not "most": those are skipped (or errors) one by one.
    std::string half = kDavisHeader;
    for (int i = 0; i < 50; ++i) {
        record(half, davis(10, 10, true), 10 + 2 * i);
        record(half, davis(300, 10, true), 11 + 2 * i);
    }
    auto rh = io::open_event_reader(tmp.write("h.aedat", half), skip);
    const ReadResult h = read_all(*rh);
    ASSERT_FALSE(h.failed) << h.error;
    EXPECT_EQ(h.events.size(), 50u);
    EXPECT_EQ(h.skipped, 50u);

    // APS and IMU words (bit 31) are not address words: a DAVIS file that starts with a
    // frame is judged on its DVS events.
    std::string aps = kDavisHeader;
    for (int i = 0; i < 1000; ++i) record(aps, 0x8000'0000u | davis(i % 240, i % 180, false), 5);
    record(aps, davis(1, 2, true), 6);
    auto ra = io::open_event_reader(tmp.write("p.aedat", aps));
    EXPECT_EQ(read_all(*ra).events.size(), 1u);

    // DVS128 words on a DAVIS header: at least 64 of them are needed to call it.
    std::string dvs_as_davis = kDavisHeader;
    for (int i = 0; i < 63; ++i) record(dvs_as_davis, (5u << 8) | (9u << 1), 10 + i);
    auto r63 = io::open_event_reader(tmp.write("d63.aedat", dvs_as_davis));
    EXPECT_FALSE(read_all(*r63).failed);
    record(dvs_as_davis, (5u << 8) | (9u << 1), 100);
    expect_chip_error(tmp.write("d64.aedat", dvs_as_davis), {}, "DVS128");
}

TEST(Aedat2Chip, ChipOptionIsChecked) {
    TempDir tmp;
    std::string f = kDavisHeader;
    record(f, davis(1, 1, true), 1);
    const auto path = tmp.write("a.aedat", f);
    io::ReaderOptions o;
    o.aedat2_chip = "DAVIS999";
    EXPECT_THROW(io::open_event_reader(path, o), std::invalid_argument);
    EXPECT_TRUE(Aedat2Reader::known_chip("DAVIS240C"));
    EXPECT_TRUE(Aedat2Reader::known_chip("ch.unizh.ini.jaer.chip.retina.DVS128"));
    EXPECT_FALSE(Aedat2Reader::known_chip("DAVIS"));
    // A chip names an AEDAT 2.0 layout: on any other format it is a usage error.
    o.aedat2_chip = "DAVIS240C";
    EXPECT_THROW(io::open_event_reader(tmp.write("e.txt", "0.1 1 1 1\n"), o), std::invalid_argument);
    // No AEChip line at all: --chip makes it readable.
    std::string none = "#!AER-DAT2.0\r\n";
    record(none, davis(3, 4, true), 1);
    EXPECT_THROW(io::open_event_reader(tmp.write("n.aedat", none)), InputError);
    auto r = io::open_event_reader(tmp.path("n.aedat"), o);
    const std::vector<Event> want = {{1, 3, 4, 1}};
    EXPECT_EQ(read_all(*r).events, want);
}

}  // namespace
}  // namespace evcorner::test
