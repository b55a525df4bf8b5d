#pragma once
// A 5x7 bitmap font for the figures' titles, tick labels and legends: printable ASCII
// (digits, both cases of letters, punctuation), each glyph in a 6x8 cell (one column
// and one row of spacing). Characters outside printable ASCII draw as a hollow box.

#include <string_view>

#include "evcorner/render/image.hpp"

namespace evcorner::render {

inline constexpr int kGlyphWidth = 5, kGlyphHeight = 7;
inline constexpr int kCellWidth = 6, kCellHeight = 8;

/// Width in pixels of `text` drawn at `scale` (kCellWidth * scale per character, less the
/// trailing spacing column); 0 for empty text.
int text_width(std::string_view text, int scale = 1) noexcept;
/// Height in pixels of one line at `scale` (the glyph, without the spacing row).
constexpr int text_height(int scale = 1) noexcept { return kGlyphHeight * scale; }

/// Draws `text` with its top-left at (x, y), each font pixel a scale x scale block;
/// clipped to the image.
void draw_text(RgbImage& img, int x, int y, std::string_view text, Rgb colour, int scale = 1) noexcept;

}  // namespace evcorner::render
