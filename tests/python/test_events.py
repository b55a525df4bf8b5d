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


# Times: float = seconds, integer = microseconds, unless time_unit names the unit.

def test_float_times_of_a_text_file_are_seconds_as_the_cli_reads_them(cli, tmp_path):
    # np.loadtxt of an ECD file (t in seconds, 9 decimals): the same events and corners as
    # the CLI's reading of that file.
    from conftest import cli_detect
    text = np.loadtxt(SAMPLE)
    events = evcorner.as_events(text)
    np.testing.assert_array_equal(events, evcorner.read(SAMPLE))
    summary, cli_mask = cli_detect(cli, SAMPLE, "efast", tmp_path)
    mask = evcorner.detect(events)
    assert int(mask.sum()) == summary["corners"] and summary["corners"] > 0
    np.testing.assert_array_equal(mask, cli_mask)


def test_float_seconds_round_as_the_text_reader_does(tmp_path):
    # Up to 9 decimals (nanoseconds), rounded to the nearest microsecond, halves away from zero.
    times = ["0.000001499", "0.000001500", "0.000002500", "0.123456789", "12.5", "51.980788001"]
    path = tmp_path / "t.txt"
    path.write_text("".join(f"{t} 1 2 1\n" for t in times))
    plain = np.array([[float(t), 1, 2, 1] for t in times])
    np.testing.assert_array_equal(evcorner.as_events(plain)["t"], evcorner.read(path)["t"])
    assert list(evcorner.as_events(plain)["t"][:3]) == [1, 2, 3]


def test_integer_times_follow_the_unit():
    a = np.zeros(4, [("t", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "u1")])
    a["t"] = [1499, 1500, 2500, 7000]
    assert list(evcorner.as_events(a)["t"]) == [1499, 1500, 2500, 7000]          # microseconds
    assert list(evcorner.as_events(a, time_unit="ns")["t"]) == [1, 2, 3, 7]       # nearest, halves up
    assert list(evcorner.as_events(a, time_unit="ms")["t"]) == [1499000, 1500000, 2500000, 7000000]
    a["t"] = [-1500, -1499, 0, 1]
    assert list(evcorner.as_events(a, time_unit="ns")["t"]) == [-2, -1, 0, 0]    # halves away from zero
    assert list(a["t"]) == [-1500, -1499, 0, 1]  # the input is left as it was
    a["t"] = [1500, 2499, 2500, 7]
    assert list(evcorner.as_events(a, time_unit="ns")["t"]) == [2, 2, 3, 0]
    assert list(a["t"]) == [1500, 2499, 2500, 7]
    a["t"] = [0, 1, 2, 2**62]
    with pytest.raises(ValueError, match="event 3: t overflows"):
        evcorner.as_events(a, time_unit="s")


def test_float_times_in_a_named_unit():
    plain = np.array([[51980.788001, 1, 2, 1], [51980.7885, 1, 2, 0]])
    assert list(evcorner.as_events(plain, time_unit="ms")["t"]) == [51980788, 51980789]
    plain[:, 0] = [3.0, 4.0]
    assert list(evcorner.as_events(plain, time_unit="us")["t"]) == [3, 4]
    plain[:, 0] = [1500.0, 2499.0]
    assert list(evcorner.as_events(plain, time_unit="ns")["t"]) == [2, 2]
    plain[:, 0] = [1e10, -8.9e12]  # seconds beyond int64 nanoseconds, within int64 microseconds
    assert list(evcorner.as_events(plain)["t"]) == [10**16, -89 * 10**17]
    f32 = np.zeros(2, [("t", "<f4"), ("x", "<u2"), ("y", "<u2"), ("p", "u1")])
    f32["t"] = [0.5, 0.25]  # float32 seconds: within its own precision
    assert list(evcorner.as_events(f32)["t"]) == [500000, 250000]


@pytest.mark.parametrize("times,unit,message", [
    ([0.1, 0.2, 0.5], "us", r"every time is below 1 with time_unit='us'.*time_unit='s'"),
    ([1.0, 2.5, 3.0], "us", r"event 1: t = 2\.5 has a fraction of a microsecond \(time_unit='us'"),
    ([0.5, 0.1234567891234], None, r"event 1: t = .* more than 9 decimals of seconds \(time_unit=None"),
    ([1.0, 2.0000000001], "s", r"event 1: .* more than 9 decimals of seconds \(time_unit='s'"),
    ([1.5, 2.0], "ns", r"event 0: t = 1\.5 has a fraction of a nanosecond"),
    ([1.0, 1.00000012], "ms", r"event 1: .* more than 6 decimals of milliseconds"),
    ([1.0, np.nan], None, r"event 1: t is not a finite number"),
    ([1.0, -9.1e12], None, r"event 1: t is out of range: \|t\| must be below 9e18 us \(time_unit=None"),
])
def test_float_times_that_cannot_follow_the_rule_are_errors(times, unit, message):
    plain = np.array([[t, 1, 2, 1] for t in times])
    with pytest.raises(ValueError, match=message) as info:
        evcorner.as_events(plain, time_unit=unit)
    if "nan" not in message and "finite" not in message:
        assert "float times are seconds" in str(info.value)  # the rule is stated


