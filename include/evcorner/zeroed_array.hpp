#pragma once
// A fixed-size array of trivially copyable values that starts all zero bytes, allocated
// with calloc: a large one comes straight from the kernel as untouched zero pages, so a
// detector's state costs neither time nor memory until events write to it (a
// 30000x30000 sensor with a few events holds a few pages, not 14 GB). The detectors'
// states therefore use all-zero bytes as their "never fired" value.
// Up to kEagerBytes (every real sensor: 1280x720 eFAST state is 14.7 MB) the pages are
// touched at construction, as a filled vector's were: first-touch page faults cost
// several microseconds each on a virtual machine, and inside the first events' detection
// they made a 30 000-event file's detection time four times its steady state.

#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>

namespace evcorner {

template <class T>
class ZeroedArray {
    static_assert(std::is_trivially_copyable_v<T>);

public:
    /// Arrays up to this size are committed (their pages touched) at construction.
    static constexpr std::size_t kEagerBytes = std::size_t{64} << 20;

    ZeroedArray() noexcept = default;
    /// `n` zero-filled values; throws std::bad_alloc when the memory cannot be had.
    explicit ZeroedArray(std::size_t n) : data_(allocate(n)), size_(n) {}
    ZeroedArray(const ZeroedArray& o) : data_(allocate(o.size_)), size_(o.size_) {
        if (size_ != 0) std::memcpy(data_, o.data_, size_ * sizeof(T));
    }
    ZeroedArray(ZeroedArray&& o) noexcept : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)) {}
    ZeroedArray& operator=(ZeroedArray o) noexcept {
        std::swap(data_, o.data_);
        std::swap(size_, o.size_);
        return *this;
    }
    ~ZeroedArray() { std::free(data_); }

    [[nodiscard]] std::size_t size() const noexcept { return size_; }
    [[nodiscard]] T* data() noexcept { return data_; }
    [[nodiscard]] const T* data() const noexcept { return data_; }
    T& operator[](std::size_t i) noexcept { return data_[i]; }
    const T& operator[](std::size_t i) const noexcept { return data_[i]; }

    /// Back to all zero bytes (fresh pages: the memory written so far is returned).
    void clear() { *this = ZeroedArray(size_); }

private:
    static T* allocate(std::size_t n) {
        if (n == 0) return nullptr;
        void* p = std::calloc(n, sizeof(T));  // checks n * sizeof(T) for overflow
        if (p == nullptr) throw std::bad_alloc();
        const std::size_t bytes = n * sizeof(T);
        if (bytes <= kEagerBytes) {
            // Volatile: a plain store of zero into calloc'd memory may be dropped.
            volatile unsigned char* c = static_cast<unsigned char*>(p);
            for (std::size_t i = 0; i < bytes; i += kPage) c[i] = 0;
        }
        return static_cast<T*>(p);
    }

    static constexpr std::size_t kPage = 4096;
    T* data_ = nullptr;
    std::size_t size_ = 0;
};

}  // namespace evcorner
