#pragma once
// Drawn timestamp grids for the detector tests: a window of one polarity's SAE written as
// rows of timestamps ('.' = never fired, 'E' = the event under test), turned into the cells
// to feed in time order.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "evcorner/event.hpp"

namespace evcorner::test {

struct Cell {
    std::int64_t t;
    int x, y;
};

/// Parses a drawn grid placed with its top-left pixel at (x0, y0). Returns the cells with
/// a timestamp, sorted by time (ties in drawing order), and sets (ex, ey) to the 'E' cell.
inline std::vector<Cell> parse_grid(const std::vector<std::string>& rows, int x0, int y0, int& ex, int& ey) {
    std::vector<Cell> cells;
    for (int r = 0; r < static_cast<int>(rows.size()); ++r) {
        std::istringstream in(rows[r]);
        std::string tok;
        for (int c = 0; in >> tok; ++c) {
            if (tok == ".") continue;
            if (tok == "E") {
                ex = x0 + c;
                ey = y0 + r;
                continue;
            }
            cells.push_back({std::stoll(tok), x0 + c, y0 + r});
        }
    }
    std::stable_sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.t < b.t; });
    return cells;
}

/// Feeds the drawn grid, placed at (5, 5), as events of polarity `p` to `fast` and
/// `oracle`, expecting the same answer from both for each; returns the 'E' event at
/// t = 1000 (not fed).
template <class Fast, class Oracle>
Event feed_grid(const std::vector<std::string>& rows, Fast& fast, Oracle& oracle, int p) {
    int ex = -1, ey = -1;
    for (const Cell& c : parse_grid(rows, 5, 5, ex, ey)) {
        const Event e{c.t, static_cast<std::uint16_t>(c.x), static_cast<std::uint16_t>(c.y),
                      static_cast<std::uint8_t>(p)};
        EXPECT_EQ(fast.process(e), oracle.process(e));
    }
    EXPECT_GE(ex, 0) << "grid has no 'E'";
    return {1000, static_cast<std::uint16_t>(ex), static_cast<std::uint16_t>(ey), static_cast<std::uint8_t>(p)};
}

}  // namespace evcorner::test
