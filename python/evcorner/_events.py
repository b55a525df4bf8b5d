"""Events in and out: files (read, open, write) and other libraries' arrays (as_events)."""

import errno
import os
import sys
import warnings

import numpy as np

from . import _evcorner
from ._evcorner import EVENT_DTYPE

#: Keyword arguments of read() / open() / detect_file(reader_options=...): the checks, then the
#: CLI's reader options by the library's table (help(evcorner._evcorner.ReaderOptions) tells each).
READER_OPTIONS = (
    "sensor",           # (width, height) or "WxH": validate against this, overriding the file's metadata
    "fallback_sensor",  # when neither sensor nor the file gives one (default (240, 180)); None: no check
    "skip_invalid",     # skip (and count) events outside the sensor instead of failing
) + _evcorner.READER_OPTION_KEYWORDS


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


def _sensor_text(sensor):
    return "unknown" if sensor is None else f"{sensor[0]}x{sensor[1]}"


class Events(np.ndarray):
    """Events and the sensor they were recorded on: an EVENT_DTYPE numpy array (an ndarray
    subclass, read in place by every evcorner function) that carries

    - ``sensor``: (width, height), or None when unknown;
    - ``format``: the format it was read from ('ecd-text', 'aedat4', ...), or None;
    - ``metadata``: a dict (``source``: the file read, ``skipped``: events skipped with
      skip_invalid, ``damaged``: the error that ended a damaged input with allow_damaged).

    read(), open()'s chunks, as_events(sensor=...) and simulate() return one; detect()
    and write() take their sensor from it unless ``sensor=`` is given. Views and slices
    (``events[mask]``, ``events[1000:]``) keep the sensor; a field (``events["t"]``) and
    other non-event results are plain arrays. Pickled (Dask, multiprocessing) with the
    sensor and metadata. Make one from an EVENT_DTYPE array with
    ``evcorner.as_events(array, sensor=(w, h))`` (no copy).
    """

    _sensor = None
    _format = None
    _metadata = None

    def __array_finalize__(self, obj):
        self._sensor = getattr(obj, "_sensor", None)
        self._format = getattr(obj, "_format", None)
        self._metadata = getattr(obj, "_metadata", None)

    def __getitem__(self, key):
        out = super().__getitem__(key)
        if isinstance(out, Events) and out.dtype is not self.dtype and not _has_layout(out.dtype):
            return out.view(np.ndarray)  # a field, or several: not events
        return out

    def __array_wrap__(self, out, *args, **kwargs):
        # Comparisons (events == other) and similar give plain arrays, not Events.
        if out.dtype != self.dtype:
            return np.ndarray.__array_wrap__(self.view(np.ndarray), out.view(np.ndarray), *args, **kwargs)
        return super().__array_wrap__(out, *args, **kwargs)

    @property
    def sensor(self):
        """(width, height) of the sensor the events lie on, or None when unknown."""
        return self._sensor

    @property
    def format(self):
        """The format the events were read from, or None."""
        return self._format

    @property
    def metadata(self):
        """What is known of where the events come from (a dict; see the class)."""
        if self._metadata is None:
            self._metadata = {}
        return self._metadata

    def __reduce__(self):
        rebuild, args, state = super().__reduce__()
        return rebuild, args, (state, self._sensor, self._format, self._metadata)

    def __setstate__(self, state):
        base, self._sensor, self._format, self._metadata = state
        super().__setstate__(base)

    def __repr__(self):
        text = super().__repr__()
        return f"{text[:-1]}, sensor={_sensor_text(self._sensor)})" if text.endswith(")") else text


def _has_layout(dtype):
    return _evcorner._has_event_layout(dtype) if dtype.names else False


def _as_recording(array, sensor, format=None, metadata=None):
    """`array` (EVENT_DTYPE layout, 1-D) as Events on `sensor`, no copy."""
    ev = array.view(dtype=EVENT_DTYPE, type=Events)  # the same layout (e.g. evcorner's .npy dtype)
    ev._sensor = sensor
    ev._format = format
    ev._metadata = metadata
    return ev


