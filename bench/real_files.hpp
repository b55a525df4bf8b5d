#pragma once
// The real 240x180 recordings the eFAST and detector benchmarks run on: the nine
// Event-Camera-Dataset cuts (eight ecd-stppp sequences and slider_depth) and the two
// DAVIS240C AEDAT 2.0 recordings of ../shared/data, each with its golden eFAST index.

#include <filesystem>
#include <string>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/open.hpp"

namespace evcorner::bench {

struct RealFile {
    std::string name;                   ///< the sequence or recording name
    std::filesystem::path events;       ///< the recording
    std::filesystem::path golden;       ///< its golden eFAST corner indices
    bool ecd = false;                   ///< an Event-Camera-Dataset text cut
};

/// The 11 files under `data` (../shared/data), or none when it is not there.
inline std::vector<RealFile> real_240x180_files(const std::filesystem::path& data) {
    std::vector<RealFile> files;
    if (!std::filesystem::is_directory(data / "real/ecd-stppp")) return files;
    for (const char* seq : {"boxes_rotation", "boxes_translation", "dynamic_rotation", "dynamic_translation",
                            "poster_rotation", "poster_translation", "shapes_rotation", "shapes_translation"})
        files.push_back({seq, data / "real/ecd-stppp" / seq / "events.txt",
                         data / "golden" / (std::string("ecd-stppp.") + seq + ".efast.idx"), true});
    files.push_back({"slider_depth", data / "real/ecd-slider-depth-eventsviz/slider_depth/events_chunk.txt",
                     data / "golden/ecd-slider-depth-eventsviz.slider_depth.efast.idx", true});
    for (const char* rec : {"IMU_rotDisk", "IMU_translBoxes"})
        files.push_back({rec, data / "real/davis240c-imu-pyaedattools" / (std::string(rec) + ".aedat"),
                         data / "golden" / (std::string("davis240c-imu-pyaedattools.") + rec + ".efast.idx"), false});
    return files;
}

/// Every event of a file, in any format evcorner reads.
inline std::vector<Event> load_events(const std::filesystem::path& file) {
    const auto reader = io::open_event_reader(file.string());
    return io::read_all_events(*reader);
}

}  // namespace evcorner::bench