def test_as_events_refuses_an_unknown_unit():
    with pytest.raises(ValueError, match="time_unit must be one of"):
        evcorner.as_events(np.zeros((1, 4)), time_unit="sec")
    events = evcorner.read(SAMPLE)[:3]
    assert evcorner.as_events(events, time_unit="us") is not None
    with pytest.raises(ValueError, match="times are microseconds; time_unit='ns' does not apply"):
        evcorner.as_events(events, time_unit="ns")


# evcorner's own .npy (t, x, y, p, '_' V3), loaded and memory-mapped: read in place.

def _npy_of_sample(tmp_path, cli):
    import subprocess
    path = tmp_path / "events.npy"
    subprocess.run([cli, "convert", str(SAMPLE), str(path), "-q"], check=True)
    return path


def test_own_npy_is_read_in_place(tmp_path, cli):
    path = _npy_of_sample(tmp_path, cli)
    whole = evcorner.read(SAMPLE)
    expected = evcorner.detect(whole)
    for mode in (None, "r"):
        loaded = np.load(path, mmap_mode=mode)
        assert loaded.dtype.names == ("t", "x", "y", "p", "_") and loaded.dtype != evcorner.EVENT_DTYPE
        np.testing.assert_array_equal(evcorner.detect(loaded), expected)
        det = evcorner.EFast(240, 180)
        det.process(loaded[1000:])
        assert det.last_address == loaded[1000:].ctypes.data  # C++ read the loaded memory itself
        events = evcorner.as_events(loaded)
        assert np.shares_memory(events, loaded) and events.ctypes.data == loaded.ctypes.data
        assert events.dtype == evcorner.EVENT_DTYPE
        np.testing.assert_array_equal(events, whole)
        out = tmp_path / f"back{mode}.txt"
        evcorner.write(out, loaded)
        np.testing.assert_array_equal(evcorner.read(out), whole)
    mm = np.load(path, mmap_mode="r")
    assert not mm.flags.writeable
    events = evcorner.as_events(mm)
    assert not events.flags.writeable and np.shares_memory(events, mm)


@pytest.mark.parametrize("dtype", [
    {"names": ["t", "x", "y", "p", "z"], "formats": ["<i8", "<u2", "<u2", "u1", "<u2"],
     "offsets": [0, 8, 10, 12, 12], "itemsize": 16},                                        # overlaps p
    {"names": ["t", "x", "y", "p"], "formats": [">i8", "<u2", "<u2", "u1"], "offsets": [0, 8, 10, 12],
     "itemsize": 16},                                                                      # big-endian t
    {"names": ["t", "x", "y", "p"], "formats": ["<i8", "<u2", "<u2", "u1"], "offsets": [0, 10, 8, 12],
     "itemsize": 16},                                                                      # x, y swapped
    {"names": ["t", "x", "y", "p", "_"], "formats": ["<i8", "<u2", "<u2", "u1", "O"],
     "offsets": [0, 8, 10, 12, 16], "itemsize": 24},                                        # 24 bytes
])
def test_other_layouts_are_not_read_in_place(dtype):
    a = np.zeros(3, np.dtype(dtype))
    with pytest.raises(TypeError, match="as_events"):
        evcorner.EFast(240, 180).process(a)


# Damaged input: the events before the damage are delivered, then the error.

def _damaged(tmp_path, n=59_065):
    path = tmp_path / "damaged.txt"
    rng = np.random.default_rng(3)
    xs, ys, ps = rng.integers(0, 240, n), rng.integers(0, 180, n), rng.integers(0, 2, n)
    path.write_text("".join(f"{i * 1e-5:.6f} {x} {y} {p}\n" for i, (x, y, p) in enumerate(zip(xs, ys, ps)))
                    + "0.9 x 1 1\n")
    return path, n


def test_the_last_chunk_before_damage_is_delivered_then_the_error(tmp_path):
    path, n = _damaged(tmp_path)
    chunks = []
    f = evcorner.open(path, n_events=50_000)
    with pytest.raises(evcorner.InputError, match=rf"damaged\.txt:{n + 1}:"):
        for chunk in f:
            chunks.append(chunk)
    assert [len(c) for c in chunks] == [50_000, n - 50_000]
    with pytest.raises(evcorner.InputError, match=rf"damaged\.txt:{n + 1}:"):
        next(f)  # and again: the input stays broken
    by_time = []
    with pytest.raises(evcorner.InputError, match=rf"damaged\.txt:{n + 1}:"):
        for chunk in evcorner.open(path, delta_t=100_000):
            by_time.append(chunk)
    assert sum(len(c) for c in by_time) == n
    with pytest.raises(evcorner.InputError, match=rf"damaged\.txt:{n + 1}:"):
        evcorner.read(path)


