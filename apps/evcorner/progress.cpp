#include "progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <fmt/format.h>

namespace evcorner::cli {

using Clock = std::chrono::steady_clock;

Progress::Progress(bool enabled, std::optional<std::uint64_t> total_bytes)
    : enabled_(enabled && ::isatty(STDERR_FILENO) == 1),
      total_(total_bytes),
      start_(Clock::now()),
      last_(start_) {}

void Progress::update(std::uint64_t bytes_done, std::uint64_t events_done) {
    if (!enabled_) return;
    const auto now = Clock::now();
    // Short runs never show a bar; long ones redraw every 100 ms.
    if (now - start_ < std::chrono::milliseconds(500) || now - last_ < std::chrono::milliseconds(100))
        return;
    last_ = now;
    const double secs = std::chrono::duration<double>(now - start_).count();
    const double rate = static_cast<double>(events_done) / secs / 1e6;
    std::string line;
    if (total_ && *total_ > 0) {
        const double frac = std::min(1.0, static_cast<double>(bytes_done) / static_cast<double>(*total_));
        constexpr int kWidth = 30;
        const int filled = static_cast<int>(frac * kWidth);
        line = fmt::format("\r[{}{}] {:5.1f}%  {:.2f} M events  {:.1f} M events/s ",
                           std::string(static_cast<std::size_t>(filled), '#'),
                           std::string(static_cast<std::size_t>(kWidth - filled), '.'),
                           100.0 * frac, static_cast<double>(events_done) / 1e6, rate);
    } else {
        line = fmt::format("\r{:.2f} M events  {:.1f} M events/s ",
                           static_cast<double>(events_done) / 1e6, rate);
    }
    std::fputs(line.c_str(), stderr);
    std::fflush(stderr);
    drawn_ = true;
}

void Progress::finish() {
    if (drawn_) {
        std::fputs("\r\033[K", stderr);
        std::fflush(stderr);
        drawn_ = false;
    }
}

}  // namespace evcorner::cli
