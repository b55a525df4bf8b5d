"""EVENT_DTYPE, reading, writing, chunks, foreign dtypes, bad input."""

import numpy as np
import pytest

import evcorner
from conftest import SAMPLE


def test_dtype_is_the_cpp_event_layout():
    dt = evcorner.EVENT_DTYPE
    layout = evcorner._evcorner._event_layout()
    assert dt.itemsize == layout["itemsize"] == 16
    assert dt.names == ("t", "x", "y", "p")
    for name, base in (("t", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "u1")):
        assert dt.fields[name][0] == np.dtype(base)
        assert dt.fields[name][1] == layout[name]


def test_read_matches_an_independent_parse_of_the_sample():
    events = evcorner.read(SAMPLE)
    assert events.dtype == evcorner.EVENT_DTYPE and events.flags.c_contiguous
    text = np.loadtxt(SAMPLE, max_rows=2000)
    assert len(events) == sum(1 for _ in open(SAMPLE))
    np.testing.assert_array_equal(events["x"][:2000], text[:, 1])
    np.testing.assert_array_equal(events["y"][:2000], text[:, 2])
    np.testing.assert_array_equal(events["p"][:2000], text[:, 3])
    assert np.abs(events["t"][:2000] - text[:, 0] * 1e6).max() <= 1.0


@pytest.mark.parametrize("ext", ["txt", "csv", "npy", "aedat4", "h5"])
def test_write_read_round_trip(tmp_path, ext):
    events = evcorner.read(SAMPLE)[:5000]
    path = tmp_path / f"events.{ext}"
    evcorner.write(path, events, sensor=(240, 180))
    back = evcorner.read(path)
    np.testing.assert_array_equal(back, events)


def test_chunks_by_count_are_the_whole_in_order():
    whole = evcorner.read(SAMPLE)
    chunks = list(evcorner.open(SAMPLE, n_events=7000))
    assert [len(c) for c in chunks[:-1]] == [7000] * (len(chunks) - 1)
    assert 0 < len(chunks[-1]) <= 7000
    np.testing.assert_array_equal(np.concatenate(chunks), whole)


def test_chunks_by_time_hold_their_slice():
    whole = evcorner.read(SAMPLE)
    dt = 20_000
    f = evcorner.open(SAMPLE, delta_t=dt)
    assert f.sensor == (240, 180) and f.format == "ecd-text"
    chunks = list(f)
    t0 = whole["t"][0]
    for k, c in enumerate(chunks):
        if len(c):
            assert c["t"].min() >= t0 + k * dt and c["t"].max() < t0 + (k + 1) * dt
    np.testing.assert_array_equal(np.concatenate(chunks), whole)
    assert len(chunks) == (whole["t"][-1] - t0) // dt + 1


def test_missing_file():
    with pytest.raises(FileNotFoundError):
        evcorner.read("/nonexistent/events.txt")


def test_damaged_file_names_file_and_line(tmp_path):
    path = tmp_path / "bad.txt"
    path.write_text("0.000001 1 2 1\n0.000002 3 4 0\n0.000003 x 4 0\n")
    with pytest.raises(evcorner.InputError, match=r"bad\.txt:3:"):
        evcorner.read(path)
    assert issubclass(evcorner.InputError, ValueError)


def test_events_outside_the_sensor(tmp_path):
    path = tmp_path / "big.txt"
    path.write_text("0.000001 1 2 1\n0.000002 300 4 0\n")
    with pytest.raises(evcorner.InputError, match=r"big\.txt:2:"):
        evcorner.read(path)
    events = evcorner.read(path, skip_invalid=True)
    assert len(events) == 1
    assert len(evcorner.read(path, sensor="640x480")) == 2


def test_unknown_reader_option():
    with pytest.raises(TypeError, match="unknown reader option 'colums'"):
        evcorner.read(SAMPLE, colums="t,x,y,p")


def _reference():
    e = np.zeros(4, evcorner.EVENT_DTYPE)
    e["t"] = [5, 10, 15, 20]
    e["x"] = [1, 2, 3, 65535]
    e["y"] = [4, 5, 6, 7]
    e["p"] = [1, 0, 1, 0]
    return e


@pytest.mark.parametrize("dtype,pol", [
    ([("x", "<u2"), ("y", "<u2"), ("p", "<i2"), ("t", "<i8")], [1, 0, 1, 0]),                 # Metavision
    ([("t", "<i8"), ("x", "<i8"), ("y", "<i8"), ("p", "<i8")], [1, -1, 1, -1]),                # tonic, -1/+1
    ([("x", "<i4"), ("y", "<i2"), ("t", "<i8"), ("p", "?")], [True, False, True, False]),     # tonic, bool
    ([("timestamp", "<i8"), ("x", "<u4"), ("y", "<i2"), ("polarity", "u1")], [1, 0, 1, 0]),  # dv-processing
])
def test_as_events_takes_foreign_dtypes_by_name(dtype, pol):
    ref = _reference()
    a = np.zeros(4, dtype)
    for k in ("t" if "t" in a.dtype.names else "timestamp", "x", "y"):
        a[k] = ref["t" if k == "timestamp" else k]
    a["polarity" if "polarity" in a.dtype.names else "p"] = pol
    out = evcorner.as_events(a)
    assert out.dtype == evcorner.EVENT_DTYPE
    np.testing.assert_array_equal(out, ref)


def test_as_events_plain_columns_and_units():
    ref = _reference()
    plain = np.stack([ref["x"], ref["y"], ref["p"], ref["t"] / 1e6], axis=1)
    np.testing.assert_array_equal(evcorner.as_events(plain, columns="x,y,p,t", time_unit="s"), ref)


def test_as_events_refuses_bad_values():
    a = np.zeros(3, [("t", "<i8"), ("x", "<i4"), ("y", "<i4"), ("p", "<i4")])
    a["x"] = [0, 70000, 1]
    with pytest.raises(ValueError, match="event 1: x outside 0..65535"):
        evcorner.as_events(a)
    a["x"] = 0
    a["p"] = [0, 1, 2]
    with pytest.raises(ValueError, match="event 2: polarity"):
        evcorner.as_events(a)
    with pytest.raises(ValueError, match="no field for 't'"):
        evcorner.as_events(np.zeros(2, [("x", "<u2"), ("y", "<u2"), ("p", "u1")]))
    with pytest.raises(TypeError):
        evcorner.as_events([1, 2, 3])


def test_numpy_operations_keep_the_layout():
    events = evcorner.read(SAMPLE)[:100]
    assert evcorner.EVENT_DTYPE.isalignedstruct
    for joined in (np.concatenate([events, events]), np.hstack([events, events]), np.append(events, events)):
        assert joined.dtype == evcorner.EVENT_DTYPE and joined.dtype.itemsize == 16
        assert evcorner._evcorner._address(joined) == joined.ctypes.data  # accepted in place, as every verb checks
