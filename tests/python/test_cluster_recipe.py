"""The cluster recipe of docs/python.md ("On a cluster") as written, in a fresh venv made
and filled as README.md says: the three commands taken from the page, and
scripts/slurm-batch.sh under a stand-in `srun`. Every process listens on 127.0.0.1 and is
stopped at the end (its process group killed), whether the test passed or not.

Filling the venv compiles the extension in the checkout's build/pip (minutes the first
time, incremental after; CMAKE_ARGS may name a compiler launcher, as setup.py says)."""

import contextlib
import json
import os
import re
import shlex
import signal
import subprocess
import time
from pathlib import Path

import pytest

import evcorner
from conftest import SAMPLE, SOURCE

pytest.importorskip("distributed")

README = SOURCE / "README.md"
PYTHON_MD = SOURCE / "docs" / "python.md"
SLURM = SOURCE / "scripts" / "slurm-batch.sh"
DETECTORS = ["efast", "harris"]


def sh_block(markdown, after):
    """The lines of the first ```sh block after the heading or text `after`."""
    text = markdown[markdown.index(after):]
    body = re.search(r"```sh\n(.*?)```", text, re.S).group(1)
    return [line for line in body.splitlines() if line.strip()]


def command(line):
    """A documented command line without its trailing comment."""
    return line.split("  #")[0].strip()


@pytest.fixture(scope="module")
def venv(tmp_path_factory):
    """A folder whose .venv is made and filled by README.md's two install lines: the first
    run there, the second from the checkout (`.` is the checkout) with that folder's .venv."""
    install = [command(x) for x in sh_block(README.read_text(), "Install it, offline, into a venv")]
    assert install == ["/usr/bin/python3 -m venv --system-site-packages .venv",
                       ".venv/bin/pip install --no-build-isolation --no-index ."], install
    root = tmp_path_factory.mktemp("user")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env.setdefault("CMAKE_BUILD_PARALLEL_LEVEL", "2")
    make, fill = (shlex.split(line) for line in install)
    fill[0] = str(root / fill[0])
    for argv, cwd in ((make, root), (fill, SOURCE)):
        r = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=1500)
        assert r.returncode == 0, f"{argv}\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    return root


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    d = tmp_path_factory.mktemp("data")
    events = evcorner.read(SAMPLE)
    paths = []
    for i, (a, b) in enumerate([(0, 12000), (12000, 30000)]):
        p = d / f"part{i}.aedat4"
        evcorner.write(p, events[a:b])
        paths.append(str(p))
    return paths


def clean_env(home):
    """The environment of a user's shell: no PYTHONPATH, HOME a folder of the test's."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env["HOME"] = str(home)
    return env


def stop(procs):
    """Stops every process group of `procs` (SIGTERM, then SIGKILL), and waits for them."""
    for p in procs:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGTERM)
    for p in procs:
        try:
            p.wait(timeout=20)
        except subprocess.TimeoutExpired:
            pass
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)
        p.wait()


def group_alive(pgid, wait_s=10):
    """Whether a process of group `pgid` is still there after up to `wait_s` seconds (a
    killed child is gone once its new parent has reaped it)."""
    deadline = time.time() + wait_s
    while True:
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return False
        if time.time() > deadline:
            return True
        time.sleep(0.1)


def expected_counts(venv, recordings, home):
    """Corner counts of the same tasks run in-process by the venv's interpreter."""
    code = ("import json, sys, evcorner._detectors as d\n"
            "print(json.dumps({f'{p} {n}': d.detect_file(p, None, n)['corners'] for p in sys.argv[2:] "
            "for n in sys.argv[1].split(',')}))")
    r = subprocess.run([str(venv / ".venv/bin/python"), "-c", code, ",".join(DETECTORS), *recordings],
                       env=clean_env(home), capture_output=True, text=True, timeout=120, check=True)
    return json.loads(r.stdout)


def check_results(out, recordings, counts, worker_pids=None):
    results = [json.loads(x) for x in (out / "results.jsonl").read_text().splitlines()]
    assert len(results) == len(recordings) * len(DETECTORS)
    for x in results:
        assert x["status"] == "ok", x
        assert x["corners"] == counts[f"{x['input']} {x['detector']}"]
        if worker_pids is not None:
            assert x["pid"] in worker_pids


