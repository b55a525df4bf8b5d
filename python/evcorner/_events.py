"""Events in and out: files (read, open, write) and other libraries' arrays (as_events)."""

import errno
import os
import sys

import numpy as np

from . import _evcorner
from ._evcorner import EVENT_DTYPE

#: Keyword arguments of read() / open() / detect_file(reader_options=...): the CLI's reader options.
READER_OPTIONS = (
    "sensor",           # (width, height) or "WxH": validate against this, overriding the file's metadata
    "fallback_sensor",  # when neither sensor nor the file gives one (default (240, 180)); None: no check
    "skip_invalid",     # skip (and count) events outside the sensor instead of failing
    "csv_columns",      # CSV column order, e.g. "x,y,p,t"
    "aedat2_chip",      # AEDAT 2.0 camera (jAER chip name)
    "time_unit",        # CSV t column / .npy / .mat time unit: "us", "ns", "ms", "s"
    "npy_columns",      # meaning of a plain (N, 4) .npy array's columns
    "mat_var",          # MATLAB variable
    "mat_columns",      # its columns
    "topic",            # ROS bag topic
)


def _size(value, what):
    if value is None:
        return None
    if isinstance(value, str):
        w, sep, h = value.lower().partition("x")
        if sep and w.isdigit() and h.isdigit():
            return int(w), int(h)
        raise ValueError(f"{what}: expected 'WIDTHxHEIGHT' or (width, height), got {value!r}")
    try:
        w, h = value
        return int(w), int(h)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected 'WIDTHxHEIGHT' or (width, height), got {value!r}") from None


def reader_options(**kw):
    """The C++ ReaderOptions from keyword arguments (READER_OPTIONS); TypeError for others."""
    o = _evcorner.ReaderOptions()
    for key, value in kw.items():
        if key not in READER_OPTIONS:
            raise TypeError(f"unknown reader option {key!r} (known: {', '.join(READER_OPTIONS)})")
        if key in ("sensor", "fallback_sensor"):
            value = _size(value, key)
        setattr(o, key, value)
    return o


def _input_path(path):
    path = os.fspath(path)
    if path != "-" and not os.path.exists(path):
        raise FileNotFoundError(errno.ENOENT, "no such file", path)
    return path


class EventFile:
    """An open event file, iterated in chunks in constant memory (evcorner.open()).

    Exactly one of n_events (chunks of that many events; the last may be shorter) and
    delta_t (chunks of that many microseconds, from the first event's time; a slice
    without events gives an empty chunk) may be given; neither: n_events=100_000.
    A time chunk ends at the first event (in file order) at or after its end.
    """

    def __init__(self, path, n_events=None, delta_t=None, format="auto", **reader_opts):
        if n_events is not None and delta_t is not None:
            raise ValueError("give n_events or delta_t, not both")
        if n_events is None and delta_t is None:
            n_events = 100_000
        if n_events is not None and int(n_events) < 1:
            raise ValueError(f"n_events must be at least 1 (got {n_events})")
        if delta_t is not None and int(delta_t) < 1:
            raise ValueError(f"delta_t must be at least 1 us (got {delta_t})")
        self.n_events = None if n_events is None else int(n_events)
        self.delta_t = None if delta_t is None else int(delta_t)
        self._reader = _evcorner.Reader(_input_path(path), reader_options(**reader_opts), format)
        self._next_start = None

    sensor = property(lambda self: self._reader.sensor, doc="(width, height) validated against, or None")
    format = property(lambda self: self._reader.format, doc="the format read, e.g. 'ecd-text'")
    name = property(lambda self: self._reader.name)
    skipped = property(lambda self: self._reader.skipped, doc="events skipped (skip_invalid=True)")

    def __iter__(self):
        return self

    def __next__(self):
        if self.n_events is not None:
            chunk = self._reader.read_count(self.n_events)
            if len(chunk) == 0:
                raise StopIteration
            return chunk
        t = self._reader.peek_time()
        if t is None:
            raise StopIteration
        if self._next_start is None:
            self._next_start = t
        end = self._next_start + self.delta_t
        self._next_start = end
        return self._reader.read_until(end)

    def read_all(self):
        """Every event not yet read, in one array."""
        return self._reader.read_count(sys.maxsize)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def open(path, n_events=None, delta_t=None, format="auto", **reader_opts):  # noqa: A001
    """Opens an event file of any format the CLI reads; iterate it for chunks (EventFile)."""
    return EventFile(path, n_events=n_events, delta_t=delta_t, format=format, **reader_opts)


def read(path, format="auto", **reader_opts):
    """Every event of the file at `path` (any format the CLI reads; `format` forces one)
    as one EVENT_DTYPE array. Raises FileNotFoundError, evcorner.InputError (ValueError)
    naming the file and the position of damage."""
    return EventFile(path, n_events=1, format=format, **reader_opts).read_all()


