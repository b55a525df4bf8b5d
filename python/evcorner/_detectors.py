"""Detectors (one class per registry entry), one-call detection, evaluation, simulation."""

import inspect
import os

import numpy as np

from . import _evcorner
from ._evcorner import Detector
from ._events import _as_recording, _input_path, _size, reader_options

#: The DAVIS240C, the sensor the CLI assumes for formats without one (text, CSV).
DAVIS240 = (240, 180)


def detectors():
    """Every registered detector, in the registry's order: dicts with name, class_name,
    summary, has_score, local and params (key, name (the keyword), type, default, min, max, help)."""
    return _evcorner.detectors()


def _detector_repr(self):
    """The call that builds this detector: its class, sensor and the parameters given (in the
    registry's order)."""
    cls = type(self)
    order = [p["name"] for d in _evcorner.detectors() if d["name"] == self.name for p in d["params"]]
    given = self.params
    params = {k: given[k] for k in sorted(given, key=lambda k: order.index(k) if k in order else len(order))}
    if getattr(cls, "registry_name", None) == self.name:
        text = "".join(f", {k}={v!r}" for k, v in params.items())
        return f"{cls.__name__}({self.sensor[0]}, {self.sensor[1]}{text})"
    return f"{cls.__name__}({self.name!r}, {self.sensor[0]}, {self.sensor[1]}, {params!r})"


def _detector_copy(self):
    new = type(self).__new__(type(self))
    Detector.__init__(new, self)
    return new


def _detector_deepcopy(self, memo):
    new = _detector_copy(self)
    memo[id(self)] = new
    return new


def _detector_reduce(self):
    if self.events:
        raise TypeError(f"cannot pickle {self!r} after it has processed events ({self.events}): the state of a C++ "
                        f"detector has no serialised form; copy.deepcopy() copies it within a process, and a "
                        f"detector that has processed nothing (or after reset()) pickles")
    return (_rebuild, (type(self), self.name, self.sensor, self.params))


def _rebuild(cls, name, sensor, params):
    if getattr(cls, "registry_name", None) == name:
        return cls(*sensor, **params)
    return cls(name, *sensor, params)


# Copies carry the state (the C++ copy constructor); pickles carry the configuration.
Detector.__repr__ = _detector_repr
Detector.__copy__ = _detector_copy
Detector.__deepcopy__ = _detector_deepcopy
Detector.__reduce__ = _detector_reduce


def _make_class(info):
    name = info["name"]
    lines = [
        f"{p['name']}={p['default']!r}  ({p['type']}"
        + ("" if p["type"] == "true/false" else f", {p['min']:g}..{p['max']:g}")
        + f"): {p['help']}"
        for p in info["params"]
    ]

    def __init__(self, width, height, **params):
        Detector.__init__(self, name, width, height, params)

    __init__.__doc__ = f"{info['class_name']}(width, height, **params): the '{name}' detector on a width x height sensor."
    # help() and inspect show the registry's keywords with their defaults and types.
    P = inspect.Parameter
    types = {"integer": int, "number": float, "true/false": bool}
    __init__.__signature__ = inspect.Signature(
        [P("self", P.POSITIONAL_OR_KEYWORD), P("width", P.POSITIONAL_OR_KEYWORD, annotation=int),
         P("height", P.POSITIONAL_OR_KEYWORD, annotation=int)]
        + [P(p["name"], P.KEYWORD_ONLY, default=p["default"], annotation=types.get(p["type"], P.empty))
           for p in info["params"]],
        return_annotation=None)
    doc = (
        f"{info['summary']}\n\n"
        f"Registry name '{name}'. process(events, out=None) -> uint8 mask; state is kept across calls, "
        f"and events must come in time order across them (InvalidEvent otherwise; reset() starts anew)."
        + (" process_scored(events) -> (mask, scores)." if info["has_score"] else "")
        + "\n\nKeyword parameters (default, range): "
        + ("\n    " + "\n    ".join(lines) if lines else "none")
    )
    return type(
        info["class_name"],
        (Detector,),
        {"__init__": __init__, "__doc__": doc, "__module__": "evcorner", "registry_name": name},
    )


DETECTOR_CLASSES = {info["class_name"]: _make_class(info) for info in _evcorner.detectors()}


def detect(events, detector="efast", sensor=None, scores=False, out=None, **params):
    """Runs `detector` (a registry name) over EVENT_DTYPE `events` in one call, read in
    place: returns the uint8 mask (1 = corner), or (mask, scores) with scores=True.
    `sensor` = (width, height); None: the one the events carry (evcorner.Events, e.g. from
    read()), else the DAVIS240C's 240x180 as in the CLI. Events off the sensor or out of time
    order raise evcorner.InvalidEvent naming the event."""
    if sensor is None:
        sensor = getattr(events, "sensor", None) or DAVIS240
    w, h = _size(sensor, "sensor")
    det = Detector(detector, w, h, params)
    if scores:
        return det.process_scored(events, out)
    return det.process(events, out)


