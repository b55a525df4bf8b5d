#pragma once
// What the binding files (one per library part: module.cpp, tracks.cpp) share.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <span>

#include "evcorner/event.hpp"

namespace evcorner::python {

/// The events of `obj` (a 1-D contiguous array of evcorner.EVENT_DTYPE's layout) in place,
/// or a TypeError / ValueError saying why not.
std::span<const Event> events_view(pybind11::handle obj, const char* what = "events");

/// Trackers: evcorner.Tracker (HASTE and the front end), the track-state dtype.
void export_tracks(pybind11::module_& m);

}  // namespace evcorner::python
