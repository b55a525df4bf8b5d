"""Shared fixtures: the CLI the package is compared with, the bundled sample, the real data."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

SOURCE = Path(os.environ.get("EVCORNER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SHARED = Path(os.environ.get("EVCORNER_SHARED_DIR", SOURCE.parent / "shared"))
SAMPLE = SOURCE / "data" / "ecd" / "shapes_translation" / "events.txt"


def cli_path():
    p = os.environ.get("EVCORNER_CLI") or str(SOURCE / "build" / "bin" / "evcorner")
    if not Path(p).exists():
        pytest.skip(f"the evcorner CLI is not built ({p})")
    return p


@pytest.fixture(scope="session")
def cli():
    return cli_path()


@pytest.fixture(scope="session")
def sample():
    return str(SAMPLE)


def cli_detect(cli, path, detector, tmp_path, params=()):
    """The CLI's summary and mask (uint8 array) for one file and detector."""
    mask = tmp_path / f"{detector}.mask"
    summary = tmp_path / f"{detector}.json"
    cmd = [cli, "detect", str(path), "-d", detector, "-o", str(tmp_path / f"{detector}.corners.txt"),
           "--mask", str(mask), "--summary-json", str(summary), "-q"]
    for key, value in params:
        cmd += ["-p", f"{key}={value}"]
    subprocess.run(cmd, check=True)
    return json.loads(summary.read_text()), np.loadtxt(mask, dtype=np.uint8).reshape(-1)
