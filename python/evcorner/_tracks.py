"""Feature trackers on event streams (the C++ tracker registry; docs/tracking.md)."""

from __future__ import annotations

import numpy as np

from . import _evcorner
from ._events import as_events

TRACK_DTYPE = _evcorner.TRACK_DTYPE
TRACKERS = tuple(name for name, _ in _evcorner.TRACKERS)


class Tracker:
    """A tracker that keeps its state across calls: feed it the stream chunk by chunk.

    name: one of TRACKERS ("haste-correlation-star", ...). seeds: an (N, 4) or (N, 5) array
    of t [s], x, y, theta [rad] [, id] (HASTE's seeds), or detector: a registered detector
    whose corner events start tracks (a corner farther than seed_radius px from every
    track starts one; at most max_tracks at once). init: "centered" or "uncentered".
    max_idle_ms / min_separation: stopping rules (defaults 200 ms / 3 px with a detector,
    none with seeds). process(events) returns the states those events produced as a
    TRACK_DTYPE array (id, t in us, x, y, theta, change 0 initialised / 1 moved / 2 stopped).
    """

    def __init__(self, name="haste-correlation-star", *, seeds=None, detector=None, init="centered",
                 width=240, height=180, seed_radius=10.0, max_tracks=200, max_idle_ms=None,
                 min_separation=None):
        if (seeds is None) == (detector is None):
            raise ValueError("give exactly one of seeds= and detector=")
        self._t = _evcorner.Tracker(name, None if seeds is None else np.asarray(seeds, dtype=float), detector,
                                    init, int(width), int(height), float(seed_radius), int(max_tracks),
                                    max_idle_ms, min_separation)

    def process(self, events) -> np.ndarray:
        return self._t.process(events)

    def stats(self) -> dict:
        """started, initialised, skipped_seeds, updates (event-track pairs), live."""
        return self._t.stats()


def track(events, tracker="haste-correlation-star", *, seeds=None, detector=None, **kwargs) -> np.ndarray:
    """Tracks over a whole stream: Tracker(tracker, ...).process(events) in one call.

    events: an EVENT_DTYPE array (other layouts go through as_events first).
    """
    ev = events if getattr(events, "dtype", None) == _evcorner.EVENT_DTYPE else as_events(events)
    return Tracker(tracker, seeds=seeds, detector=detector, **kwargs).process(ev)
