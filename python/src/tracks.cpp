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
#include "evcorner/eval/track_metrics.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/track/track_file.hpp"
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

/// Track samples from an (N, 4) float array of id, t [s], x, y.
std::vector<TrackPoint> points_from(const py::object& obj, const char* what) {
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
    if (!a || a.ndim() != 2 || a.shape(1) != 4)
        throw py::value_error(std::string(what) + ": expected an (N, 4) array of id, t [s], x, y");
    const auto r = a.unchecked<2>();
    std::vector<TrackPoint> out;
    out.reserve(static_cast<std::size_t>(a.shape(0)));
    for (py::ssize_t i = 0; i < a.shape(0); ++i) {
        const double id = r(i, 0);
        if (!(id >= 0) || id != std::floor(id) || id >= 1.8e19)
            throw py::value_error(std::string(what) + ": row " + std::to_string(i) + ": id must be a whole number >= 0");
        if (!std::isfinite(r(i, 1)) || !std::isfinite(r(i, 2)) || !std::isfinite(r(i, 3)))
            throw py::value_error(std::string(what) + ": row " + std::to_string(i) + ": t, x and y must be finite");
        out.push_back({static_cast<std::uint64_t>(id), r(i, 1), r(i, 2), r(i, 3)});
    }
    return out;
}

py::array points_array(const std::vector<TrackPoint>& pts) {
    py::array_t<double> a(std::vector<py::ssize_t>{static_cast<py::ssize_t>(pts.size()), 4});
    auto w = a.mutable_unchecked<2>();
    for (std::size_t i = 0; i < pts.size(); ++i) {
        const auto k = static_cast<py::ssize_t>(i);
        w(k, 0) = static_cast<double>(pts[i].id);
        w(k, 1) = pts[i].t;
        w(k, 2) = pts[i].x;
        w(k, 3) = pts[i].y;
    }
    return a;
}

py::dict eval_tracks(const py::object& pred, const py::object& gt, bool asynchronous, double associate_px,
                     const py::object& seeds, bool align) {
    const std::vector<TrackPoint> p = points_from(pred, "pred"), g = points_from(gt, "gt");
    std::vector<TrackPoint> sd;
    if (!seeds.is_none()) sd = points_from(seeds, "seeds");
    eval::TrackMetricOptions o;
    o.asynchronous = asynchronous;
    o.associate_px = associate_px;
    o.align_start = align;
    o.seeds = sd;
    eval::TrackEvaluation r;
    {
        py::gil_scoped_release release;
        r = eval::evaluate_tracks(p, g, o);
    }
    py::list tracks;
    for (const eval::TrackScore& s : r.tracks)
        tracks.append(py::dict(py::arg("id") = s.id, py::arg("gt_id") = s.gt_id, py::arg("skipped") = s.skipped,
                               py::arg("fa_5") = s.skipped ? py::object(py::none()) : py::object(py::float_(s.age[4])),
                               py::arg("te_5") = s.has_error_5 ? py::object(py::float_(s.error_5)) : py::object(py::none())));
    return py::dict(py::arg("fa") = r.fa, py::arg("efa") = r.efa, py::arg("fa_5") = r.fa_5, py::arg("te_5") = r.te_5,
                    py::arg("inlier_ratio") = r.inlier_ratio, py::arg("age") = r.age,
                    py::arg("inlier_mean") = r.inlier_mean, py::arg("inlier_std") = r.inlier_std,
                    py::arg("age_mean") = r.age_mean, py::arg("age_std") = r.age_std,
                    py::arg("predicted_tracks") = r.predicted_tracks, py::arg("gt_tracks") = r.gt_tracks,
                    py::arg("counted_tracks") = r.counted_tracks, py::arg("skipped_tracks") = r.skipped_tracks,
                    py::arg("unmatched_tracks") = r.unmatched_tracks, py::arg("time_shift_s") = r.time_shift_s,
                    py::arg("tracks") = tracks);
}

py::dict track_statistics(const py::object& tracks) {
    const eval::TrackStatistics s = eval::track_statistics(points_from(tracks, "tracks"));
    return py::dict(py::arg("tracks") = s.tracks, py::arg("samples") = s.samples,
                    py::arg("lifetime_median_s") = s.lifetime_median_s, py::arg("lifetime_mean_s") = s.lifetime_mean_s,
                    py::arg("length_median_px") = s.length_median_px, py::arg("length_mean_px") = s.length_mean_px,
                    py::arg("jitter_rms_px") = s.jitter_rms_px, py::arg("jitter_samples") = s.jitter_samples);
}

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
    m.def("eval_tracks", &eval_tracks, py::arg("pred"), py::arg("gt"), py::arg("asynchronous"),
          py::arg("associate_px"), py::arg("seeds"), py::arg("align"));
    m.def("track_statistics", &track_statistics, py::arg("tracks"));
    m.def("read_track_points", [](const std::string& path) { return points_array(read_track_points(path)); },
          py::arg("path"));
}

}  // namespace evcorner::python