def detect_file(input, output=None, detector="efast", mask=None, format="auto", to="auto", with_score=False,
                threads=1, allow_damaged=False, reader=None, **params):
    """`evcorner detect` as a function: the library's pipeline from the file `input` to the
    corner file `output` (None: none) and the mask file `mask` (one 0/1 line per event).
    `reader`: a dict of reader options (READER_OPTIONS). Returns the summary as the CLI's
    --summary-json writes it (input, detector, width, height, events, corners, ...).
    Damaged input raises, and then leaves no output file (allow_damaged=True: the outputs
    of the events before the damage, and the summary's 'damaged' names it)."""
    return _evcorner.detect_file(
        _input_path(input),
        "" if output is None else os.fspath(output),
        detector,
        params,
        reader_options(**(reader or {})),
        format,
        to,
        "" if mask is None else os.fspath(mask),
        with_score,
        threads,
        allow_damaged,
    )


def label(corners, **ft_params):
    """Feature-track labels of corner events (Mueggler et al. 2017; docs/evaluation.md):
    returns (on_track uint8 array, dict with corners, on_track, ft_percent, hypotheses,
    accepted). Keywords: inner_radius, outer_radius, min_inner, max_outer_ratio,
    max_duration_us, max_length, same_polarity, overlap ("any"/"exclusive"), cell_size."""
    p = _evcorner.FeatureTrackParams()
    for key, value in ft_params.items():
        if key.startswith("_") or not hasattr(p, key):
            raise TypeError(f"label: unknown parameter {key!r}")
        setattr(p, key, value)
    return _evcorner.label(corners, p)


def simulate(scene):
    """Simulates a scene (a JSON file path, or JSON text starting with '{'; docs/simulate.md):
    returns (events, (width, height)), the events an evcorner.Events carrying that sensor."""
    if isinstance(scene, str) and scene.lstrip().startswith("{"):
        events, sensor = _evcorner.simulate(scene, False)
    else:
        events, sensor = _evcorner.simulate(_input_path(scene), True)
    return _as_recording(events, sensor), sensor


def evaluate_truth(events, corners, truth, radius=3.5, tolerance_us=1000, credit="all", interpolation="linear",
                   speed_bins=None):
    """Corner events against a simulated scene's ground truth (the truth CSV of
    ``evcorner simulate --truth``), as ``evcorner eval --truth`` judges them
    (docs/evaluation.md, "Against ground truth"): precision, recall, localisation error.

    `corners` is either the detector's uint8/bool mask over `events` (as detect() returns
    it) or the corner events themselves (EVENT_DTYPE, time order; `events` may then be
    None). The keywords are eval's options: radius = --match-radius (px), tolerance_us =
    --match-tolerance (us), credit = --match-credit ("all"/"nearest"), interpolation =
    --match-interpolation ("linear"/"nearest"), speed_bins = --speed-bins (edges in px/s,
    from 0; None: 0,50,100,200,400,700). The truth is streamed, never all in memory; the GIL
    is released while matching.

    Returns a dict with the keys of results.json's "truth" object (truth, true_positives,
    precision_percent, truth_samples, recalled, recall_percent, loc_median_px,
    loc_mean_px, loc_p90_px, speed_bins) plus corner_events, events (len(events), or None),
    is_true (uint8 per corner event) and errors (float32 px per true positive, in order)."""
    if isinstance(corners, np.ndarray) and corners.dtype.names and _evcorner._has_event_layout(corners.dtype):
        corner_events = corners
    else:
        if events is None:
            raise TypeError("evaluate_truth: a mask needs the events it marks (events=None)")
        mask = np.asarray(corners)
        if mask.ndim != 1 or mask.dtype not in (np.dtype(np.uint8), np.dtype(np.bool_)):
            raise TypeError(f"evaluate_truth: corners must be a 1-D uint8/bool mask or EVENT_DTYPE corner events, "
                            f"got {mask.dtype} with {mask.ndim} dimension(s)")
        if len(mask) != len(events):
            raise ValueError(f"evaluate_truth: the mask has {len(mask)} entries for {len(events)} events")
        _evcorner._address(events)  # the same checks (dtype, stride) as every verb
        corner_events = events[mask != 0]  # the corners only: one copy of a small part
    bins = None if speed_bins is None else [float(b) for b in speed_bins]
    r = _evcorner.evaluate_truth(corner_events, _input_path(truth), float(radius), int(tolerance_us), credit,
                                 interpolation, bins)
    r["events"] = None if events is None else len(events)
    return r
