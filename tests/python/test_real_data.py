"""Python on the real recordings of ../shared/data (skipped, and reported skipped by ctest,
when that folder is not beside the checkout)."""

import pytest

import evcorner
from conftest import SHARED, cli_detect

DVS128 = SHARED / "data" / "real" / "dvs128-walking-ouyang" / "alex_walking_for_10secs.aedat"

pytestmark = pytest.mark.skipif(not DVS128.exists(), reason=f"no {DVS128} (../shared/data is not beside the checkout)")


def test_dvs128_recording_read_then_detect_equals_the_cli(tmp_path, cli):
    events = evcorner.read(DVS128)
    assert events.sensor == (128, 128)
    summary, cli_mask = cli_detect(cli, DVS128, "efast", tmp_path)
    mask = evcorner.detect(events)
    assert int(mask.sum()) == summary["corners"]
    assert (mask == cli_mask).all()
