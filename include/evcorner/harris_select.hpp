#pragma once
// The selection step of the spatially-adaptive Harris detector (harris.hpp): from the w x w
// arrival sequence numbers of a window, light the nl cells that fired most recently
// (sequence numbers are unique, so the newest nl are always well defined; 0 = never fired).
//
// Several codes light the same cells (docs/harris.md, "The newest-nl selection"):
// - "portable": for the 9x9 window, 31-bit ages and a search for a threshold age with exactly
//   nl cells at or below it (counts written as plain loops the compiler vectorises); other
//   windows, and the rare 9x9 windows whose nl-th newest cell is 2^31 - 1 or more arrivals old,
//   take the exact 64-bit bucket selection;
// - "avx2": the same threshold search with the 81 ages in eleven 8-lane vectors;
// - "avx512": the bucket selection on 64-bit sequence numbers in 512-bit vectors.
// The path is chosen at run time (the fastest this CPU runs); the environment variable
// EVCORNER_HARRIS_PATH=portable|avx2|avx512 forces one the CPU runs.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace evcorner {

enum class HarrisPath : std::uint8_t { portable, avx2, avx512 };

/// The name of a path ("portable", "avx2", "avx512").
const char* harris_path_name(HarrisPath path) noexcept;
/// The path a new Harris takes for the 9x9 window: EVCORNER_HARRIS_PATH when set to a path
/// this CPU runs, else the fastest this CPU runs.
HarrisPath harris_default_path() noexcept;
/// The paths this CPU runs, the default first, "portable" last.
std::vector<std::string> harris_code_paths();
/// The path of that name if this CPU runs it; else std::invalid_argument naming it.
HarrisPath harris_path_named(std::string_view name);

/// Lights in `rows` (bit c of rows[r] = cell (r, c)) the `nl` cells with the largest
/// sequence numbers of the `window` x `window` cells whose top-left one is `first` (rows
/// `stride` cells apart); `now` is at least every sequence number read. Returns false
/// (rows unspecified) when fewer than nl cells are nonzero. Paths other than portable
/// serve window 9 only (other windows take the portable code whatever `path` says).
bool harris_select_newest(HarrisPath path, const std::uint64_t* first, std::size_t stride, int window,
                          std::uint64_t now, int nl, std::uint16_t* rows) noexcept;

}  // namespace evcorner