def test_allow_damaged_ends_the_input_at_the_damage(tmp_path):
    path, n = _damaged(tmp_path)
    with pytest.warns(RuntimeWarning, match=rf"damaged\.txt:{n + 1}:.*the {n} events before it"):
        events = evcorner.read(path, allow_damaged=True)
    assert len(events) == n and f"damaged.txt:{n + 1}:" in events.metadata["damaged"]
    np.testing.assert_array_equal(events["x"][:5], np.loadtxt(path, max_rows=5)[:, 1])
    f = evcorner.open(path, n_events=50_000, allow_damaged=True)
    with pytest.warns(RuntimeWarning):
        assert [len(c) for c in f] == [50_000, n - 50_000]
    assert f"damaged.txt:{n + 1}:" in f.damaged
    intact = evcorner.open(SAMPLE, allow_damaged=True)
    assert len(intact.read_all()) > 0 and intact.damaged is None


def test_format_lists_are_tuples():
    assert isinstance(evcorner.INPUT_FORMATS, tuple) and isinstance(evcorner.OUTPUT_FORMATS, tuple)
    assert {"ecd-text", "csv", "npy", "aedat2", "aedat4", "hdf5"} <= set(evcorner.INPUT_FORMATS)
    assert {"ecd-text", "csv", "npy", "aedat4", "hdf5"} == set(evcorner.OUTPUT_FORMATS)
    assert all(name and name == name.strip() for name in evcorner.INPUT_FORMATS)


def test_a_file_cut_short_delivers_its_events_then_the_error(tmp_path):
    # A binary format: a .npy whose data ends 20 000 events (and 7 bytes) into the 30 000 declared.
    events = evcorner.read(SAMPLE)
    path = tmp_path / "cut.npy"
    evcorner.write(path, events)
    header = path.stat().st_size - 16 * len(events)
    with path.open("r+b") as f:
        f.truncate(header + 16 * 20_000 + 7)
    chunks = []
    with pytest.raises(evcorner.InputError, match=r"cut\.npy: byte \d+: the file ends after 20000 of the 30000"):
        for chunk in evcorner.open(path, n_events=25_000):
            chunks.append(chunk)
    assert [len(c) for c in chunks] == [20_000]
    np.testing.assert_array_equal(chunks[0], events[:20_000])
    with pytest.warns(RuntimeWarning, match="the file ends after 20000"):
        np.testing.assert_array_equal(evcorner.read(path, allow_damaged=True), events[:20_000])


def test_threads_sharing_a_file_get_each_event_once():
    # The reader is read with the GIL released: without its lock, threads sharing it lose,
    # repeat or corrupt events (or crash).
    import threading
    whole = np.sort(evcorner.read(SAMPLE), order=["t", "x", "y", "p"])
    for _ in range(10):
        f = evcorner.open(SAMPLE, n_events=37)
        got = [[] for _ in range(4)]

        def drain(out):
            for chunk in f:
                out.append(chunk)

        threads = [threading.Thread(target=drain, args=(g,)) for g in got]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        chunks = [c for g in got for c in g]
        assert sum(len(c) for c in chunks) == len(whole)
        np.testing.assert_array_equal(np.sort(np.concatenate(chunks), order=["t", "x", "y", "p"]), whole)


def test_numpy_operations_keep_the_layout():
    events = evcorner.read(SAMPLE)[:100]
    assert evcorner.EVENT_DTYPE.isalignedstruct
    for joined in (np.concatenate([events, events]), np.hstack([events, events]), np.append(events, events)):
        assert joined.dtype == evcorner.EVENT_DTYPE and joined.dtype.itemsize == 16
        assert evcorner._evcorner._address(joined) == joined.ctypes.data  # accepted in place, as every verb checks


def test_reader_errors_name_python_keywords(tmp_path):
    """Reader messages reaching Python name its keywords, not the CLI's flags."""
    outside = tmp_path / "outside.txt"
    outside.write_text("0.1 1 2 1\n0.2 300 5 1\n")
    with pytest.raises(evcorner.InputError) as e:
        evcorner.read(outside)
    assert "set sensor=, or skip_invalid=True to skip" in str(e.value), str(e.value)
    mixed = tmp_path / "mixed.csv"
    mixed.write_text("100,1,1,1\n100.5,1,1,1\n")
    with pytest.raises(evcorner.InputError) as e:
        evcorner.read(mixed)
    assert "(time_unit sets the unit)" in str(e.value) and "--" not in str(e.value), str(e.value)
    with pytest.raises(ValueError) as e:
        evcorner.read(mixed, aedat2_chip="DVS128")
    assert "aedat2_chip applies to aedat2 files; this file is csv" in str(e.value), str(e.value)
