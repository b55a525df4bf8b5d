#include "evcorner/io/aedat2_reader.hpp"
#include "evcorner/io/line_source.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <fmt/format.h>

namespace evcorner::io {

namespace {

constexpr std::size_t kRecord = 8;
// check_layout() judges the address layout on the first kLayoutWords address words found
// among the records in the read buffer, at most kLayoutSample (1 MiB; a DAVIS file may
// start with a frame of APS samples).
constexpr std::uint64_t kLayoutWords = 4096;
constexpr std::size_t kLayoutSample = std::size_t{1} << 17;
// Fewer address words than this are too few to call them DVS128 words.
constexpr std::uint64_t kMinDvs128Evidence = 64;
constexpr std::string_view kKnownChips = "DVS128, DAVIS128, DAVIS208, DAVIS240A/B/C, DAVIS346, DAVIS640";

std::string trim(std::string s) {
    auto sp = [](unsigned char c) { return std::isspace(c) != 0; };
    s.erase(s.begin(), std::find_if_not(s.begin(), s.end(), sp));
    s.erase(std::find_if_not(s.rbegin(), s.rend(), sp).base(), s.end());
    return s;
}

bool contains_nocase(std::string_view hay, std::string_view needle) {
    return std::search(hay.begin(), hay.end(), needle.begin(), needle.end(), [](char a, char b) {
               return std::tolower(static_cast<unsigned char>(a)) ==
                      std::tolower(static_cast<unsigned char>(b));
           }) != hay.end();
}

struct Chip {
    Aedat2Reader::Layout layout;
    SensorSize size;
};

// jAER's AEChip class names, e.g. "eu.seebetter.ini.chips.davis.DAVIS240C",
// "ch.unizh.ini.jaer.chip.retina.DVS128".
std::optional<Chip> chip_from_name(std::string_view name) {
    using L = Aedat2Reader::Layout;
    if (contains_nocase(name, "DVS128") || contains_nocase(name, "Tmpdiff128"))
        return Chip{L::dvs128, {128, 128}};
    if (contains_nocase(name, "davis")) {
        if (contains_nocase(name, "346")) return Chip{L::davis, {346, 260}};
        if (contains_nocase(name, "240")) return Chip{L::davis, {240, 180}};
        if (contains_nocase(name, "640")) return Chip{L::davis, {640, 480}};
        if (contains_nocase(name, "208")) return Chip{L::davis, {208, 192}};
        if (contains_nocase(name, "128")) return Chip{L::davis, {128, 128}};
    }
    return std::nullopt;
}

}  // namespace

bool Aedat2Reader::known_chip(std::string_view name) { return chip_from_name(name).has_value(); }

Aedat2Reader::Aedat2Reader(InputFile file, ReaderOptions options)
    : BinaryReader(std::move(file), std::move(options)) {
    std::string line;
    if (!header_line('#', line) || line.rfind("#!AER-DAT2.0", 0) != 0)
        fail(0, "not an AEDAT 2.0 file (it must start with '#!AER-DAT2.0')");
    bool have_chip = false;
    while (header_line('#', line)) {
        const auto pos = line.find("AEChip:");
        if (pos != std::string::npos && !have_chip) {
            chip_ = trim(line.substr(pos + 7));
            have_chip = true;
        }
    }
    // The format has no end-of-header mark: a header with no record after it is a file
    // cut short at the end of a header line.
    if (fill(1) == 0) fail(offset(), "the file ends right after its header, with no event records: it is cut short");

    const ReaderOptions& o = this->options();
    const std::string& forced = o.aedat2_chip;
    const auto chip = chip_from_name(forced.empty() ? chip_ : forced);
    if (!forced.empty() && !chip)
        throw std::invalid_argument(fmt::format("unknown camera chip '{}' (known: {})", forced, kKnownChips));
    if (chip) {
        layout_ = chip->layout;
        // A DVS128 address has 7-bit x and y: a larger --size means the DAVIS layout.
        if (forced.empty() && layout_ == Layout::dvs128 && o.sensor &&
            (o.sensor->width > 128 || o.sensor->height > 128))
            layout_ = Layout::davis;
        set_file_sensor(chip->size);
    } else if (o.sensor) {
        // An unknown chip with an explicit size: the DAVIS layout, jAER's current one.
        layout_ = Layout::davis;
        set_address_limit(1024);
        set_file_sensor(std::nullopt);
    } else {
        fail(offset(), chip_.empty()
                           ? fmt::format("the header has no '# AEChip:' line, so the address layout and sensor "
                                         "size are unknown; pass {} NAME ({}) or {} WxH to read DAVIS "
                                         "addresses",
                                         option_spelling(this->options(), "--chip"), kKnownChips,
                                         option_spelling(this->options(), "--size"))
                           : fmt::format("unknown AEChip '{}': the address layout and sensor size are unknown; "
                                         "pass {} NAME ({}) or {} WxH to read DAVIS addresses",
                                         chip_, option_spelling(this->options(), "--chip"), kKnownChips,
                                         option_spelling(this->options(), "--size")));
    }
    if (forced.empty()) check_layout();
}

// A wrong "# AEChip" line decodes the address words with the wrong layout: DAVIS words
// read as DVS128 ones are nearly all off its 128x128 array (skipped as not DVS128
// addresses), DAVIS words of a larger sensor fall off a smaller one, and DVS128 words
// read as DAVIS ones all land on row 0, x < 16. Judged before any event is returned, so
// nothing is half read.
void Aedat2Reader::check_layout() {
    // What the read buffer holds (most of 1 MiB for a file), at least 64 KiB if the file
    // has them: filling the buffer to the brim would move its contents for nothing.
    const std::size_t min_bytes = 2 * kLayoutWords * kRecord;
    const std::size_t avail = available() >= min_bytes ? available() : fill(min_bytes);
    const std::size_t records = std::min(avail / kRecord, kLayoutSample);
    const SensorSize s = sensor().value_or(SensorSize{1024, 512});
    const auto w = static_cast<std::uint32_t>(s.width);
    const auto h = static_cast<std::uint32_t>(s.height);
    std::uint64_t words = 0, off = 0, low16 = 0;
    const unsigned char* p = data();
    for (std::size_t i = 0; i < records && words < kLayoutWords; ++i, p += kRecord) {
        const std::uint32_t a = load_be32(p);
        if (layout_ == Layout::dvs128) {
            ++words;
            off += (a >> 16) != 0;
        } else if ((a & 0x8000'0000u) == 0) {  // not APS or IMU: a DVS or special event
            ++words;
            low16 += (a >> 16) == 0;
            if ((a & 0x400u) == 0) off += ((a >> 12) & 0x3FF) >= w || ((a >> 22) & 0x1FF) >= h;
        }
    }
    const std::string chip = chip_.empty() ? std::string("none") : quote_bytes(chip_);
    if (off * 2 > words)
        fail(offset(), fmt::format("{} of the first {} address words decode outside the {}x{} sensor of the "
                                   "header's AEChip {}: that line does not name the camera that recorded the "
                                   "file; pass {} NAME ({}) or {} WxH",
                                   off, words, s.width, s.height, chip, option_spelling(this->options(), "--chip"),
                                   kKnownChips, option_spelling(this->options(), "--size")));
    if (layout_ == Layout::davis && words >= kMinDvs128Evidence && low16 * 2 > words)
        fail(offset(), fmt::format("{} of the first {} address words have only their low 16 bits set, as DVS128 "
                                   "addresses do, not DAVIS ones: the header's AEChip {} does not name the "
                                   "camera that recorded the file; pass {} NAME (e.g. DVS128)",
                                   low16, words, chip, option_spelling(this->options(), "--chip")));
}

bool Aedat2Reader::decode() {
    const std::size_t available = whole_records(kRecord, "an event record");
    if (available == 0) return false;
    const std::size_t records = std::min(available, batch_room());
    const unsigned char* p = data();
    const std::uint64_t base = offset();
    for (std::size_t i = 0; i < records; ++i, p += kRecord) {
        const std::uint32_t a = load_be32(p);
        const std::uint32_t raw = load_be32(p + 4);
        const std::int64_t t = unwrap_(raw);
        if (layout_ == Layout::davis) {
            if ((a & 0x8000'0400u) != 0) {
                ++other_words_;
                continue;
            }
            push(t, (a >> 12) & 0x3FF, (a >> 22) & 0x1FF, (a >> 11) & 1, base + i * kRecord);
        } else {
            if ((a & 0x8000u) != 0 || (a >> 16) != 0) {
                ++other_words_;
                continue;
            }
            push(t, (a >> 1) & 0x7F, (a >> 8) & 0x7F, (a & 1) == 0, base + i * kRecord);
        }
    }
    consume(records * kRecord);
    return true;
}

}  // namespace evcorner::io
