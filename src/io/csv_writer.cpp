#include "evcorner/io/csv_writer.hpp"

#include <charconv>
#include <stdexcept>

#include <fmt/format.h>

namespace evcorner::io {

CsvWriter::CsvWriter(std::string path, bool with_score) : out_(std::move(path)), with_score_(with_score) {
    out_.write(with_score ? "t,x,y,p,score\n" : "t,x,y,p\n");
}

namespace {
constexpr std::size_t kMaxLine = 48;  // 20 + 1 + 5 + 1 + 5 + 1 + 1 + 1
constexpr std::size_t kMaxScore = 32;  // ",-2.2250738585072014e-308"
}  // namespace

void CsvWriter::write(std::span<const Event> events) {
    if (with_score_) throw std::logic_error("CsvWriter: opened with scores, written without");
    for (const Event& e : events) {
        char* dst = out_.reserve(kMaxLine);
        const auto r = fmt::format_to_n(dst, kMaxLine, "{},{},{},{}\n", e.t, e.x, e.y, e.p != 0 ? 1 : 0);
        out_.commit(r.size);
    }
}

void CsvWriter::write(std::span<const Event> events, std::span<const double> scores) {
    if (!with_score_ || scores.size() != events.size())
        throw std::logic_error("CsvWriter: scores on a writer opened without, or not one per event");
    for (std::size_t i = 0; i < events.size(); ++i) {
        const Event& e = events[i];
        char* dst = out_.reserve(kMaxLine + kMaxScore);
        std::size_t n = fmt::format_to_n(dst, kMaxLine, "{},{},{},{},", e.t, e.x, e.y, e.p != 0 ? 1 : 0).size;
        n = static_cast<std::size_t>(std::to_chars(dst + n, dst + kMaxLine + kMaxScore - 1, scores[i]).ptr - dst);
        dst[n++] = '\n';
        out_.commit(n);
    }
}

}  // namespace evcorner::io
