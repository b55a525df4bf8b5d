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
    virtual ~EventWriter() = default;
    virtual void write(std::span<const Event> events) = 0;
    /// Completes the file; throws OutputError. Without it, the destructor completes
    /// it and swallows errors.
    virtual void close() = 0;
    [[nodiscard]] virtual const std::string& name() const noexcept = 0;
};

/// The format names open_event_writer() accepts, besides "auto".
inline constexpr std::string_view kOutputFormats = "ecd-text, csv, npy, aedat4, hdf5";

/// The output format for `path` by its extension: .txt -> ecd-text, .csv -> csv,
/// .npy -> npy, .aedat4 -> aedat4, .h5 / .hdf5 -> hdf5 (DSEC layout); "" when the extension says nothing.
std::string output_format_for(const std::string& path);

/// Creates `path` ("-" = standard output, text formats only) in `format` ("auto": by
/// extension, ecd-text when it says nothing). `sensor`: the sensor size for formats that
/// record one (AEDAT 4.0, HDF5; nullopt: the smallest holding every event). Throws OutputError.
std::unique_ptr<EventWriter> open_event_writer(const std::string& path, std::string_view format = "auto",
                                               std::optional<SensorSize> sensor = std::nullopt);

}  // namespace evcorner::io
