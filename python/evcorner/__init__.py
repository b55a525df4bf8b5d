"""evcorner: corner detection on event-camera streams, over numpy arrays without copies.

Events are numpy structured arrays of ``EVENT_DTYPE`` (t int64 microseconds, x, y uint16,
p uint8; 16 bytes, the C++ ``evcorner::Event``), which the C++ library reads in place;
``evcorner.Events`` (what read() returns) is such an array that carries its sensor size.

    import evcorner
    events = evcorner.read("events.txt")                    # every format the CLI reads
    mask = evcorner.detect(events, "harris", harris_window=7)  # on events.sensor
    corners = events[mask.view(bool)]
    det = evcorner.EFast(240, 180)                          # stateful: chunk by chunk
    for chunk in evcorner.open("events.txt", n_events=100_000):
        m = det.process(chunk)

docs/python.md describes every function; ``python3 -m evcorner batch`` runs many
recordings and detectors on Dask distributed (evcorner.batch).
"""

from . import _evcorner
from ._evcorner import (
    EVENT_DTYPE,
    INPUT_FORMATS,
    OUTPUT_FORMATS,
    Detector,
    InputError,
    InvalidEvent,
    OutputError,
    StateTooLarge,
    ft_percent,
    reduction_rate,
)
from ._events import EventFile, Events, as_events, open, read, write  # noqa: A004 (open, like io.open)
from ._detectors import DETECTOR_CLASSES, detect, detect_file, detectors, evaluate_truth, label, simulate
from ._tracks import TRACK_DTYPE, TRACKERS, Tracker, eval_tracks, track, track_statistics

__version__ = "0.1.0"

# One class per registered detector (EFast, Harris, HarrisGlobal, ArcStar, ...), generated
# from the C++ registry: a detector added there appears here without an edit.
globals().update(DETECTOR_CLASSES)

__all__ = [
    "EVENT_DTYPE",
    "INPUT_FORMATS",
    "OUTPUT_FORMATS",
    "Detector",
    "EventFile",
    "Events",
    "InputError",
    "InvalidEvent",
    "OutputError",
    "StateTooLarge",
    "TRACKERS",
    "TRACK_DTYPE",
    "Tracker",
    "as_events",
    "detect",
    "detect_file",
    "detectors",
    "eval_tracks",
    "evaluate_truth",
    "ft_percent",
    "label",
    "open",
    "read",
    "reduction_rate",
    "simulate",
    "track",
    "track_statistics",
    "write",
    *DETECTOR_CLASSES,
]
