// The worker pool and the part planning of parallel_detect.hpp.

#include "evcorner/parallel_detect.hpp"

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace evcorner {

// Hand-offs spin briefly before they sleep: a round lasts a millisecond or less, and
// a futex wake-up costs tens of microseconds, which would eat the gain of a second core.
namespace {
constexpr int kSpins = 1 << 15;
inline void pause() noexcept {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
}
}  // namespace

struct WorkerPool::State {
    std::mutex mutex;
    std::condition_variable start;
    std::condition_variable done;
    const std::function<void(int)>* job = nullptr;
    std::atomic<std::uint64_t> generation{0};
    std::atomic<int> pending{0};
    std::atomic<bool> stop{false};
    std::vector<std::thread> threads;
};

WorkerPool::WorkerPool(int threads) : threads_(std::max(1, threads)), state_(std::make_unique<State>()) {
    State& s = *state_;
    for (int w = 1; w < threads_; ++w) {
        s.threads.emplace_back([&s, w] {
            std::uint64_t seen = 0;
            for (;;) {
                for (int i = 0; i < kSpins && s.generation.load(std::memory_order_acquire) == seen &&
                                !s.stop.load(std::memory_order_relaxed);
                     ++i)
                    pause();
                if (s.generation.load(std::memory_order_acquire) == seen && !s.stop.load()) {
                    std::unique_lock lock(s.mutex);
                    s.start.wait(lock, [&] { return s.stop.load() || s.generation.load() != seen; });
                }
                if (s.stop.load()) return;
                seen = s.generation.load(std::memory_order_acquire);
                (*s.job)(w);
                if (s.pending.fetch_sub(1, std::memory_order_acq_rel) == 1) {
                    std::lock_guard lock(s.mutex);
                    s.done.notify_one();
                }
            }
        });
    }
}

WorkerPool::~WorkerPool() {
    {
        std::lock_guard lock(state_->mutex);
        state_->stop = true;
    }
    state_->start.notify_all();
    for (auto& t : state_->threads) t.join();
}

void WorkerPool::run(const std::function<void(int)>& job) {
    State& s = *state_;
    if (threads_ == 1) {
        job(0);
        return;
    }
    s.job = &job;
    s.pending.store(threads_ - 1, std::memory_order_relaxed);
    {
        std::lock_guard lock(s.mutex);
        s.generation.fetch_add(1, std::memory_order_release);
    }
    s.start.notify_all();
    job(0);
    for (int i = 0; i < kSpins && s.pending.load(std::memory_order_acquire) != 0; ++i) pause();
    if (s.pending.load(std::memory_order_acquire) != 0) {
        std::unique_lock lock(s.mutex);
        s.done.wait(lock, [&] { return s.pending.load() == 0; });
    }
}

std::vector<DetectPart> plan_parts(SensorSize size, int bands, int radius, std::span<const Event> sample,
                                   bool split_polarity) {
    const int h = size.height;
    const int min_rows = std::max(1, 2 * radius);
    bands = std::clamp(bands, 1, std::max(1, h / min_rows));
    std::vector<DetectPart> parts;
    // p = 0, 1 (one polarity each), or p = -1 alone (both).
    for (int p = split_polarity ? 0 : -1; p < (split_polarity ? 2 : 0); ++p) {
        // Rows' shares of this polarity's (or all) sample events.
        std::vector<std::uint64_t> count(static_cast<std::size_t>(h), 0);
        std::uint64_t total = 0;
        for (const Event& e : sample)
            if ((p < 0 || (e.p & 1) == p) && e.y < h) {
                ++count[e.y];
                ++total;
            }
        int y = 0;
        std::uint64_t cum = 0;
        for (int b = 0; b < bands; ++b) {
            int end = h;
            if (b + 1 < bands) {
                if (total == 0) {
                    end = static_cast<int>(static_cast<std::int64_t>(h) * (b + 1) / bands);
                } else {
                    // The band ends where the cumulative count comes closest to (b+1)/bands.
                    const std::uint64_t target = total * static_cast<std::uint64_t>(b + 1) / static_cast<std::uint64_t>(bands);
                    end = y;
                    while (end < h && cum + count[static_cast<std::size_t>(end)] <= target) cum += count[static_cast<std::size_t>(end++)];
                    if (end < h && target - cum > cum + count[static_cast<std::size_t>(end)] - target)
                        cum += count[static_cast<std::size_t>(end++)];
                }
                // At least min_rows rows for this band and for each band after it.
                end = std::clamp(end, y + min_rows, h - (bands - b - 1) * min_rows);
                cum = 0;
                for (int r = 0; r < end; ++r) cum += count[static_cast<std::size_t>(r)];
            }
            DetectPart part;
            part.p = p;
            part.y0 = y;
            part.y1 = end;
            part.lo = std::max(0, y - radius);
            part.hi = std::min(h, end + radius);
            parts.push_back(part);
            y = end;
        }
    }
    return parts;
}

}  // namespace evcorner
