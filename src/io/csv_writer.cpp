#include "evcorner/io/csv_writer.hpp"

#include <fmt/format.h>

namespace evcorner::io {

CsvWriter::CsvWriter(std::string path) : out_(std::move(path)) { out_.write("t,x,y,p\n"); }

void CsvWriter::write(std::span<const Event> events) {
    constexpr std::size_t kMaxLine = 48;  // 20 + 1 + 5 + 1 + 5 + 1 + 1 + 1
    for (const Event& e : events) {
        char* dst = out_.reserve(kMaxLine);
        const auto r = fmt::format_to_n(dst, kMaxLine, "{},{},{},{}\n", e.t, e.x, e.y, e.p != 0 ? 1 : 0);
        out_.commit(r.size);
    }
}

}  // namespace evcorner::io
