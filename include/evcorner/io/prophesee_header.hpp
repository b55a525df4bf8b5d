#pragma once
// The ASCII header of Prophesee files (RAW and DAT): lines "% key value", e.g.
//   % evt 3.0                          (RAW, older files)
//   % format EVT3;height=720;width=1280 (RAW, newer files)
//   % geometry 1280x720
//   % plugin_name hal_plugin_gen41_evk3
//   % Height 480 / % Width 640          (DAT)
//   % Data file containing Event2d events. (DAT)
//   % end                               (newer files: the last header line)
// The sensor size comes from the geometry keys, else from the HAL plugin / sensor
// generation the camera was read with.

#include <optional>
#include <string>
#include <string_view>

#include "evcorner/sensor.hpp"

namespace evcorner::io {

struct PropheseeHeader {
    std::string evt;          ///< "2.0", "3.0", "2.1" ("" when not stated)
    std::string plugin_name;  ///< e.g. "hal_plugin_gen3_fx3"
    std::string sensor_generation;
    std::optional<int> width, height;
    bool is_dat = false;      ///< "% Data file containing ..."
    bool ended = false;       ///< "% end" seen

    /// Takes one header line (with its leading '%').
    void add_line(std::string_view line);
    /// The sensor size the header states or implies.
    [[nodiscard]] std::optional<SensorSize> sensor() const;
};

}  // namespace evcorner::io