class EventFile:
    """An open event file, iterated in chunks in constant memory (evcorner.open()).

    Exactly one of n_events (chunks of that many events; the last may be shorter) and
    delta_t (chunks of that many microseconds, from the first event's time; a slice
    without events gives an empty chunk) may be given; neither: n_events=100_000.
    A time chunk ends at the first event (in file order) at or after its end.
    Each chunk is an Events array carrying the file's sensor and format.

    Damaged input (a malformed line, a file cut short): the chunk that reaches the damage
    holds every event before it, and the next one raises evcorner.InputError naming the
    file and position. With allow_damaged=True the damage ends the input instead, with a
    warning (RuntimeWarning), and ``damaged`` holds the error's message.
    """

    def __init__(self, path, n_events=None, delta_t=None, format="auto", allow_damaged=False, **reader_opts):
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
        self._reader = _evcorner.Reader(_input_path(path), reader_options(**reader_opts), format,
                                        bool(allow_damaged))
        self._next_start = None
        self._events = 0
        self._warned = False

    sensor = property(lambda self: self._reader.sensor, doc="(width, height) validated against, or None")
    format = property(lambda self: self._reader.format, doc="the format read, e.g. 'ecd-text'")
    name = property(lambda self: self._reader.name)
    skipped = property(lambda self: self._reader.skipped, doc="events skipped (skip_invalid=True)")
    damaged = property(lambda self: self._reader.damaged,
                       doc="the error that ended a damaged input (allow_damaged=True), or None")

    def _chunk(self, array):
        self._events += len(array)
        damaged = self._reader.damaged
        if damaged is not None and not self._warned:
            self._warned = True
            warnings.warn(f"{damaged}; the {self._events} events before it are read", RuntimeWarning, stacklevel=3)
        return _as_recording(array, self._reader.sensor, self._reader.format,
                             {"source": self._reader.name, "skipped": self._reader.skipped, "damaged": damaged})

    def __iter__(self):
        return self

    def __next__(self):
        if self.n_events is not None:
            chunk = self._reader.read_count(self.n_events)
            if len(chunk) == 0:
                raise StopIteration
            return self._chunk(chunk)
        t = self._reader.peek_time()
        if t is None:
            raise StopIteration
        if self._next_start is None:
            self._next_start = t
        end = self._next_start + self.delta_t
        self._next_start = end
        return self._chunk(self._reader.read_until(end))

    def read_all(self):
        """Every event not yet read, in one Events array; damaged input raises (unless
        allow_damaged=True) rather than returning the events before the damage."""
        events = self._reader.read_count(sys.maxsize)
        self._reader.read_count(1)  # at the end: raises the error that ended the read, if any
        return self._chunk(events)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def open(path, n_events=None, delta_t=None, format="auto", allow_damaged=False, **reader_opts):  # noqa: A001
    """Opens an event file of any format the CLI reads; iterate it for chunks (EventFile):
    Events arrays carrying the file's sensor."""
    return EventFile(path, n_events=n_events, delta_t=delta_t, format=format, allow_damaged=allow_damaged,
                     **reader_opts)


def read(path, format="auto", allow_damaged=False, **reader_opts):
    """Every event of the file at `path` (any format the CLI reads; `format` forces one)
    as one Events array (EVENT_DTYPE, with .sensor and .format). Raises FileNotFoundError,
    evcorner.InputError (ValueError) naming the file and the position of damage; with
    allow_damaged=True, the events before the damage, with a RuntimeWarning and
    ``metadata["damaged"]`` naming it."""
    return EventFile(path, n_events=1, format=format, allow_damaged=allow_damaged, **reader_opts).read_all()


#: The sensor recorded for events whose sensor is unknown and that fit it (as `evcorner convert`).
_DAVIS240 = (240, 180)


def _sensor_to_record(events, sensor):
    """The sensor write() records: `sensor`, else the one the events carry, else (as
    `evcorner convert` for an input without one) 240x180 when every event fits it, else the
    events' bounding box, with a warning."""
    if sensor is not None:
        return _size(sensor, "write: sensor")
    carried = getattr(events, "sensor", None)
    if carried is not None:
        return carried
    if not isinstance(events, np.ndarray) or not _has_layout(events.dtype) or len(events) == 0:
        return _DAVIS240  # (the C++ side refuses what is not events)
    box = (int(events["x"].max()) + 1, int(events["y"].max()) + 1)
    if box[0] <= _DAVIS240[0] and box[1] <= _DAVIS240[1]:
        return _DAVIS240
    warnings.warn(f"write: the events carry no sensor and do not fit the {_sensor_text(_DAVIS240)} default; "
                  f"recording their bounding box {_sensor_text(box)} (pass sensor=(width, height) to record "
                  "the sensor's)", RuntimeWarning, stacklevel=3)
    return box


