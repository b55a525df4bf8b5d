#pragma once
// The paper's figures of merit (Mueggler et al., BMVC 2017, Tables 1 and 2) and the
// arithmetic that turns per-run measurements into those tables.
//
//   reduction rate = 100 (1 - corners / events)             [%]      Table 1, "Red."
//   FT             = 100 corners on a feature track / corners [%]      Table 1, "FT"
//   time per event = detection time / events                 [us]     Table 2
//   max event rate = 1 / time per event                      [events/s] Table 2

#include <cstdint>
#include <string>
#include <vector>

namespace evcorner::eval {

/// 100 (1 - corners / events); 0 when there are no events.
double reduction_rate(std::uint64_t events, std::uint64_t corners) noexcept;
/// 100 on_track / corners; 0 when there are no corners.
double ft_percent(std::uint64_t corners, std::uint64_t on_track) noexcept;
/// Median of `values` (mean of the two middle ones for an even count); 0 when empty.
double median(std::vector<double> values) noexcept;

/// One detector run on one sequence.
struct RunRecord {
    std::string sequence;
    std::string detector;
    std::uint64_t events = 0;
    std::uint64_t corners = 0;
    std::uint64_t on_track = 0;
    double detect_s = 0;  ///< detection time (median over repeats), seconds
};

/// Table 1 cell: one detector on one sequence.
struct QualityCell {
    double reduction = 0;  ///< %
    double ft = 0;         ///< %
};

struct Table1 {
    std::vector<std::string> sequences;  ///< rows, in first-seen order
    std::vector<std::string> detectors;  ///< column groups, in first-seen order
    /// cells[row][column]; a missing run gives a NaN cell.
    std::vector<std::vector<QualityCell>> cells;
};

/// Table 2 row: one detector over every sequence it ran on.
struct SpeedRow {
    std::string detector;
    std::uint64_t events = 0;
    double detect_s = 0;        ///< sum of the per-sequence detection times
    double us_per_event = 0;    ///< detect_s / events, microseconds
    double max_event_rate = 0;  ///< events per second = 1 / time per event
};

using Table2 = std::vector<SpeedRow>;

Table1 make_table1(const std::vector<RunRecord>& runs);
/// Time per event pools all sequences: total detection time over total events (a
/// long sequence weighs more, as in the paper's per-event figure over whole datasets).
Table2 make_table2(const std::vector<RunRecord>& runs);

}  // namespace evcorner::eval
