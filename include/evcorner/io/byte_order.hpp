#pragma once
// Unsigned integers stored in a given byte order, read from unaligned bytes: what the
// binary formats' decoders share (AEDAT 2.0 is big-endian, the others little-endian).

#include <cstdint>

namespace evcorner::io {

inline std::uint16_t load_le16(const unsigned char* p) noexcept {
    return static_cast<std::uint16_t>(p[0] | p[1] << 8);
}
inline std::uint32_t load_le32(const unsigned char* p) noexcept {
    return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
}
inline std::uint64_t load_le64(const unsigned char* p) noexcept {
    return load_le32(p) | std::uint64_t{load_le32(p + 4)} << 32;
}
inline std::uint32_t load_be32(const unsigned char* p) noexcept {
    return std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[2]} << 8 | p[3];
}

}  // namespace evcorner::io
