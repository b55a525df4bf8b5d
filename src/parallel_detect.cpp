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

std::vector<DetectPart> plan_parts(SensorSize size, int threads, std::span<const Event> sample) {
    threads = std::max(1, threads);
    const int h = size.height;
    // Cell c = p * h + y: OFF rows first, then ON rows; its share of the sample.
    std::vector<std::uint64_t> count(2 * static_cast<std::size_t>(h), 0);
    std::uint64_t total = 0;
    for (const Event& e : sample)
        if (e.y < h) {
            ++count[static_cast<std::size_t>((e.p & 1) * h + e.y)];
            ++total;
        }
    const int cells = 2 * h;
    std::vector<DetectPart> parts;
    int c = 0;
    std::uint64_t cum = 0;
    for (int t = 0; t < threads; ++t) {
        int end = cells;
        if (t + 1 < threads) {
            if (total == 0) {
                end = static_cast<int>(static_cast<std::int64_t>(cells) * (t + 1) / threads);
            } else {
                // The run ends where the cumulative count comes closest to (t+1)/threads.
                const std::uint64_t target = total * static_cast<std::uint64_t>(t + 1) / static_cast<std::uint64_t>(threads);
                end = c;
                while (end < cells && cum + count[static_cast<std::size_t>(end)] <= target) cum += count[static_cast<std::size_t>(end++)];
                if (end < cells && target - cum > cum + count[static_cast<std::size_t>(end)] - target)
                    cum += count[static_cast<std::size_t>(end++)];
            }
            end = std::max(c, end);
        }
        // Cells [c, end) as a band per polarity.
        DetectPart part;
        for (int p = 0; p < 2; ++p) {
            const int from = std::clamp(c - p * h, 0, h);
            const int to = std::clamp(end - p * h, 0, h);
            part.y0[p] = from < to ? from : 0;
            part.y1[p] = from < to ? to : 0;
        }
        parts.push_back(part);
        c = end;
    }
    return parts;
}

}  // namespace evcorner
