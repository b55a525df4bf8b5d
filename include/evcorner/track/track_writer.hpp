#pragma once
// Track files: the states a tracker reports, one row each, in the order reported.
//   ddft   `id t x y` (whitespace), the feature-track benchmark's layout (t seconds)
//   haste  `t,x,y,theta,id`, the HASTE app's layout, every value with 6 decimals
//   csv    header `id,t,x,y,theta,change`, t in seconds, change a name (track_state.hpp)
//   npy    a structured array [('id','<u8'), ('t','<i8'), ('x','<f4'), ('y','<f4'),
//          ('theta','<f4'), ('change','u1')] (t in microseconds, change 0/1/2)
// Times in text are printed exactly from the integer microseconds. A file is complete or
// absent: written under a temporary name and put in place by close().

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "evcorner/track/track_state.hpp"

namespace evcorner {

enum class TrackFormat : std::uint8_t { ddft, haste, csv, npy };

/// "ddft", "haste", "csv", "npy"; nullopt for another name.
std::optional<TrackFormat> parse_track_format(std::string_view name) noexcept;
/// The format a path's extension implies: .npy npy, .csv csv, anything else ddft.
TrackFormat track_format_for(std::string_view path) noexcept;

class TrackWriter {
public:
    /// Creates `path` ("-": standard output; not for npy). Throws OutputError.
    TrackWriter(const std::string& path, TrackFormat format);
    ~TrackWriter();  ///< without close(): no file under the name
    void write(std::span<const TrackState> states);
    /// Completes the file; throws OutputError.
    void close();
    [[nodiscard]] std::uint64_t rows() const noexcept { return rows_; }

private:
    struct Out;
    std::unique_ptr<Out> out_;
    TrackFormat format_;
    std::uint64_t rows_ = 0;
    bool closed_ = false;
};

}  // namespace evcorner
