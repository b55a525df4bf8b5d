"""evaluate_truth: the ground-truth evaluation of `evcorner eval --truth`, from Python."""

import csv
import json
import shutil
import subprocess

import numpy as np
import pytest

import evcorner
from conftest import SOURCE

SCENES = SOURCE / "data" / "scenes"


@pytest.fixture(scope="module")
def scene(cli, tmp_path_factory):
    """A small simulated scene written by the CLI: NAME.json, NAME.npy and NAME.truth.csv
    side by side (so that eval finds the sensor in the scene file, as for simulate --suite)."""
    d = tmp_path_factory.mktemp("truth")
    shutil.copy(SCENES / "polygons.json", d / "scene.json")
    subprocess.run([cli, "simulate", str(d / "scene.json"), "-o", str(d / "scene.npy"), "--truth",
                    str(d / "scene.truth.csv"), "-q"], check=True)
    return d


def cli_eval(cli, scene, detector, out, options=()):
    subprocess.run([cli, "eval", str(scene / "scene.npy"), "--truth", str(scene / "scene.truth.csv"), "-d", detector,
                    "--repeat", "1", "--report", str(out), "--no-figures", "-q", *options],
                   check=True, capture_output=True)
    (run,) = json.loads((out / "results.json").read_text())["runs"]
    with open(out / "truth_table.csv", newline="") as f:
        (row,) = list(csv.DictReader(f))
    return run, row


def python_eval(scene, detector, **match):
    events, sensor = evcorner.simulate(str(scene / "scene.json"))
    np.testing.assert_array_equal(events, evcorner.read(scene / "scene.npy"))  # the events eval reads
    mask = evcorner.detect(events, detector, sensor=sensor)
    return events, mask, evcorner.evaluate_truth(events, mask, scene / "scene.truth.csv", **match)


KEYS = ("true_positives", "precision_percent", "truth_samples", "recalled", "recall_percent", "loc_median_px",
        "loc_mean_px", "loc_p90_px", "speed_bins")

CASES = [
    ("efast", {}, ()),
    ("harris", {}, ()),
    ("efast", dict(radius=2.0, tolerance_us=300, credit="nearest", interpolation="nearest",
                   speed_bins=[0, 20, 60, 150]),
     ("--match-radius", "2", "--match-tolerance", "300", "--match-credit", "nearest", "--match-interpolation",
      "nearest", "--speed-bins", "0,20,60,150")),
]


@pytest.mark.parametrize("detector,match,options", CASES, ids=["efast", "harris", "efast-options"])
def test_equals_eval_truth(cli, scene, tmp_path, detector, match, options):
    run, row = cli_eval(cli, scene, detector, tmp_path / "report", options)
    events, mask, r = python_eval(scene, detector, **match)
    truth = run["truth"]
    assert r["corner_events"] == run["corners"] == int(mask.sum()) > 0
    assert r["events"] == run["events"] == len(events)
    for key in KEYS:  # results.json keeps doubles exactly
        assert r[key] == truth[key], key
    assert r["true_positives"] > 0 and r["recalled"] > 0  # a scene that tests something
    assert len(r["speed_bins"]) == (len(match["speed_bins"]) if "speed_bins" in match else 6)
    # truth_table.csv: the same figures, rounded as it prints them
    assert int(row["true_positives"]) == r["true_positives"]
    assert int(row["truth_samples"]) == r["truth_samples"] and int(row["recalled"]) == r["recalled"]
    for col, key in (("precision_percent", "precision_percent"), ("recall_percent", "recall_percent"),
                     ("loc_median_px", "loc_median_px"), ("loc_mean_px", "loc_mean_px"),
                     ("loc_p90_px", "loc_p90_px")):
        assert float(row[col]) == pytest.approx(r[key], abs=5e-5), col
    # the per-event arrays agree with the counts
    assert len(r["is_true"]) == r["corner_events"] and int(r["is_true"].sum()) == r["true_positives"]
    assert len(r["errors"]) == r["true_positives"]
    assert float(np.median(r["errors"])) == pytest.approx(r["loc_median_px"], abs=0.5)
    assert np.all(r["errors"] <= match.get("radius", 3.5))


def test_mask_and_corner_events_agree(scene, tmp_path):
    events, mask, by_mask = python_eval(scene, "efast")
    by_events = evcorner.evaluate_truth(None, events[mask.view(bool)], scene / "scene.truth.csv")
    assert by_events["events"] is None
    for key in KEYS + ("corner_events",):
        assert by_events[key] == by_mask[key], key
    np.testing.assert_array_equal(by_events["is_true"], by_mask["is_true"])
    # the corner events as evcorner's own .npy gives them back (the '_' padding field)
    corners_npy = tmp_path / "corners.npy"
    evcorner.write(corners_npy, events[mask.view(bool)])
    from_npy = evcorner.evaluate_truth(None, np.load(corners_npy, mmap_mode="r"), scene / "scene.truth.csv")
    for key in KEYS + ("corner_events",):
        assert from_npy[key] == by_mask[key], key
    # a bool mask is the same as the uint8 one; no corners: nothing true, nothing recalled
    assert evcorner.evaluate_truth(events, mask.view(bool), scene / "scene.truth.csv")["recalled"] == by_mask["recalled"]
    none = evcorner.evaluate_truth(events, np.zeros(len(events), np.uint8), scene / "scene.truth.csv")
    assert none["corner_events"] == none["true_positives"] == none["recalled"] == 0
    assert none["truth_samples"] == by_mask["truth_samples"] > 0


def test_refusals(scene, tmp_path):
    events, mask, _ = python_eval(scene, "efast")
    truth = scene / "scene.truth.csv"
    with pytest.raises(FileNotFoundError):
        evcorner.evaluate_truth(events, mask, tmp_path / "missing.truth.csv")
    lines = truth.read_text().splitlines()
    damaged = tmp_path / "damaged.truth.csv"
    damaged.write_text("\n".join(lines[:5] + ["12,0,0,not-a-number,1,90,0,0,0,1,visible"] + lines[5:]) + "\n")
    with pytest.raises(evcorner.InputError, match=r"damaged\.truth\.csv:6"):
        evcorner.evaluate_truth(events, mask, damaged)
    with pytest.raises(ValueError, match="radius"):
        evcorner.evaluate_truth(events, mask, truth, radius=0)
    with pytest.raises(ValueError):
        evcorner.evaluate_truth(events, mask, truth, credit="some")
    with pytest.raises(ValueError):
        evcorner.evaluate_truth(events, mask, truth, speed_bins=[10, 20])
    with pytest.raises(ValueError, match="entries for"):
        evcorner.evaluate_truth(events, mask[:-1], truth)
    with pytest.raises(TypeError):
        evcorner.evaluate_truth(events, mask.astype(np.int32), truth)
    with pytest.raises(TypeError):
        evcorner.evaluate_truth(None, mask, truth)
    corners = events[mask.view(bool)][::-1].copy()
    with pytest.raises(ValueError, match="not in time order at index"):
        evcorner.evaluate_truth(None, corners, truth)
