#pragma once
// The newest N distinct pixels of an event stream (one polarity), as the event-based
// Harris of Vasco et al. (IROS 2016) binarises its surface: a pixel belongs to the set
// iff fewer than N other pixels have fired more recently than its own latest event.
//
// Kept as a FIFO ring of (pixel, sequence number) entries next to the per-pixel latest
// sequence numbers (an ArrivalSae plane): an entry is stale once its pixel has fired
// again. A re-firing member adds an entry and leaves the set unchanged; a newcomer adds
// one and, once the set would exceed N, evicts the oldest valid entry. Stale entries are
// dropped when they reach the tail, or all at once when the ring is full (compaction
// keeps at most N entries in a ring of 2N, so it runs at most once every N events):
// O(1) amortised per event, no allocation after construction.
//
// Membership needs no flag: the set is exactly the pixels whose latest sequence number
// is >= the sequence number of the oldest valid entry, threshold().

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace evcorner {

class NewestPixels {
public:
    /// `n` >= 1: the size of the set. `max_pixels`: how many distinct pixel ids can occur
    /// (bounds the ring when n exceeds it).
    NewestPixels(std::size_t n, std::size_t max_pixels) : n_(n), ring_(ring_size(n, max_pixels)) {}

    /// Bytes a set of `n` over `max_pixels` pixel ids holds.
    [[nodiscard]] static constexpr std::uint64_t state_bytes(std::size_t n, std::size_t max_pixels) noexcept {
        return static_cast<std::uint64_t>(ring_size(n, max_pixels)) * sizeof(Entry);
    }

    /// Records that pixel `id` fired with sequence number `seq` (larger than any before).
    /// `latest[id]` must already hold `seq`; `previous` is what it held before (0 = never).
    void push(std::size_t id, std::uint64_t seq, std::uint64_t previous, const std::uint64_t* latest) noexcept {
        const bool member = previous != 0 && previous >= threshold_;
        if (count_ == ring_.size()) compact(latest);
        ring_[wrap(tail_ + count_)] = {id, seq};
        ++count_;
        if (!member && ++size_ > n_) {
            drop_stale(latest);
            ++tail_;  // the oldest valid entry: evicted
            if (tail_ == ring_.size()) tail_ = 0;
            --count_;
            --size_;
        }
        drop_stale(latest);
        threshold_ = ring_[tail_].seq;
    }

    /// Sequence number of the oldest member (0 before the first push): pixel `id` is in
    /// the set iff latest[id] != 0 and latest[id] >= threshold().
    [[nodiscard]] std::uint64_t threshold() const noexcept { return threshold_; }
    /// Number of distinct pixels in the set (min(n, pixels fired so far)).
    [[nodiscard]] std::size_t size() const noexcept { return size_; }
    [[nodiscard]] std::size_t n() const noexcept { return n_; }
    [[nodiscard]] std::size_t memory_bytes() const noexcept { return ring_.size() * sizeof(Entry); }

private:
    struct Entry {
        std::size_t id;
        std::uint64_t seq;
    };
    static constexpr std::size_t ring_size(std::size_t n, std::size_t max_pixels) noexcept {
        return 2 * std::min(n, std::max<std::size_t>(max_pixels, 1)) + 1;
    }
    [[nodiscard]] std::size_t wrap(std::size_t i) const noexcept { return i >= ring_.size() ? i - ring_.size() : i; }
    [[nodiscard]] static bool valid(const Entry& en, const std::uint64_t* latest) noexcept {
        return latest[en.id] == en.seq;
    }
    void drop_stale(const std::uint64_t* latest) noexcept {
        while (count_ > 0 && !valid(ring_[tail_], latest)) {
            if (++tail_ == ring_.size()) tail_ = 0;
            --count_;
        }
    }
    // Moves the valid entries together, in order, from the tail on.
    void compact(const std::uint64_t* latest) noexcept {
        std::size_t kept = 0;
        for (std::size_t i = 0; i < count_; ++i) {
            const Entry en = ring_[wrap(tail_ + i)];
            if (valid(en, latest)) ring_[wrap(tail_ + kept++)] = en;
        }
        count_ = kept;
    }

    std::size_t n_;
    std::vector<Entry> ring_;
    std::size_t tail_ = 0;   // oldest entry
    std::size_t count_ = 0;  // entries in the ring, stale ones included
    std::size_t size_ = 0;   // valid entries = members
    std::uint64_t threshold_ = 0;
};

}  // namespace evcorner
