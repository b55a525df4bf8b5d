// Bindings of the tracking part (track/tracker.hpp): a Tracker class that keeps its state
// across calls, fed chunk by chunk, optionally with a detector in front whose corner
// events seed tracks.

#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eval.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/track/tracker.hpp"

namespace py = pybind11;

namespace evcorner::python {

namespace {

py::dtype track_dtype() {
    return py::reinterpret_steal<py::dtype>(
        py::module_::import("numpy")
            .attr("dtype")(py::eval("[('id', '<u8'), ('t', '<i8'), ('x', '<f4'), ('y', '<f4'), ('theta', '<f4'), "
                                    "('change', 'u1')]"))
            .release());
}

/// Seeds from an (N, 4) or (N, 5) float array of t (seconds), x, y, theta[, id] (HASTE's
/// seeds file as numbers; ids 0.. in order when absent).
std::vector<TrackSeed> seeds_from(const py::object& obj) {
    std::vector<TrackSeed> seeds;
    if (obj.is_none()) return seeds;
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
    if (!a || a.ndim() != 2 || (a.shape(1) != 4 && a.shape(1) != 5))
        throw py::value_error("seeds: expected an (N, 4) or (N, 5) array of t [s], x, y, theta [, id]");
    const auto r = a.unchecked<2>();
    for (py::ssize_t i = 0; i < a.shape(0); ++i) {
        const double t = r(i, 0);
        if (!std::isfinite(t) || std::fabs(t) >= 9e12)
            throw py::value_error("seeds: row " + std::to_string(i) + ": time must be finite seconds");
        const double id = a.shape(1) == 5 ? r(i, 4) : static_cast<double>(i);
        if (!(id >= 0) || id != std::floor(id) || id >= 1.8e19)
            throw py::value_error("seeds: row " + std::to_string(i) + ": id must be a whole number >= 0");
        seeds.push_back({std::llround(t * 1e6), static_cast<float>(r(i, 1)), static_cast<float>(r(i, 2)),
                         static_cast<float>(r(i, 3)), static_cast<std::uint64_t>(id)});
    }
    return seeds;
}

class PyTracker {
public:
    PyTracker(const std::string& name, const py::object& seeds, const std::optional<std::string>& detector,
              const std::string& init, int width, int height, double seed_radius, std::size_t max_tracks,
              std::optional<double> max_idle_ms, std::optional<double> min_separation)
        : size_(checked_sensor_size({width, height}, "tracker")) {
        TrackerConfig c;
        c.seeds = seeds_from(seeds);
        if (init != "centered" && init != "uncentered")
            throw py::value_error("init: 'centered' or 'uncentered', not '" + init + "'");
        c.init = init == "centered" ? HasteInit::centered : HasteInit::uncentered;
        c.seed_radius = static_cast<float>(seed_radius);
        c.max_tracks = max_tracks;
        if (detector) {
            detector_.emplace(make_detector(*detector, size_));
            c.seed_from_corners = true;
            c.stop.max_idle_us = 200000;  // the front end's defaults, as `evcorner track -d`
            c.stop.min_separation = 3;
        } else if (c.seeds.empty()) {
            throw py::value_error("a tracker needs seeds or a detector to seed from");
        }
        if (max_idle_ms) c.stop.max_idle_us = std::llround(*max_idle_ms * 1000);
        if (min_separation) c.stop.min_separation = *min_separation;
        tracker_ = tracker_entry(name).make(size_, c);
    }

    py::array process(py::handle events) {
        // A private copy: the array may change under us once the GIL is released.
        const std::span<const Event> view = events_view(events);
        std::vector<Event> ev(view.begin(), view.end());
        std::vector<TrackState> out;
        {
            py::gil_scoped_release release;
            std::vector<std::uint8_t> corner(ev.size(), 0);
            if (detector_) detect(*detector_, ev, corner);
            for (std::size_t i = 0; i < ev.size(); ++i)
                for (const TrackState& s : tracker_->process(ev[i], corner[i] != 0)) out.push_back(s);
        }
        py::array a(track_dtype(), std::vector<py::ssize_t>{static_cast<py::ssize_t>(out.size())});
        auto* p = static_cast<char*>(a.mutable_data());
        for (const TrackState& s : out) {
            std::memcpy(p, &s.id, 8);
            std::memcpy(p + 8, &s.t, 8);
            std::memcpy(p + 16, &s.x, 4);
            std::memcpy(p + 20, &s.y, 4);
            std::memcpy(p + 24, &s.theta, 4);
            p[28] = static_cast<char>(s.why);
            p += 29;
        }
        return a;
    }

    py::dict stats() const {
        const TrackerStats s = tracker_->stats();
        return py::dict(py::arg("started") = s.started, py::arg("initialised") = s.initialised,
                        py::arg("skipped_seeds") = s.skipped_seeds, py::arg("updates") = s.updates,
                        py::arg("live") = s.live);
    }

private:
    SensorSize size_;
    std::optional<AnyDetector> detector_;
    std::unique_ptr<Tracker> tracker_;
};

}  // namespace

void export_tracks(py::module_& m) {
    m.attr("TRACK_DTYPE") = track_dtype();
    py::list names;
    for (const TrackerEntry& t : tracker_registry()) names.append(py::make_tuple(std::string(t.name), std::string(t.summary)));
    m.attr("TRACKERS") = names;
    py::class_<PyTracker>(m, "Tracker")
        .def(py::init<const std::string&, const py::object&, const std::optional<std::string>&, const std::string&, int,
                      int, double, std::size_t, std::optional<double>, std::optional<double>>(),
             py::arg("name"), py::arg("seeds"), py::arg("detector"), py::arg("init"), py::arg("width"),
             py::arg("height"), py::arg("seed_radius"), py::arg("max_tracks"), py::arg("max_idle_ms"),
             py::arg("min_separation"))
        .def("process", &PyTracker::process, py::arg("events"))
        .def("stats", &PyTracker::stats);
}

}  // namespace evcorner::python
