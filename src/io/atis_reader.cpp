#include "evcorner/io/atis_reader.hpp"

#include <algorithm>
#include <cctype>

namespace evcorner::io {

namespace {
constexpr std::size_t kRecord = 5;
constexpr std::uint32_t kWrap = std::uint32_t{1} << 23;
constexpr std::uint32_t kHalf = kWrap / 2;

inline std::uint32_t raw_time(const unsigned char* r) noexcept {
    return (std::uint32_t{r[2]} & 0x7f) << 16 | std::uint32_t{r[3]} << 8 | r[4];
}
}  // namespace

AtisReader::AtisReader(InputFile file, ReaderOptions options) : BinaryReader(std::move(file), std::move(options)) {
    set_address_limit(256);
    set_file_sensor(std::nullopt);
}

bool AtisReader::decode() {
    const std::size_t whole = whole_records(kRecord, "an ATIS record");
    if (whole == 0) return false;
    const std::size_t records = std::min(whole, batch_room());
    const unsigned char* p = data();
    const std::uint64_t base = offset();
    std::size_t i = 0;
    while (i < records) {
        // Runs without a wrap: time is epoch_ + raw, checked for order by push_run.
        const std::int64_t epoch = epoch_;
        i += push_run(records - i, [&](std::size_t k, Event& e) {
            const unsigned char* r = p + (i + k) * kRecord;
            e.x = r[0];
            e.y = r[1];
            e.p = r[2] >> 7;
            e.t = epoch + raw_time(r);
        });
        if (i == records) break;
        // Record i failed a check: a wrap of the 23-bit counter, or an event push() rejects.
        const unsigned char* r = p + i * kRecord;
        const std::uint32_t raw = raw_time(r);
        const std::uint32_t prev = i > 0 ? raw_time(r - kRecord) : last_raw_;
        if (raw < prev && prev - raw > kHalf) epoch_ += kWrap;
        push(epoch_ + raw, r[0], r[1], (r[2] >> 7) != 0, base + i * kRecord);
        ++i;
    }
    if (records > 0) last_raw_ = raw_time(p + (records - 1) * kRecord);
    consume(records * kRecord);
    return true;
}

bool looks_like_atis(std::string_view name, std::string_view head, std::optional<std::uint64_t> size) {
    if (name.size() < 4) return false;
    std::string ext(name.substr(name.size() - 4));
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".bin") return false;
    if (size && *size % kRecord != 0) return false;
    const std::size_t n = std::min<std::size_t>(head.size() / kRecord, 4096);
    if (n == 0) return size && *size == 0;
    const auto* p = reinterpret_cast<const unsigned char*>(head.data());
    std::uint32_t prev = raw_time(p);
    int wraps = 0;
    for (std::size_t i = 1; i < n; ++i) {
        const std::uint32_t t = raw_time(p + i * kRecord);
        if (t < prev && (prev - t <= kHalf || ++wraps > 1)) return false;
        prev = t;
    }
    return true;
}

}  // namespace evcorner::io