def write(path, events, format="auto", sensor=None):
    """Writes events (EVENT_DTYPE layout) to `path` in `format` (auto: by extension: .txt,
    .csv, .npy, .aedat4, .h5/.hdf5). The sensor, recorded by the formats with a field for it
    (AEDAT 4.0, HDF5), is `sensor` = (width, height), else the one the events carry (Events),
    else 240x180 when every event fits it, else their bounding box (with a RuntimeWarning),
    as `evcorner convert` records it. An event off that sensor (or with a polarity other than
    0/1) raises evcorner.InvalidEvent naming its index, before the file is created."""
    _evcorner.write(os.fspath(path), events, format, _sensor_to_record(events, sensor))


_ALIASES = {
    "t": ("t", "ts", "timestamp", "timestamps", "time"),
    "x": ("x",),
    "y": ("y",),
    "p": ("p", "polarity", "pol", "polarities"),
}
#: Microseconds per unit.
_TIME_SCALE = {"us": 1, "ns": 1e-3, "ms": 1e3, "s": 1e6}
#: The decimals a float time may have in each unit: down to the nanosecond, except that a
#: time declared in microseconds must be whole.
_TIME_DECIMALS = {"s": 9, "ms": 6, "us": 0, "ns": 0}
_TIME_RULE = ("float times are seconds and integer times microseconds unless time_unit names the unit; a float "
              "time has at most 9 decimals of seconds (6 of ms), whole microseconds or whole nanoseconds")


def _field(names, which):
    for alias in _ALIASES[which]:
        for n in names:
            if n.lower() == alias:
                return n
    raise ValueError(f"as_events: no field for {which!r} (tried {', '.join(_ALIASES[which])}; fields: {', '.join(names)})")


def as_events(array, time_unit=None, columns="t,x,y,p", sensor=None):
    """Other libraries' events as an Events array (EVENT_DTYPE): ONE copy, or none for
    an array that has the layout already.

    Structured arrays are matched by field name, in any order and of any integer types
    (Metavision's x,y,p,t; tonic's; dv-processing's timestamp,x,y,polarity): t from
    t / ts / timestamp, p from p / polarity (bool, 0/1, or -1/+1 with -1 = OFF). A plain
    (N, 4) array is read by `columns`.

    Times (the rule of docs/python.md, "Times"): without `time_unit`, float times are
    seconds and integer times microseconds; `time_unit` ("s", "ms", "us", "ns") names the
    unit of either. Times are rounded to the nearest microsecond (halves away from zero)
    from at most nanosecond digits: a float time with more than 9 decimals of seconds (6 of
    milliseconds), or a fraction of a microsecond with time_unit="us" (of a nanosecond with
    "ns") is a ValueError naming time_unit and the rule, never a silent rounding; when every
    time is below 1 with time_unit="us", it says they look like seconds.

    An array with EVENT_DTYPE's layout (EVENT_DTYPE itself, evcorner's .npy dtype with its
    '_' padding field, np.load(..., mmap_mode='r') of one) is returned as a view of the
    same memory when contiguous (else copied once). `sensor` = (width, height) (or
    "WxH") is carried by the result (default: the one `array` carries, if any); an event
    off it is a ValueError (evcorner.InvalidEvent) naming its index. Raises ValueError for
    a value out of range (naming its index), TypeError for a non-array.
    """
    if not isinstance(array, np.ndarray):
        raise TypeError(f"as_events: expected a numpy array, got {type(array).__name__}")
    if time_unit is not None and time_unit not in _TIME_SCALE:
        raise ValueError(f"as_events: time_unit must be one of {', '.join(_TIME_SCALE)} or None (got {time_unit!r})")
    sensor = _size(sensor, "as_events: sensor") if sensor is not None else getattr(array, "sensor", None)
    if array.dtype.names and _has_layout(array.dtype):
        if time_unit not in (None, "us"):
            raise ValueError(f"as_events: the array has EVENT_DTYPE's layout, whose times are microseconds; "
                             f"time_unit={time_unit!r} does not apply")
        if array.ndim != 1:
            raise ValueError(f"as_events: expected a 1-D array of events, got {array.ndim} dimensions")
        if not array.flags.c_contiguous or array.ctypes.data % 8:
            array = np.ascontiguousarray(array)
        out = _as_recording(array, sensor, getattr(array, "format", None), getattr(array, "_metadata", None))
    else:
        out = _as_recording(_converted(array, time_unit, columns), sensor)
    if sensor is not None:
        _evcorner._check_events(out, sensor)
    return out


