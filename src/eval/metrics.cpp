#include "evcorner/eval/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace evcorner::eval {

double reduction_rate(std::uint64_t events, std::uint64_t corners) noexcept {
    if (events == 0) return 0.0;
    return 100.0 * (1.0 - static_cast<double>(corners) / static_cast<double>(events));
}

double ft_percent(std::uint64_t corners, std::uint64_t on_track) noexcept {
    if (corners == 0) return 0.0;
    return 100.0 * static_cast<double>(on_track) / static_cast<double>(corners);
}

double median(std::vector<double> v) noexcept {
    if (v.empty()) return 0.0;
    const std::size_t mid = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
    const double upper = v[mid];
    if (v.size() % 2 == 1) return upper;
    const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
    return 0.5 * (lower + upper);
}

namespace {
std::size_t index_of(std::vector<std::string>& names, const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it != names.end()) return static_cast<std::size_t>(it - names.begin());
    names.push_back(name);
    return names.size() - 1;
}
}  // namespace

Table1 make_table1(const std::vector<RunRecord>& runs) {
    Table1 t;
    for (const auto& r : runs) {
        index_of(t.sequences, r.sequence);
        index_of(t.detectors, r.detector);
    }
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    t.cells.assign(t.sequences.size(), std::vector<QualityCell>(t.detectors.size(), QualityCell{nan, nan}));
    for (const auto& r : runs) {
        const std::size_t row = index_of(t.sequences, r.sequence);
        const std::size_t col = index_of(t.detectors, r.detector);
        t.cells[row][col] = {reduction_rate(r.events, r.corners), ft_percent(r.corners, r.on_track)};
    }
    return t;
}

Table2 make_table2(const std::vector<RunRecord>& runs) {
    std::vector<std::string> names;
    Table2 rows;
    for (const auto& r : runs) {
        const std::size_t i = index_of(names, r.detector);
        if (i == rows.size()) rows.push_back(SpeedRow{r.detector});
        rows[i].events += r.events;
        rows[i].detect_s += r.detect_s;
    }
    for (auto& row : rows) {
        row.us_per_event = row.events > 0 ? row.detect_s * 1e6 / static_cast<double>(row.events) : 0.0;
        row.max_event_rate = row.detect_s > 0 ? static_cast<double>(row.events) / row.detect_s : 0.0;
    }
    return rows;
}

}  // namespace evcorner::eval
