#include "evcorner/io/aedat2_reader.hpp"

#include <algorithm>
#include <cctype>
#include <fmt/format.h>

namespace evcorner::io {

namespace {

constexpr std::size_t kRecord = 8;

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

Aedat2Reader::Aedat2Reader(std::string path, ReaderOptions options)
    : BinaryReader(std::move(path), options) {
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
    const auto chip = chip_from_name(chip_);
    if (chip) {
        layout_ = chip->layout;
        set_file_sensor(chip->size);
    } else if (options.sensor) {
        // An unknown chip with an explicit size: the DAVIS layout, jAER's current one.
        layout_ = Layout::davis;
        set_address_limit(1024);
        set_file_sensor(std::nullopt);
    } else {
        fail(offset(), chip_.empty()
                           ? std::string("the header has no '# AEChip:' line, so the address "
                                         "layout and sensor size are unknown; pass --size WxH "
                                         "to read DAVIS addresses")
                           : fmt::format("unknown AEChip '{}': the address layout and sensor size "
                                         "are unknown; pass --size WxH to read DAVIS addresses",
                                         chip_));
    }
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
