#pragma once
// The ground truth of a simulated scene: where every corner is, at any time.
//
// A corner is a vertex of a polygon object or a grid point of a checkerboard, moved by its
// object's motion (motion.hpp): its exact sub-pixel position (pixel (x, y) is the square
// [x, x+1) x [y, y+1), so an event at pixel (x, y) lies at (x + 0.5, y + 0.5)), its interior
// angle (unchanged by the motion, a similarity), its image velocity, and its state:
//   visible   on the sensor (0 <= x < width, 0 <= y < height) and not covered
//   occluded  strictly inside a piece of an object later in the list (in front of it)
//   outside   off the sensor
//
// The CSV (TruthWriter, read_truth_csv) has one row per corner and sample time, rows in time
// order and, within a time, by object then corner; its header is kTruthHeader:
//   t_us      sample time, integer microseconds (the events' clock)
//   object    index in the scene's "objects" list, from 0
//   corner    index within the object: the polygon's vertex as listed in the scene, or
//             row * (cols + 1) + col for a checkerboard's grid point
//   x, y      position, pixels
//   angle_deg interior angle, degrees (90 for a checkerboard's grid points)
//   vx, vy    image velocity, px/s; speed = its length
//   visible   1 when state is visible, else 0
//   state     visible, occluded or outside

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/sim/scene.hpp"

namespace evcorner::io {
class OutputFile;
}

namespace evcorner::sim {

enum class CornerState : std::uint8_t { visible, occluded, outside };

/// "visible", "occluded", "outside".
std::string_view to_string(CornerState s) noexcept;

struct TruthCorner {
    std::int64_t t_us = 0;
    int object = 0;
    int corner = 0;
    double x = 0;
    double y = 0;
    double angle_deg = 0;
    double vx = 0;
    double vy = 0;
    CornerState state = CornerState::visible;
};

inline constexpr std::string_view kTruthHeader = "t_us,object,corner,x,y,angle_deg,vx,vy,speed,visible,state";

/// Appends every corner of every object at time t_us to `out`.
void corners_at(const Scene& scene, std::int64_t t_us, std::vector<TruthCorner>& out);

/// Writes the truth CSV through io::OutputFile (atomic: nothing under the name until close()).
class TruthWriter {
public:
    /// Creates `path` ("-" = standard output) and writes the header. Throws OutputError.
    explicit TruthWriter(const std::string& path);
    ~TruthWriter();
    TruthWriter(const TruthWriter&) = delete;
    TruthWriter& operator=(const TruthWriter&) = delete;

    void write(std::span<const TruthCorner> rows);
    void close();
    [[nodiscard]] std::uint64_t rows() const noexcept { return rows_; }

private:
    std::unique_ptr<io::OutputFile> out_;
    std::uint64_t rows_ = 0;
};

/// Reads a truth CSV written by TruthWriter one sample time at a time, so that a long
/// truth (hundreds of MB) is never all in memory: next_sample() returns the rows of the next
/// t_us. Throws InputError "FILE:LINE: reason" for a wrong header, a row with the wrong number
/// of fields, a field that is not a number, a state other than the three, visible disagreeing
/// with state, or rows out of time order.
class TruthReader {
public:
    explicit TruthReader(const std::string& path);
    ~TruthReader();
    TruthReader(const TruthReader&) = delete;
    TruthReader& operator=(const TruthReader&) = delete;

    /// Replaces `rows` with every row of the next sample time; false (rows empty) at the end.
    bool next_sample(std::vector<TruthCorner>& rows);
    [[nodiscard]] const std::string& path() const noexcept { return path_; }
    /// Bytes read so far and the file's size (for a progress bar).
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept { return consumed_; }
    [[nodiscard]] std::uint64_t bytes_total() const noexcept { return total_; }

private:
    bool read_row(TruthCorner& r);
    std::string path_;
    struct Impl;
    std::unique_ptr<Impl> in_;
    std::uint64_t line_no_ = 0, consumed_ = 0, total_ = 0;
    std::int64_t last_t_ = INT64_MIN;
    bool has_pending_ = false;
    TruthCorner pending_;
};

/// Every row of a truth CSV in memory (tests, small scenes); the errors of TruthReader.
std::vector<TruthCorner> read_truth_csv(const std::string& path);

}  // namespace evcorner::sim