def test_the_documented_commands_in_a_fresh_venv(venv, recordings, tmp_path):
    lines = [command(x) for x in sh_block(PYTHON_MD.read_text(), "### On a cluster")]
    assert len(lines) == 3, lines
    sched_line, worker_line, batch_line = lines
    assert sched_line.startswith(".venv/bin/python -m dask scheduler ")
    assert worker_line.startswith(".venv/bin/python -m dask worker ")
    assert batch_line.startswith(".venv/bin/python -m evcorner batch ")
    home = tmp_path / "home"
    home.mkdir()
    out = tmp_path / "out"
    sched_file = home / "evcorner-sched.json"

    def argv(line, extra=()):
        words = shlex.split(line.replace("~/", f"{home}/"))
        words[0] = str(venv / words[0])
        return words + list(extra)

    batch = argv(batch_line)
    glob_at = batch.index("/data/*.aedat4")
    batch[glob_at:glob_at + 1] = recordings
    batch[batch.index("/data/out")] = str(out)
    env = clean_env(home)
    procs = []
    try:
        procs.append(subprocess.Popen(argv(sched_line, ["--host", "127.0.0.1", "--no-dashboard"]), cwd=venv,
                                      env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                      start_new_session=True))
        # The scheduler creates the file, then writes it: wait until it holds the JSON.
        deadline = time.time() + 60
        info = None
        while info is None and time.time() < deadline and procs[0].poll() is None:
            try:
                info = json.loads(sched_file.read_text())
            except (FileNotFoundError, ValueError):
                time.sleep(0.1)
        assert info is not None, procs[0].stderr.read().decode() if procs[0].poll() is not None else "no scheduler file"
        assert info["address"].startswith("tcp://127.0.0.1:")
        for _ in range(2):
            procs.append(subprocess.Popen(argv(worker_line, ["--host", "127.0.0.1", "--no-dashboard"]), cwd=venv,
                                          env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                          start_new_session=True))
        r = subprocess.run(batch, cwd=venv, env=env, capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        assert "ModuleNotFoundError" not in r.stdout + r.stderr
        # The tasks ran in the workers (processes of the workers' groups), not in the driver.
        pids = subprocess.run(["ps", "-eo", "pid=,pgid="], capture_output=True, text=True, check=True).stdout.split()
        worker_pids = {int(pid) for pid, pgid in zip(pids[::2], pids[1::2]) if int(pgid) in {p.pid for p in procs[1:]}}
        check_results(out, recordings, expected_counts(venv, recordings, home), worker_pids)
    finally:
        stop(procs)
    assert not any(group_alive(p.pid) for p in procs)


FAKE_SRUN = """#!/bin/bash
# srun for a test: runs the command --ntasks times on this machine, stops them on TERM.
n=1
while [ $# -gt 0 ] && [ "${1#--}" != "$1" ]; do
    case $1 in --ntasks=*) n=${1#--ntasks=} ;; esac
    shift
done
pids=()
for ((i = 0; i < n; i++)); do "$@" & pids+=($!); done
trap 'kill "${pids[@]}" 2>/dev/null; wait; exit 143' TERM INT
wait
"""


def test_the_slurm_script_under_a_stand_in_srun(venv, recordings, tmp_path):
    assert subprocess.run(["bash", "-n", str(SLURM)]).returncode == 0
    text = SLURM.read_text()
    assert '"$PY" -m dask scheduler' in text and '"$PY" -m dask worker' in text and '"$PY" -m evcorner batch' in text
    code = [line for line in text.splitlines() if not line.lstrip().startswith("#")]
    assert not [line for line in code if re.search(r"(?<!-m )\bdask\b", line)]  # no bare `dask` command
    # The documented submission line names this script.
    submit = sh_block(PYTHON_MD.read_text(), "`scripts/slurm-batch.sh` is one job")
    assert any(line.startswith("sbatch scripts/slurm-batch.sh ") for line in submit), submit
    home = tmp_path / "home"
    home.mkdir()
    bindir = tmp_path / "bin"
    bindir.mkdir()
    (bindir / "srun").write_text(FAKE_SRUN)
    (bindir / "srun").chmod(0o755)
    out = tmp_path / "out"
    env = clean_env(home)
    env.update(PATH=f"{bindir}:{env['PATH']}", SLURM_NTASKS="3", SLURM_JOB_ID="4242",
               EVCORNER_VENV=str(venv / ".venv"), DASK_HOST="127.0.0.1")
    job = subprocess.Popen(["bash", str(SLURM), *recordings, "-d", ",".join(DETECTORS), "-o", str(out)], env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        stdout, stderr = job.communicate(timeout=300)
    finally:
        stop([job])
    assert job.returncode == 0, stderr
    assert re.search(r"workers at tcp://127\.0\.0\.1:\d+ ", stderr), stderr
    assert "ModuleNotFoundError" not in stdout + stderr
    assert not (home / "evcorner-sched-4242.json").exists()
    assert not group_alive(job.pid)
    # Against a scheduler the tasks run in its workers only: each result is the workers'.
    check_results(out, recordings, expected_counts(venv, recordings, home))