def _converted(array, time_unit, columns):
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


def _nearest_us(v, div):
    """Integers `v` in units of 1/div us, to the nearest microsecond, halves away from zero."""
    if v.min() >= 0:
        return (v + div // 2) // div  # (a new array: v may be the caller's)
    q, r = np.divmod(v, div)  # floor division: 0 <= r < div
    up = (r > div // 2) | ((r == div // 2) & (v >= 0))
    return q + up


_INT64_MAX = np.iinfo(np.int64).max


def _times(t, unit):
    if t.dtype.kind == "u" and len(t) and t.max() > _INT64_MAX:
        _first_bad(t > _INT64_MAX, "t beyond int64", t)
    if t.dtype.kind in "iu":
        unit = unit or "us"
        v = t.astype(np.int64, copy=False)
        if unit == "ns":
            return _nearest_us(v, 1000)
        mul = int(_TIME_SCALE[unit])
        if mul > 1 and len(v) and (v.max() > _INT64_MAX // mul or v.min() < -_INT64_MAX // mul):
            _first_bad((v > _INT64_MAX // mul) | (v < -_INT64_MAX // mul), f"t overflows int64 microseconds "
                       f"(time_unit={unit!r})", t)
        return v * mul
    if t.dtype.kind != "f":
        raise TypeError(f"as_events: field t has dtype {t.dtype}, not a number")
    what = "time_unit=None: float times are seconds" if unit is None else f"time_unit={unit!r}"
    unit = unit or "s"
    finite = np.isfinite(t)
    if not finite.all():
        _first_bad(~finite, "t is not a finite number", t)
    if len(t) == 0:
        return np.zeros(0, np.int64)
    # Whole units of 1/10**decimals, within the rounding a float of t's type has at its value.
    # |t| of 9e18 microseconds (9e12 s) or more is out of range, as for the C++ readers.
    if not (max(float(t.max()), -float(t.min())) * _TIME_SCALE[unit] < 9e18):
        _first_bad(~(np.abs(t.astype(np.float64) * _TIME_SCALE[unit]) < 9e18),
                   f"t is out of range: |t| must be below 9e18 us ({what})", t)
    decimals = _TIME_DECIMALS[unit]
    scaled = np.multiply(t, 10.0 ** decimals, dtype=np.float64)
    exact = max(scaled.max(), -scaled.min()) < 9.2e18  # whole units fit int64
    whole = np.rint(scaled)
    # The rounding a float of t's type has at the largest time (at most a few ulps, in units).
    slack = 4.0 * float(np.spacing(t.dtype.type(max(t.max(), -t.min())))) * 10.0 ** decimals
    np.subtract(scaled, whole, out=scaled)
    np.abs(scaled, out=scaled)
    bad = scaled > slack
    if unit == "us" and bad.any() and (np.abs(t) < 1).all():
        raise ValueError(f"as_events: every time is below 1 with time_unit='us' (seconds declared as "
                         f"microseconds?); pass time_unit='s' or leave it None ({_TIME_RULE})")
    if bad.any():
        digits = {"s": "more than 9 decimals of seconds", "ms": "more than 6 decimals of milliseconds",
                  "us": "a fraction of a microsecond", "ns": "a fraction of a nanosecond"}[unit]
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"as_events: event {i}: t = {t[i]!r} has {digits} ({what}; {_TIME_RULE})")
    if not exact:  # beyond 292 years of nanoseconds a float holds no nanosecond digits
        us = t.astype(np.float64) * _TIME_SCALE[unit]
        return np.trunc(us + np.copysign(0.5, us)).astype(np.int64)  # halves away from zero
    v = whole.astype(np.int64)  # nanoseconds, or whole microseconds for "us"
    per_us = round(10 ** decimals / _TIME_SCALE[unit])  # 1000 units a microsecond, or 1 for "us"
    return v if per_us == 1 else _nearest_us(v, per_us)


def _polarity(p):
    if p.dtype.kind == "b":
        return p
    bad = (p != 0) & (p != 1) & (p != -1)
    if bad.any():
        _first_bad(bad, "polarity is not 0/1 or -1/+1", p)
    return p > 0

