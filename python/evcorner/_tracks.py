"""Feature trackers on event streams (the C++ tracker registry; docs/tracking.md)."""

from __future__ import annotations

import os

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


def _points(tracks, what) -> np.ndarray:
    """Track samples as an (N, 4) float array of id, t [s], x, y."""
    if isinstance(tracks, (str, os.PathLike)):
        return _evcorner.read_track_points(os.fspath(tracks))
    a = np.asarray(tracks)
    if a.dtype.names is not None:
        missing = [f for f in ("id", "t", "x", "y") if f not in a.dtype.names]
        if missing:
            raise ValueError(f"{what}: a structured array needs fields id, t, x, y (missing {', '.join(missing)})")
        t = a["t"]
        # integer times are microseconds (TRACK_DTYPE), float times seconds
        t = t / 1e6 if np.issubdtype(t.dtype, np.integer) else t.astype(float)
        return np.column_stack([a["id"].astype(float), t, a["x"].astype(float), a["y"].astype(float)])
    return a


def eval_tracks(pred, gt, *, asynchronous=False, associate_px=None, seeds=None, align=True) -> dict:
    """Predicted tracks against ground truth by the feature-track benchmark's metric.

    pred, gt: track files (paths in any layout evcorner reads), TRACK_DTYPE arrays (what
    track() returns), structured arrays with fields id, t, x, y (integer t in us, float t
    in s), or (N, 4) arrays of id, t [s], x, y. Matched by id (the prediction's times first
    shifted so that the first rows agree, unless align=False), by position within
    associate_px at each track's first sample, or through seeds (where each track was
    seeded: id, t, x, y in any of those forms; matched within associate_px, default 1 px).
    asynchronous: the variant in which a track holds its last position instead of the GT
    being cut.

    Returns a dict: fa, efa, fa_5, te_5, inlier_ratio and age (per threshold 1..31 px),
    their means and standard deviations, the track counts (predicted, gt, counted, skipped,
    unmatched), time_shift_s and per-track results (docs/tracking.md).
    """
    return _evcorner.eval_tracks(_points(pred, "pred"), _points(gt, "gt"), bool(asynchronous),
                                 0.0 if associate_px is None else float(associate_px),
                                 None if seeds is None else _points(seeds, "seeds"), bool(align))


def track_statistics(tracks) -> dict:
    """What tracks say without ground truth: count, samples, lifetime and path length
    (median, mean), jitter (RMS distance of each sample from the line between its
    neighbours). tracks: as for eval_tracks."""
    return _evcorner.track_statistics(_points(tracks, "tracks"))
