#pragma once
// Errors that name where they happened: the file and a position in it.

#include <cstdint>
#include <stdexcept>
#include <string>

namespace evcorner {

/// Bad or unreadable input. what() reads "FILE:LINE: reason" (text formats) or
/// "FILE: byte OFFSET: reason" (binary formats), or "FILE: reason" with no position.
class InputError : public std::runtime_error {
public:
    enum class Unit { none, line, byte };

    InputError(std::string file, std::string reason)
        : std::runtime_error(file + ": " + reason), file_(std::move(file)) {}
    InputError(std::string file, Unit unit, std::uint64_t position, std::string reason)
        : std::runtime_error(format(file, unit, position, reason)),
          file_(std::move(file)),
          unit_(unit),
          position_(position) {}

    [[nodiscard]] const std::string& file() const noexcept { return file_; }
    [[nodiscard]] Unit unit() const noexcept { return unit_; }
    /// 1-based line number, or 0-based byte offset, depending on unit().
    [[nodiscard]] std::uint64_t position() const noexcept { return position_; }

private:
    static std::string format(const std::string& file, Unit unit, std::uint64_t pos,
                              const std::string& reason) {
        if (unit == Unit::line) return file + ":" + std::to_string(pos) + ": " + reason;
        if (unit == Unit::byte) return file + ": byte " + std::to_string(pos) + ": " + reason;
        return file + ": " + reason;
    }
    std::string file_;
    Unit unit_ = Unit::none;
    std::uint64_t position_ = 0;
};

/// A failure to write an output file.
class OutputError : public std::runtime_error {
public:
    OutputError(const std::string& file, const std::string& reason)
        : std::runtime_error(file + ": " + reason) {}
};

}  // namespace evcorner
