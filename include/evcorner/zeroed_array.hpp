#pragma once
// A fixed-size array of trivially copyable values that starts all zero bytes, allocated
// with calloc: a large one comes straight from the kernel as untouched zero pages, so a
// detector's state costs neither time nor memory until events write to it (a
// 30000x30000 sensor with a few events holds a few pages, not 14 GB). The detectors'
// states therefore use all-zero bytes as their "never fired" value.

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
        return static_cast<T*>(p);
    }

    T* data_ = nullptr;
    std::size_t size_ = 0;
};

}  // namespace evcorner