def write(path, events, format="auto", sensor=None):
    """Writes EVENT_DTYPE events to `path` in `format` (auto: by extension: .txt, .csv,
    .npy, .aedat4, .h5/.hdf5). `sensor` is recorded by the formats with a field for it."""
    _evcorner.write(os.fspath(path), events, format, _size(sensor, "sensor"))


_ALIASES = {
    "t": ("t", "ts", "timestamp", "timestamps", "time"),
    "x": ("x",),
    "y": ("y",),
    "p": ("p", "polarity", "pol", "polarities"),
}
_TIME_SCALE = {"us": 1, "ns": 1e-3, "ms": 1e3, "s": 1e6}


def _field(names, which):
    for alias in _ALIASES[which]:
        for n in names:
            if n.lower() == alias:
                return n
    raise ValueError(f"as_events: no field for {which!r} (tried {', '.join(_ALIASES[which])}; fields: {', '.join(names)})")


def as_events(array, time_unit="us", columns="t,x,y,p"):
    """Converts other libraries' events to a new EVENT_DTYPE array: ONE copy.

    Structured arrays are matched by field name, in any order and of any integer types
    (Metavision's x,y,p,t; tonic's; dv-processing's timestamp,x,y,polarity): t from
    t / ts / timestamp, p from p / polarity (bool, 0/1, or -1/+1 with -1 = OFF). A plain
    (N, 4) array is read by `columns`. Times in `time_unit` ("us", "ns", "ms", "s"; float
    times are rounded to the nearest microsecond). An EVENT_DTYPE array is returned as it
    is when contiguous (else copied once). Raises ValueError for a value out of range
    (naming its index), TypeError for a non-array.
    """
    if not isinstance(array, np.ndarray):
        raise TypeError(f"as_events: expected a numpy array, got {type(array).__name__}")
    if time_unit not in _TIME_SCALE:
        raise ValueError(f"as_events: time_unit must be one of {', '.join(_TIME_SCALE)} (got {time_unit!r})")
    if array.dtype == EVENT_DTYPE:
        return array if array.flags.c_contiguous and array.ndim == 1 else np.ascontiguousarray(array).reshape(-1)
    if array.dtype.names:
        if array.ndim != 1:
            raise ValueError(f"as_events: expected a 1-D structured array, got {array.ndim} dimensions")
        names = array.dtype.names
        cols = {k: array[_field(names, k)] for k in "txyp"}
    else:
        if array.ndim != 2 or array.shape[1] != 4:
            raise ValueError(f"as_events: expected a structured array or an (N, 4) array, got shape {array.shape}")
        order = [c.strip() for c in columns.split(",")]
        if sorted(order) != ["p", "t", "x", "y"]:
            raise ValueError(f"as_events: columns must name t, x, y, p once each (got {columns!r})")
        cols = {k: array[:, order.index(k)] for k in "txyp"}
    out = np.empty(len(cols["t"]), dtype=EVENT_DTYPE)
    out["t"] = _times(cols["t"], time_unit)
    for k in "xy":
        out[k] = _checked_int(cols[k], k, 0, 65535)
    out["p"] = _polarity(cols["p"])
    return out


def _first_bad(bad, what, values):
    i = int(np.flatnonzero(bad)[0])
    raise ValueError(f"as_events: event {i}: {what} (got {values[i]!r})")


def _checked_int(v, name, lo, hi):
    if v.dtype.kind == "f":
        bad = ~np.isfinite(v) | (v != np.rint(v))
        if bad.any():
            _first_bad(bad, f"{name} is not a whole number", v)
    elif v.dtype.kind not in "iub":
        raise TypeError(f"as_events: field {name} has dtype {v.dtype}, not a number")
    bad = (v < lo) | (v > hi)
    if bad.any():
        _first_bad(bad, f"{name} outside {lo}..{hi}", v)
    return v


def _times(t, unit):
    scale = _TIME_SCALE[unit]
    if t.dtype.kind in "iu" and scale == 1:
        if t.dtype == np.uint64 and len(t) and t.max() > np.iinfo(np.int64).max:
            _first_bad(t > np.iinfo(np.int64).max, "t beyond int64", t)
        return t
    if t.dtype.kind in "iu" and scale >= 1:
        return t.astype(np.int64) * int(scale)
    if t.dtype.kind in "iu":  # ns -> us, rounded down
        return t.astype(np.int64) // 1000
    if t.dtype.kind != "f":
        raise TypeError(f"as_events: field t has dtype {t.dtype}, not a number")
    us = np.rint(t.astype(np.float64) * scale)
    bad = ~np.isfinite(us) | (np.abs(us) > 9.2e18)
    if bad.any():
        _first_bad(bad, "t is not a finite time", t)
    return us.astype(np.int64)


def _polarity(p):
    if p.dtype.kind == "b":
        return p
    bad = (p != 0) & (p != 1) & (p != -1)
    if bad.any():
        _first_bad(bad, "polarity is not 0/1 or -1/+1", p)
    return p > 0

