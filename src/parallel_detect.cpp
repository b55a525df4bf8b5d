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
    // Polarities are independent: split them first when the count allows.
    const std::vector<unsigned> groups = threads % 2 == 0 ? std::vector<unsigned>{1u, 2u} : std::vector<unsigned>{3u};
    const int bands = threads / static_cast<int>(groups.size());
    std::vector<DetectPart> parts;
    for (const unsigned g : groups) {
        std::vector<std::uint64_t> rows(static_cast<std::size_t>(size.height), 0);
        std::uint64_t total = 0;
        for (const Event& e : sample)
            if (((g >> e.p) & 1u) && e.y < size.height) {
                ++rows[e.y];
                ++total;
            }
        int y = 0;
        std::uint64_t cum = 0;
        for (int b = 0; b < bands; ++b) {
            DetectPart part{g, y, size.height};
            if (b + 1 < bands) {
                int end = y;
                if (total == 0) {
                    end = static_cast<int>(static_cast<std::int64_t>(size.height) * (b + 1) / bands);
                } else {
                    // The band ends where the sample's cumulative count reaches (b+1)/bands.
                    const std::uint64_t target = total * static_cast<std::uint64_t>(b + 1) / static_cast<std::uint64_t>(bands);
                    while (end < size.height && cum + rows[static_cast<std::size_t>(end)] <= target) cum += rows[static_cast<std::size_t>(end++)];
                }
                part.y1 = std::max(y, end);
            }
            parts.push_back(part);
            y = part.y1;
        }
    }
    return parts;
}

}  // namespace evcorner
