#pragma once
// Writer for the Event-Camera-Dataset text format: "t x y p" per line, t in seconds
// with 9 decimals (as the dataset writes it), so that TextReader reads back the very
// same events. Lines are written whole.

#include <span>
#include <string>

#include "evcorner/event.hpp"
#include "evcorner/io/output_file.hpp"

namespace evcorner::io {

class TextWriter {
public:
    /// Creates `path` ("-" = standard output). Throws OutputError.
    explicit TextWriter(std::string path) : out_(std::move(path)) {}

    void write(const Event& e);
    /// Writes "t x y p score": the event's line with a score appended (the shortest form
    /// that reads back to the same double; "nan" when there is none).
    void write(const Event& e, double score);
    void write(std::span<const Event> events) {
        for (const Event& e : events) write(e);
    }
    void close() { out_.close(); }
    [[nodiscard]] const std::string& name() const noexcept { return out_.name(); }

private:
    OutputFile out_;
};

/// Formats one event as a text line (with its '\n') into `dst`, which must hold
/// at least kMaxTextLine bytes; returns the number of bytes written.
inline constexpr std::size_t kMaxTextLine = 64;
std::size_t format_text_line(const Event& e, char* dst) noexcept;
/// The same line with " score" before the '\n'; `dst` must hold kMaxScoredTextLine bytes.
inline constexpr std::size_t kMaxScoredTextLine = kMaxTextLine + 32;
std::size_t format_text_line(const Event& e, double score, char* dst) noexcept;

}  // namespace evcorner::io
