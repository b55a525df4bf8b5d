"""evcorner.track / evcorner.Tracker against the CLI's `evcorner track`, and chunking."""

import os
import subprocess

import numpy as np
import pytest

import evcorner

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLE = os.path.join(HERE, "..", "..", "data", "ecd", "shapes_translation", "events.txt")
CLI = os.environ.get("EVCORNER_CLI")


def sample():
    return evcorner.read(SAMPLE)


def test_detector_seeded_tracks_match_the_cli(tmp_path):
    if not CLI:
        pytest.skip("EVCORNER_CLI not set")
    ev = sample()
    states = evcorner.track(ev, "haste-correlation-star", detector="arcstar")
    assert len(states) > 100
    out = tmp_path / "t.csv"
    subprocess.run([CLI, "track", SAMPLE, "--tracker", "haste-correlation-star", "-d", "arcstar", "-o", str(out),
                    "-q"], check=True)
    rows = np.loadtxt(out, delimiter=",", skiprows=1, usecols=(0, 1, 2, 3))
    assert rows.shape[0] == len(states)
    np.testing.assert_array_equal(rows[:, 0].astype(np.uint64), states["id"])
    np.testing.assert_array_equal(np.round(rows[:, 1] * 1e6).astype(np.int64), states["t"])
    np.testing.assert_allclose(rows[:, 2], states["x"], atol=1e-6)


def test_chunking_does_not_change_the_tracks():
    ev = sample()
    whole = evcorner.track(ev, "haste-difference-star", detector="efast", init="uncentered")
    t = evcorner.Tracker("haste-difference-star", detector="efast", init="uncentered")
    parts = [t.process(ev[i:i + 777]) for i in range(0, len(ev), 777)]
    np.testing.assert_array_equal(np.concatenate(parts), whole)
    assert t.stats()["initialised"] > 0


def test_seeded_tracker_and_errors():
    ev = sample()
    first = ev[500]
    seeds = np.array([[first["t"] / 1e6, first["x"], first["y"], 0.0, 7]])
    states = evcorner.track(ev, "haste-correlation", seeds=seeds, init="uncentered")
    assert set(states["id"]) <= {7}
    with pytest.raises(ValueError, match="exactly one"):
        evcorner.Tracker("haste-correlation")
    with pytest.raises(ValueError, match="unknown tracker"):
        evcorner.Tracker("klt", detector="efast")
    with pytest.raises(ValueError, match="time order"):
        evcorner.track(ev[::-1].copy(), detector="efast")
