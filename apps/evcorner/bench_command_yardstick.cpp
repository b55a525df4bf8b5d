// The built-in yardstick: a plain eFAST written from the definition (shared/docs/algorithms.md,
// docs/efast.md), deliberately without any of the detector's shortcuts. See the header.

#include "bench_command_yardstick.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <limits>
#include <vector>

namespace evcorner::cli {

namespace {

// Circle offsets (dx, dy) in cyclic order, radius 3 then radius 4.
constexpr int kCircle3[16][2] = {{0, 3},  {1, 3},   {2, 2},   {3, 1},   {3, 0},  {3, -1}, {2, -2}, {1, -3},
                                 {0, -3}, {-1, -3}, {-2, -2}, {-3, -1}, {-3, 0}, {-3, 1}, {-2, 2}, {-1, 3}};
constexpr int kCircle4[20][2] = {{0, 4},   {1, 4},   {2, 3},   {3, 2},   {4, 1},  {4, 0},  {4, -1},
                                 {3, -2},  {2, -3},  {1, -4},  {0, -4},  {-1, -4}, {-2, -3}, {-3, -2},
                                 {-4, -1}, {-4, 0},  {-4, 1},  {-3, 2},  {-2, 3},  {-1, 4}};

// Does some arc of length lo..hi (cyclic) have its oldest time strictly newer than every
// time on the rest of the circle? Every start and length, from scratch.
template <int N>
bool arc_fires(const std::int64_t* t, int lo, int hi) {
    for (int start = 0; start < N; ++start)
        for (int len = lo; len <= hi; ++len) {
            std::int64_t oldest = std::numeric_limits<std::int64_t>::max();
            for (int k = 0; k < len; ++k) oldest = std::min(oldest, t[(start + k) % N]);
            bool rest_older = true;
            for (int k = len; k < N && rest_older; ++k) rest_older = t[(start + k) % N] < oldest;
            if (rest_older) return true;
        }
    return false;
}

}  // namespace

double bench_clock_ns(bool cpu_time) noexcept {
    if (!cpu_time)
        return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now().time_since_epoch()).count();
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

[[gnu::noinline]] YardstickPass plain_efast_pass(std::span<const Event> events, SensorSize sensor, bool cpu_time) {
    const int w = sensor.width, h = sensor.height;
    const std::size_t plane_size = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    std::vector<std::int64_t> sae(2 * plane_size, std::numeric_limits<std::int64_t>::min());
    YardstickPass out;
    const double t0 = bench_clock_ns(cpu_time);
    for (const Event& e : events) {
        std::int64_t* const plane = sae.data() + (e.p != 0 ? plane_size : 0);
        plane[static_cast<std::size_t>(e.y) * w + e.x] = e.t;
        if (e.x < 4 || e.x >= w - 4 || e.y < 4 || e.y >= h - 4) continue;
        std::int64_t c3[16], c4[20];
        for (int k = 0; k < 16; ++k) c3[k] = plane[static_cast<std::size_t>(e.y + kCircle3[k][1]) * w + e.x + kCircle3[k][0]];
        if (!arc_fires<16>(c3, 3, 6)) continue;
        for (int k = 0; k < 20; ++k) c4[k] = plane[static_cast<std::size_t>(e.y + kCircle4[k][1]) * w + e.x + kCircle4[k][0]];
        out.corners += arc_fires<20>(c4, 4, 8);
    }
    const double ns = bench_clock_ns(cpu_time) - t0;
    out.ns_per_event = events.empty() ? 0.0 : ns / static_cast<double>(events.size());
    return out;
}

}  // namespace evcorner::cli
