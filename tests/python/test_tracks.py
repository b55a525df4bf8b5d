"""evcorner.track / evcorner.Tracker against the CLI's `evcorner track`, and chunking."""

import json
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


def test_eval_tracks_agrees_with_the_cli_and_takes_every_form(tmp_path):
    if not CLI:
        pytest.skip("EVCORNER_CLI not set")
    subprocess.run([CLI, "simulate", "--preset", "shapes", "-o", str(tmp_path / "ev.npy"), "--gt-tracks",
                    str(tmp_path / "gt.txt"), "-q"], check=True)
    gt_file = str(tmp_path / "gt.txt")
    gt = np.loadtxt(gt_file)  # id t x y
    ev = np.load(tmp_path / "ev.npy")
    firsts = {}
    for row in gt:
        firsts.setdefault(int(row[0]), row)
    seeds = np.array([[r[1], r[2], r[3], 0.0, i] for i, r in firsts.items()])
    pred = evcorner.track(ev, "haste-correlation-star", seeds=seeds, init="uncentered")
    assert set(pred["id"]) == set(firsts)
    out = tmp_path / "pred.txt"
    subprocess.run([CLI, "track", str(tmp_path / "ev.npy"), "--tracker", "haste-correlation-star", "--init",
                    "uncentered", "--seeds", gt_file, "-o", str(out), "-q"], check=True)
    cli = subprocess.run([CLI, "eval-tracks", str(out), gt_file, "--json", "-"], check=True, capture_output=True,
                         text=True)
    want = json.loads(cli.stdout)["metric"]
    for got in (evcorner.eval_tracks(pred, gt_file), evcorner.eval_tracks(str(out), gt),
                evcorner.eval_tracks(np.loadtxt(out), gt_file)):
        assert got["fa"] == pytest.approx(want["fa"], abs=1e-6)  # text rows have 6 decimals
        assert got["efa"] == pytest.approx(want["efa"], abs=1e-6)
        assert got["te_5"] == pytest.approx(want["te_5"], abs=1e-6)
        assert got["counted_tracks"] == want["counted_tracks"]
    perfect = evcorner.eval_tracks(gt, gt, asynchronous=True)
    assert perfect["fa"] == 1.0 and perfect["te_5"] == 0.0
    stats = evcorner.track_statistics(pred)
    assert stats["tracks"] == len(firsts)
    with pytest.raises(ValueError, match="fields id, t, x, y"):
        evcorner.eval_tracks(ev, gt)
    with pytest.raises(evcorner.InputError, match="nothing.txt"):
        evcorner.eval_tracks(str(tmp_path / "nothing.txt"), gt)
