#pragma once
// What every event-file writer offers, and opening one by format name or by the
// output file's extension. Each writer's output reads back through the matching
// reader to the identical events.

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::io {

class EventWriter {
public:
    /// Without close(), nothing is left under the file's name (an old file there stays
    /// as it was); standard output keeps what was written.
    virtual ~EventWriter() = default;
    virtual void write(std::span<const Event> events) = 0;
    /// Writes events with one score each (scores.size() == events.size()), on a writer
    /// opened with scores (open_event_writer(..., with_score)); its readers give them back
    /// (EventReader::scores_in_batch()). Throws std::logic_error on one opened without.
    virtual void write(std::span<const Event> events, std::span<const double> scores);
    /// The sensor size to record, for formats that have a field for it (AEDAT 4.0, HDF5;
    /// the others ignore it); replaces the one given when opening. Call before close().
    /// Throws OutputError when it cannot hold the events written.
    virtual void set_sensor(SensorSize /*size*/) {}
    /// Completes the file and puts it under its name (output_file.hpp); throws OutputError.
    virtual void close() = 0;
    [[nodiscard]] virtual const std::string& name() const noexcept = 0;
};

/// The format names open_event_writer() accepts, besides "auto" (and the aliases "text"
/// for ecd-text, "h5" for hdf5).
inline constexpr std::string_view kOutputFormats = "ecd-text, csv, npy, aedat4, hdf5";
/// The file extensions that name an output format (compared case-insensitively).
inline constexpr std::string_view kOutputExtensions = ".txt, .csv, .npy, .aedat4, .h5, .hdf5";

/// The output format for `path` by its extension: .txt -> ecd-text, .csv -> csv,
/// .npy -> npy, .aedat4 -> aedat4, .h5 / .hdf5 -> hdf5 (DSEC layout), case-insensitive;
/// "" when the extension is none of these.
std::string output_format_for(const std::string& path);

/// The format to write `path` in: `format` when it is not "auto" (a name of
/// kOutputFormats or an alias); else by extension; ecd-text when the path's last
/// component has no extension ("-", "/dev/null", "corners"). Throws std::invalid_argument
/// for an unknown format name, or an extension that names no format (".npz", ".json"),
/// listing the known ones.
std::string resolve_output_format(const std::string& path, std::string_view format);

/// Creates `path` ("-" = standard output, text formats only) in `format`
/// (resolve_output_format()). `sensor`: the sensor size for formats that record one
/// (AEDAT 4.0, HDF5; nullopt: set_sensor() before close(), else AEDAT 4.0 records the
/// smallest size holding every event and HDF5 none). Throws OutputError, or
/// std::invalid_argument for the format, and, before opening anything, for a pipe or
/// socket (a FIFO's path, or "-" to one) in a format that seeks back to complete its
/// file: npy, hdf5, and aedat4 without `sensor`.
///
/// `with_score`: each event carries a score (EventWriter::write(events, scores)): text
/// "t x y p score" lines, a CSV `score` column, a .npy `score` field ('<f8'), HDF5
/// events/score (float64). AEDAT 4.0's event packets have no field for one: with_score
/// there is std::invalid_argument.
std::unique_ptr<EventWriter> open_event_writer(const std::string& path, std::string_view format = "auto",
                                               std::optional<SensorSize> sensor = std::nullopt,
                                               bool with_score = false);
/// The formats whose writer carries scores (with_score), as names of kOutputFormats.
inline constexpr std::string_view kScoredOutputFormats = "ecd-text, csv, npy, hdf5";

}  // namespace evcorner::io
