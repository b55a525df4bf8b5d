#include "evcorner/state_memory.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace evcorner {

namespace {

// "MemAvailable:   22345678 kB" -> bytes; 0 when absent.
std::uint64_t meminfo_available() {
    std::ifstream in("/proc/meminfo");
    std::string key, unit;
    std::uint64_t value = 0;
    while (in >> key >> value) {
        std::getline(in, unit);
        if (key == "MemAvailable:") return value * 1024;
    }
    return 0;
}

// The room left under a cgroup v2 memory limit ("max" or absent: no limit, 0).
std::uint64_t cgroup_room() {
    std::ifstream max_in("/sys/fs/cgroup/memory.max"), cur_in("/sys/fs/cgroup/memory.current");
    std::string max_text;
    std::uint64_t current = 0;
    if (!(max_in >> max_text) || max_text == "max" || !(cur_in >> current)) return 0;
    std::uint64_t limit = 0;
    try {
        limit = std::stoull(max_text);
    } catch (...) {
        return 0;
    }
    return limit > current ? limit - current : 1;
}

}  // namespace

std::uint64_t available_memory_bytes() noexcept {
    try {
        std::uint64_t avail = meminfo_available();
        if (avail == 0) {
            const long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
            if (pages > 0 && page > 0) avail = static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page);
        }
        if (const std::uint64_t room = cgroup_room(); room != 0) avail = avail == 0 ? room : std::min(avail, room);
        return avail;
    } catch (...) {
        return 0;
    }
}

std::string format_bytes(std::uint64_t bytes) {
    static constexpr const char* kUnits[] = {"B", "kB", "MB", "GB", "TB", "PB", "EB"};
    double v = static_cast<double>(bytes);
    int u = 0;
    while (v >= 999.95 && u < 6) {
        v /= 1000.0;
        ++u;
    }
    char buf[32];
    if (u == 0)
        std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
    else
        std::snprintf(buf, sizeof buf, v < 9.995 ? "%.2f %s" : v < 99.95 ? "%.1f %s" : "%.0f %s", v, kUnits[u]);
    return buf;
}

void require_state_fits(std::string_view detector, SensorSize size, std::uint64_t need, std::uint64_t available) {
    if (available == 0 || need <= available) return;
    const double per_pixel = static_cast<double>(need) / static_cast<double>(std::max<std::int64_t>(size.pixels(), 1));
    char pp[32];
    std::snprintf(pp, sizeof pp, "%.*f", per_pixel == static_cast<double>(static_cast<std::uint64_t>(per_pixel)) ? 0 : 1, per_pixel);
    throw StateTooLarge("a " + std::to_string(size.width) + "x" + std::to_string(size.height) + " sensor needs " +
                        format_bytes(need) + " for " + std::string(detector) + "'s state (" + pp +
                        " B per pixel); " + format_bytes(available) + " is available");
}

void require_memory_fits(std::string_view what, std::uint64_t need, std::string_view hint) {
    const std::uint64_t available = available_memory_bytes();
    if (available == 0 || need <= available) return;
    throw StateTooLarge(std::string(what) + " needs " + format_bytes(need) + "; " + format_bytes(available) +
                        " is available" + std::string(hint));
}

}  // namespace evcorner
