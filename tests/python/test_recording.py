"""evcorner.Events: the sensor size travels with the events (read -> detect -> write)."""

import pickle
import subprocess

import numpy as np
import pytest

import evcorner
from conftest import SAMPLE, SOURCE, cli_detect

def _events(xs, ys, sensor=None):
    """Events at (x, y), 1 ms apart, alternating polarity."""
    a = np.zeros(len(xs), evcorner.EVENT_DTYPE)
    a["t"] = np.arange(len(xs)) * 1000
    a["x"], a["y"] = xs, ys
    a["p"] = np.arange(len(xs)) % 2
    return evcorner.as_events(a, sensor=sensor)


def _small_sensor_file(tmp_path):
    """The sample's events that lie on a 128x128 sensor, in an AEDAT 4.0 file that records it."""
    whole = evcorner.read(SAMPLE)
    events = whole[(whole["x"] < 128) & (whole["y"] < 128)]
    path = tmp_path / "small.aedat4"
    evcorner.write(path, events, sensor=(128, 128))
    return path


def test_read_and_chunks_carry_the_files_sensor(tmp_path, cli):
    path = _small_sensor_file(tmp_path)
    events = evcorner.read(path)
    assert isinstance(events, evcorner.Events)
    assert events.sensor == (128, 128) and events.format == "aedat4"
    assert events.metadata["source"] == str(path) and events.metadata["damaged"] is None
    for chunk in evcorner.open(path, n_events=5000):
        assert isinstance(chunk, evcorner.Events) and chunk.sensor == (128, 128) and chunk.format == "aedat4"
    summary, cli_mask = cli_detect(cli, path, "efast", tmp_path)
    assert (summary["width"], summary["height"]) == (128, 128)
    mask = evcorner.detect(events)  # on the sensor the events carry
    np.testing.assert_array_equal(mask, cli_mask)
    # (The sensor matters: the 240x180 default gives another mask on these events.)
    assert not np.array_equal(evcorner.detect(events, sensor=(240, 180)), cli_mask)


@pytest.mark.parametrize("ext", ["h5", "aedat4"])
def test_write_records_the_carried_sensor(tmp_path, ext):
    events = _events([0, 319, 100, 250], [0, 239, 50, 200], sensor=(320, 240))
    path = tmp_path / f"w.{ext}"
    evcorner.write(path, events)
    back = evcorner.read(path)
    assert back.sensor == (320, 240)
    np.testing.assert_array_equal(back, events)
    evcorner.write(path, events, sensor=(640, 480))  # an explicit sensor wins
    assert evcorner.read(path).sensor == (640, 480)


def test_write_without_a_sensor_records_what_convert_does(tmp_path, cli):
    fits = _events([0, 239], [0, 179]).view(np.ndarray)  # a plain array: no sensor
    evcorner.write(tmp_path / "fits.h5", fits)
    assert evcorner.read(tmp_path / "fits.h5").sensor == (240, 180)
    text = tmp_path / "big.txt"
    text.write_text("0.000001 1 2 1\n0.000002 300 4 0\n0.000003 5 250 1\n")
    events = evcorner.read(text, fallback_sensor=None)
    assert events.sensor is None
    with pytest.warns(RuntimeWarning, match="bounding box 301x251"):
        evcorner.write(tmp_path / "py.h5", events)
    subprocess.run([cli, "convert", str(text), str(tmp_path / "cli.h5"), "-q"], check=True, capture_output=True)
    assert evcorner.read(tmp_path / "py.h5").sensor == evcorner.read(tmp_path / "cli.h5").sensor == (301, 251)


def test_write_refuses_events_off_the_sensor(tmp_path):
    events = _events([0, 150, 10], [0, 20, 30])
    path = tmp_path / "w.h5"
    with pytest.raises(evcorner.InvalidEvent, match=r"event 1 \(t=1000 x=150 .* off the 100x100 sensor"):
        evcorner.write(path, events, sensor=(100, 100))
    assert not path.exists()
    moved = evcorner.as_events(events, sensor=(240, 180)).copy()
    moved["x"][2] = 240  # now off the sensor it carries
    with pytest.raises(evcorner.InvalidEvent, match=r"event 2 .* off the 240x180 sensor"):
        evcorner.write(tmp_path / "w.txt", moved)
    assert not (tmp_path / "w.txt").exists()


def test_detect_defaults_to_the_carried_sensor():
    rng = np.random.default_rng(5)
    n = 3000
    events = _events(rng.integers(0, 320, n), rng.integers(0, 240, n), sensor=(320, 240))
    np.testing.assert_array_equal(evcorner.detect(events), evcorner.EFast(320, 240).process(events))
    np.testing.assert_array_equal(evcorner.detect(events, "harris", sensor=(640, 480)),
                                  evcorner.Harris(640, 480).process(events))
    with pytest.raises(evcorner.InvalidEvent, match="240x180"):
        evcorner.detect(events.view(np.ndarray))  # a plain array: the CLI's 240x180


def test_as_events_attaches_a_sensor_without_copying():
    plain = _events([1, 2, 3], [4, 5, 6]).view(np.ndarray)
    events = evcorner.as_events(plain, sensor="64x32")
    assert events.sensor == (64, 32) and np.shares_memory(events, plain)
    assert evcorner.as_events(events).sensor == (64, 32)  # kept
    with pytest.raises(evcorner.InvalidEvent, match=r"event 2 .* off the 3x32 sensor"):
        evcorner.as_events(plain, sensor=(3, 32))
    with pytest.raises(ValueError, match="sensor"):
        evcorner.as_events(plain, sensor="64by32")


def test_events_behave_as_arrays_and_keep_their_sensor():
    events = _events(np.arange(10), np.arange(10), sensor=(16, 16))
    for view in (events[2:5], events[events["x"] > 4], events[::2].copy(), events.copy()):
        assert isinstance(view, evcorner.Events) and view.sensor == (16, 16)
    for plain in (events["t"], events[["x", "y"]], events == events):
        assert type(plain) is np.ndarray
    assert "sensor=16x16" in repr(events)
    back = pickle.loads(pickle.dumps(events))
    assert back.sensor == (16, 16) and back.metadata == events.metadata
    np.testing.assert_array_equal(back, events)
    evcorner.EFast(16, 16).process(events)


def test_simulate_gives_events_on_the_scene_sensor():
    events, sensor = evcorner.simulate(str(SOURCE / "data" / "scenes" / "square.json"))
    assert isinstance(events, evcorner.Events) and events.sensor == sensor
    np.testing.assert_array_equal(evcorner.detect(events), evcorner.detect(events, sensor=sensor))
