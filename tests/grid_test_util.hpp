#pragma once
// Drawn timestamp grids for the detector tests: a window of one polarity's SAE written as
// rows of timestamps ('.' = never fired, 'E' = the event under test), turned into the cells
// to feed in time order.

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

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

}  // namespace evcorner::test
