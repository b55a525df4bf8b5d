#include "evcorner/io/evt3_reader.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "evcorner/io/prophesee_header.hpp"
#include "evt3_decoder.hpp"

namespace evcorner::io {

namespace {
constexpr std::size_t kWord = 2;
}  // namespace

Evt3Reader::Evt3Reader(InputFile file, ReaderOptions options)
    : BinaryReader(std::move(file), std::move(options)), dec_(std::make_unique<DecoderBox>()) {
    PropheseeHeader h;
    std::string line;
    while (!h.ended && header_line('%', line)) h.add_line(line);
    if (!h.evt.empty() && h.evt != "3.0")
        fail(0, fmt::format("the header says EVT {}, not EVT 3.0", h.evt));
    // Without "% end" the header's end is where the data starts: no data at all is a
    // file cut short at the end of a header line.
    if (!h.ended && fill(1) == 0)
        fail(offset(), offset() == 0 ? "the file is empty"
                                     : "the file ends right after its header, with no event data: it is cut short");
    set_address_limit(2048);
    set_file_sensor(h.sensor());
}

struct Evt3Reader::DecoderBox {
    detail::Evt3Decoder d;
};

Evt3Reader::~Evt3Reader() = default;

std::uint64_t Evt3Reader::other_words() const noexcept { return dec_->d.other_words(); }

// What the word decoder needs from the reader: room in the batch, the checked push, fail.
struct Evt3Reader::Sink {
    Evt3Reader& r;
    [[nodiscard]] bool full() const noexcept { return r.batch_full(); }
    void push(std::int64_t t, std::uint32_t x, std::uint32_t y, bool on, std::uint64_t at) { r.push(t, x, y, on, at); }
    [[noreturn]] void fail(std::uint64_t at, const char* reason) const { r.fail(at, reason); }
};

bool Evt3Reader::decode() {
    Sink sink{*this};
    if (!dec_->d.drain(sink)) return true;
    const std::size_t words = whole_records(kWord, "a 16-bit word");
    if (words == 0) return false;
    consume(dec_->d.decode(data(), words, offset(), sink) * kWord);
    return true;
}

}  // namespace evcorner::io
