#pragma once
// Bounds-checked reading of FlatBuffers tables (internal to the AEDAT 4.0 reader).
// Wire format (flatbuffers.dev, "FlatBuffers internals"): little-endian; a buffer
// starts with a uint32 offset to the root table, optionally followed by a 4-byte file
// identifier; a table starts with an int32 soffset: vtable = table - soffset; a vtable
// is uint16 vtable size, uint16 table size, then one uint16 offset per field (0 =
// absent); a reference field holds a uint32 offset relative to the field itself; a
// vector / string is a uint32 length followed by its elements.
//
// Every accessor checks its offsets against the buffer and returns nullopt (never
// reads outside) when they do not fit. Offsets are 64-bit so that no sum overflows.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string_view>

#include "evcorner/io/byte_order.hpp"

namespace evcorner::io::fb {

// FlatBuffers are little-endian.
inline std::uint16_t u16(const unsigned char* p) noexcept { return load_le16(p); }
inline std::uint32_t u32(const unsigned char* p) noexcept { return load_le32(p); }
inline std::uint64_t u64(const unsigned char* p) noexcept { return load_le64(p); }

class Buffer {
public:
    Buffer(const unsigned char* data, std::size_t size) noexcept : p_(data), n_(size) {}

    /// The root table's position, checking the identifier when one is given.
    [[nodiscard]] std::optional<std::uint64_t> root(std::string_view identifier = {}) const noexcept {
        if (n_ < 8) return std::nullopt;
        if (!identifier.empty() && std::memcmp(p_ + 4, identifier.data(), 4) != 0) return std::nullopt;
        const std::uint64_t t = u32(p_);
        if (!table_ok(t)) return std::nullopt;
        return t;
    }

    /// Position of field `index` of the table at `t` with `width` bytes there; nullopt
    /// when absent or out of bounds (absent and broken are told apart by present()).
    [[nodiscard]] std::optional<std::uint64_t> field(std::uint64_t t, unsigned index,
                                                     std::size_t width) const noexcept {
        const std::uint64_t vt = vtable(t);
        const std::uint16_t vts = u16(p_ + vt);
        const std::uint64_t slot = 4 + 2 * std::uint64_t{index};
        if (slot + 2 > vts) return std::nullopt;
        const std::uint16_t off = u16(p_ + vt + slot);
        if (off == 0 || off + width > u16(p_ + vt + 2)) return std::nullopt;
        return t + off;
    }

    [[nodiscard]] std::optional<std::int32_t> i32(std::uint64_t t, unsigned index) const noexcept {
        const auto f = field(t, index, 4);
        if (!f) return std::nullopt;
        return static_cast<std::int32_t>(u32(p_ + *f));
    }
    [[nodiscard]] std::optional<std::int64_t> i64(std::uint64_t t, unsigned index) const noexcept {
        const auto f = field(t, index, 8);
        if (!f) return std::nullopt;
        return static_cast<std::int64_t>(u64(p_ + *f));
    }

    /// A vector field: the position of its first element and its length, checked to
    /// hold `length * elem` bytes.
    struct Vector {
        std::uint64_t data;
        std::uint64_t length;
    };
    [[nodiscard]] std::optional<Vector> vector(std::uint64_t t, unsigned index, std::size_t elem) const noexcept {
        const auto f = field(t, index, 4);
        if (!f) return std::nullopt;
        const std::uint64_t v = *f + u32(p_ + *f);
        if (v + 4 > n_) return std::nullopt;
        const std::uint64_t len = u32(p_ + v);
        if (len > (n_ - v - 4) / elem) return std::nullopt;
        return Vector{v + 4, len};
    }
    [[nodiscard]] std::optional<std::string_view> string(std::uint64_t t, unsigned index) const noexcept {
        const auto v = vector(t, index, 1);
        if (!v) return std::nullopt;
        return std::string_view(reinterpret_cast<const char*>(p_ + v->data), v->length);
    }

    /// Whether the table's vtable has a non-zero slot for field `index`.
    [[nodiscard]] bool present(std::uint64_t t, unsigned index) const noexcept {
        const std::uint64_t vt = vtable(t);
        const std::uint64_t slot = 4 + 2 * std::uint64_t{index};
        return slot + 2 <= u16(p_ + vt) && u16(p_ + vt + slot) != 0;
    }

    [[nodiscard]] const unsigned char* at(std::uint64_t pos) const noexcept { return p_ + pos; }

private:
    // A table at t whose soffset, vtable and declared table size all lie in the buffer.
    [[nodiscard]] bool table_ok(std::uint64_t t) const noexcept {
        if (t + 4 > n_) return false;
        const std::int64_t vt = static_cast<std::int64_t>(t) - static_cast<std::int32_t>(u32(p_ + t));
        if (vt < 0 || static_cast<std::uint64_t>(vt) + 4 > n_) return false;
        const std::uint16_t vts = u16(p_ + vt);
        const std::uint16_t ts = u16(p_ + vt + 2);
        return vts >= 4 && vts % 2 == 0 && static_cast<std::uint64_t>(vt) + vts <= n_ && ts >= 4 && t + ts <= n_;
    }
    [[nodiscard]] std::uint64_t vtable(std::uint64_t t) const noexcept {
        return static_cast<std::uint64_t>(static_cast<std::int64_t>(t) - static_cast<std::int32_t>(u32(p_ + t)));
    }

    const unsigned char* p_;
    std::size_t n_;
};

}  // namespace evcorner::io::fb
