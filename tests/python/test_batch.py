"""Batches on Dask distributed: a LocalCluster of 2 workers, an external scheduler with two
`dask worker` processes on 127.0.0.1, failures, bad options, a lost scheduler, temporary
files, and resuming an interrupted batch. Every process a test starts is on 127.0.0.1 and
stopped at its end (its process group killed), failed or not."""

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import evcorner
from conftest import SAMPLE

distributed = pytest.importorskip("distributed")
from evcorner import batch  # noqa: E402

DETECTORS = ["efast", "harris"]


def env_with_package():
    env = dict(os.environ)
    pkg_root = str(Path(evcorner.__file__).resolve().parent.parent)
    env["PYTHONPATH"] = pkg_root + os.pathsep + env.get("PYTHONPATH", "")
    return env


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    """Three recordings cut from the bundled sample, plus the sample itself."""
    d = tmp_path_factory.mktemp("recordings")
    events = evcorner.read(SAMPLE)
    paths = [str(SAMPLE)]
    for i, (a, b) in enumerate([(0, 9000), (9000, 21000), (21000, 30000)]):
        p = d / f"part{i}.txt"
        evcorner.write(p, events[a:b])
        paths.append(str(p))
    return paths


@pytest.fixture(scope="module")
def cli_counts(recordings, tmp_path_factory):
    cli = os.environ.get("EVCORNER_CLI") or str(Path(SAMPLE).parents[3] / "build" / "bin" / "evcorner")
    if not Path(cli).exists():
        pytest.skip("the evcorner CLI is not built")
    d = tmp_path_factory.mktemp("cli")
    counts = {}
    for i, path in enumerate(recordings):
        for det in DETECTORS:
            js = d / f"{i}-{det}.json"
            subprocess.run([cli, "detect", path, "-d", det, "-o", os.devnull, "--summary-json", str(js), "-q"],
                           check=True)
            counts[(path, det)] = json.loads(js.read_text())["corners"]
    return counts


@pytest.fixture(scope="module")
def client():
    from dask.distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0")
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


def lines(path):
    return [json.loads(x) for x in Path(path).read_text().splitlines()]


def test_local_cluster_counts_equal_the_cli(client, recordings, cli_counts, tmp_path):
    tasks = batch.plan(recordings, DETECTORS, tmp_path)
    assert len(tasks) == len(recordings) * len(DETECTORS)
    futures = batch.submit(client, tasks)
    assert len(futures) == len(tasks) and all(isinstance(f, distributed.Future) for f in futures.values())
    records = batch.gather(tasks, futures, tmp_path)
    workers = set(client.run(os.getpid).values())
    for t, r in zip(tasks, records):
        assert r["status"] == "ok", r
        assert r["corners"] == cli_counts[(t["input"], t["detector"])]
        assert r["pid"] in workers and r["pid"] != os.getpid()
        assert len(Path(t["corners"]).read_text().splitlines()) == r["corners"]
        assert json.loads(Path(t["summary"]).read_text())["corners"] == r["corners"]
    assert sorted(x["task"] for x in lines(tmp_path / "results.jsonl")) == sorted(t["key"] for t in tasks)


def test_parameter_grid_and_a_failure_do_not_stop_the_others(client, recordings, tmp_path):
    damaged = tmp_path / "damaged.txt"
    damaged.write_text("0.000001 1 2 1\nnot an event\n")
    inputs = [recordings[1], str(damaged), str(tmp_path / "missing.txt")]
    records = batch.run(client, inputs, ["harris"], tmp_path / "out", params={"harris_window": [5, 7]})
    assert len(records) == 6
    ok = [r for r in records if r["status"] == "ok"]
    failed = [r for r in records if r["status"] != "ok"]
    assert len(ok) == 2 and {r["params"]["harris_window"] for r in ok} == {5, 7}
    assert ok[0]["corners"] != ok[1]["corners"]
    assert len(failed) == 4
    assert all("damaged.txt:2" in r["error"] for r in failed if r["input"] == str(damaged))
    assert all("FileNotFoundError" in r["error"] for r in failed if r["input"].endswith("missing.txt"))
    assert "FAILED" in batch.table(records)


def outputs(folder):
    """Every file under `folder` but the batch log, by path relative to it."""
    return sorted(str(p.relative_to(folder)) for p in Path(folder).rglob("*") if p.is_file()
                  and p.name != "results.jsonl")


@pytest.mark.parametrize("to", ["txt", "npy", "aedat4", "h5"])
def test_a_failed_task_leaves_no_output(client, recordings, tmp_path, to):
    """Damage after thousands of good events: the library has written part of the corner
    file when it fails; the task leaves nothing, neither corners nor JSON nor a temporary."""
    text = Path(recordings[1]).read_text().splitlines()
    damaged = tmp_path / "in" / "late.txt"
    damaged.parent.mkdir()
    damaged.write_text("\n".join(text[:9000] + ["0.5 1 2 1 extra"] + text[9000:]) + "\n")
    out = tmp_path / "out"
    tasks = batch.plan([damaged, recordings[2]], DETECTORS, out, to=to)
    # A corner file of an earlier failed attempt, without its JSON, goes too.
    os.makedirs(tasks[0]["dir"])
    Path(tasks[0]["corners"]).write_text("stale\n")
    records = batch.gather(tasks, batch.submit(client, tasks), out)
    assert [r["status"] for r in records] == ["failed", "failed", "ok", "ok"], records
    assert all("late.txt:9001" in r["error"] for r in records[:2])
    done = [t for t in tasks[2:]]
    assert outputs(out) == sorted(str(Path(p).relative_to(out)) for t in done for p in (t["corners"], t["summary"]))


def test_failed_rows_tell_files_of_one_name_apart(client, tmp_path):
    inputs = []
    for d in ("a/x", "b/x", "c"):
        f = tmp_path / d / "events.txt"
        f.parent.mkdir(parents=True)
        f.write_text("0.000001 1 2 1\nnot an event\n")
        inputs.append(str(f))
    records = batch.run(client, inputs, ["efast"], tmp_path / "out")
    text = batch.table(records).splitlines()
    assert text[0] == f"inputs in {tmp_path}/"
    rows = [line.split()[0] for line in text[2:]]
    assert rows == ["a/x/events.txt", "b/x/events.txt", "c/events.txt"]
    assert all("FAILED: InputError" in line for line in text[2:])
    assert len({r["recording"] for r in records}) == 3


@pytest.mark.parametrize("args, says", [
    (["--to", "xyz"], "unknown corner file format 'xyz'"),
    (["-p", "harris_window=5,4"], "harris harris_window=4: harris_window must be within 5..15 (got 4)"),
    (["-p", "harris_window=5.5"], "harris_window takes an integer"),
    (["-p", "harris_nl=100", "-p", "harris_window=5"], "harris harris_nl=100 harris_window=5:"),
    (["-p", "no_such=1"], "parameter 'no_such' is taken by none of efast, harris"),
    (["-d", "efast,nope"], "unknown detector 'nope'"),
])
def test_bad_options_are_a_usage_error_before_anything_runs(recordings, tmp_path, args, says):
    out = tmp_path / "out"
    start = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "evcorner", "batch", *recordings, "-d", "efast,harris", "-o", str(out),
                        *args], env=env_with_package(), capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert says in r.stderr, r.stderr
    assert "Traceback" not in r.stderr
    assert not out.exists()  # nothing submitted, nothing written
    assert time.perf_counter() - start < 30  # no cluster was started


def test_a_lost_result_counts_the_finished_task_as_finished(client, recordings, tmp_path):
    """Futures that end cancelled (as when the scheduler is lost): a task whose JSON was
    written is counted as finished, one without it as not run, none as failed."""
    tasks = batch.plan(recordings, ["efast"], tmp_path)
    futures = batch.submit(client, tasks[:2])
    distributed.wait(list(futures.values()))
    futures.update(batch.submit(client, tasks[2:]))
    client.cancel(list(futures.values()))
    records = batch.gather(tasks, futures, tmp_path)
    assert all(f.status == "cancelled" for f in futures.values())
    for t, r in zip(tasks, records):
        finished = batch.done(t) is not None
        assert r["status"] == ("ok" if finished else batch.NOT_RUN), r
        assert finished or not Path(t["corners"]).exists()
    assert [r["status"] for r in records[:2]] == ["ok", "ok"] and records[0].get("recovered")
    assert "FAILED" not in batch.table(records)


def test_resume_removes_the_tasks_own_temporary_files_only(client, recordings, tmp_path):
    tasks = batch.plan(recordings[:1], ["efast", "harris"], tmp_path, params={"harris_window": [5]})
    d = Path(tasks[0]["dir"])
    d.mkdir(parents=True)
    # What a killed worker leaves: run_task's temporaries, the library's hidden file beside
    # one and beside the corner file, and an earlier version's summary temporary.
    own = [".efast.evcorner-batch-123-abcd.txt", ".efast.evcorner-batch-123-abcd.json",
           "..efast.evcorner-batch-123-abcd.txt.evcorner-Ab12Cd", ".efast.txt.evcorner-Zz9Yx8", "efast.json.tmp4242",
           ".harris_harris_window=5.evcorner-batch-9-ff.txt"]
    others = [".efast.txt.evcorner-toolong", ".efast_other.evcorner-batch-1-a.txt", "efast.json.tmpx", ".notes",
              "keep.txt", ".harris.evcorner-batch-9-ff.txt"]
    for name in own + others:
        (d / name).write_text("x")
    records = batch.gather(tasks, batch.submit(client, tasks), tmp_path)
    assert all(r["status"] == "ok" for r in records)
    left = sorted(p.name for p in d.iterdir())
    assert left == sorted(others + [Path(t[k]).name for t in tasks for k in ("corners", "summary")])


def test_resume_skips_what_was_done(client, recordings, cli_counts, tmp_path):
    tasks = batch.plan(recordings, DETECTORS, tmp_path)
    # An interrupted batch: only the first three tasks ran.
    batch.gather(tasks[:3], batch.submit(client, tasks[:3]), tmp_path)
    stamps = {t["key"]: os.stat(t["summary"]).st_mtime_ns for t in tasks[:3]}
    futures = batch.submit(client, tasks)
    assert set(futures) == {t["key"] for t in tasks[3:]}
    records = batch.gather(tasks, futures, tmp_path)
    assert [bool(r.get("resumed")) for r in records] == [True] * 3 + [False] * (len(tasks) - 3)
    for t, r in zip(tasks, records):
        assert r["corners"] == cli_counts[(t["input"], t["detector"])]
    assert {t["key"]: os.stat(t["summary"]).st_mtime_ns for t in tasks[:3]} == stamps
    logged = [x["task"] for x in lines(tmp_path / "results.jsonl")]
    assert sorted(logged) == sorted(t["key"] for t in tasks)  # each once


def test_cli_interrupted_then_resumed(recordings, cli_counts, tmp_path):
    """Interrupts `python3 -m evcorner batch` (SIGINT to its process group, as Ctrl-C does)
    once a result is logged: it stops at once, says so in one line (exit 130), leaves no
    temporary file and no corner file without its JSON; then reruns it to completion."""
    out = tmp_path / "out"
    windows = [5, 7, 9, 11, 13, 15]
    cmd = [sys.executable, "-m", "evcorner", "batch", *recordings, "-d", ",".join(DETECTORS), "-o", str(out),
           "--workers", "1", "-p", "harris_window=" + ",".join(map(str, windows))]
    proc = subprocess.Popen(cmd, env=env_with_package(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True, text=True)
    log = out / "results.jsonl"
    try:
        deadline = time.time() + 60
        while time.time() < deadline and proc.poll() is None:
            if log.exists() and log.read_text().count("\n") >= 1:
                break
            time.sleep(0.02)
        assert proc.poll() is None, "the batch ended before it could be interrupted"
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        stop_group(proc)
    total = len(recordings) * (1 + len(windows))
    assert proc.returncode == 130, err
    assert "interrupted: " in err and "rerun the same command to resume" in err, err
    assert "Traceback" not in err, err
    assert not [p for p in out.rglob(".*")], "temporary files left"
    corners = {p.with_suffix("") for p in out.rglob("*.txt")}
    summaries = {p.with_suffix("") for p in out.rglob("*.json")}
    assert corners == summaries
    done_before = len(summaries)
    assert 1 <= done_before < total
    rerun = subprocess.run(cmd, env=env_with_package(), capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    assert f"({done_before} done before)" in rerun.stderr
    assert rerun.stdout.count("ok (resumed)") == done_before
    for r in lines(log):
        if r["detector"] == "efast":
            assert r["corners"] == cli_counts[(r["input"], "efast")]
    assert len({r["task"] for r in lines(log)}) == total


def stop_group(proc, sig=signal.SIGTERM):
    """Stops `proc` and everything in its process group (started with start_new_session)."""
    for s in (sig, signal.SIGKILL):
        if proc.poll() is not None:
            break
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, s)
        with contextlib.suppress(subprocess.TimeoutExpired):
            proc.wait(timeout=20)
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL)  # what the leader left behind in its group
    proc.wait()


def test_external_scheduler_and_two_dask_workers(recordings, cli_counts, tmp_path):
    """`dask scheduler` + two `dask worker` processes on 127.0.0.1, all stopped at the end."""
    sched_file = tmp_path / "scheduler.json"
    env = env_with_package()
    dask = [sys.executable, "-m", "dask", "scheduler"]  # the `dask` command, on this interpreter
    worker = [sys.executable, "-m", "dask", "worker"]
    procs = []
    try:
        procs.append(subprocess.Popen(dask + ["--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                              "--scheduler-file", str(sched_file)],
                                      env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        deadline = time.time() + 60
        while not sched_file.exists() and time.time() < deadline:
            time.sleep(0.05)
        for i in range(2):
            procs.append(subprocess.Popen(worker + ["--scheduler-file", str(sched_file), "--nthreads", "1",
                                                    "--no-nanny", "--no-dashboard", "--name", f"w{i}",
                                                    "--host", "127.0.0.1"],
                                          env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from dask.distributed import Client
        with Client(scheduler_file=str(sched_file), timeout=60) as c:
            c.wait_for_workers(2, timeout=60)
        out = tmp_path / "out"
        r = subprocess.run([sys.executable, "-m", "evcorner", "batch", *recordings, "-d", ",".join(DETECTORS),
                            "-o", str(out), "--scheduler-file", str(sched_file)],
                           env=env, capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
        assert "on 2 workers" in r.stderr
        assert r.stdout.splitlines()[1].split()[:2] == ["input", "detector+params"]
        results = lines(out / "results.jsonl")
        assert len(results) == len(recordings) * len(DETECTORS)
        worker_pids = {p.pid for p in procs[1:]}
        for x in results:
            assert x["status"] == "ok" and x["pid"] in worker_pids
            assert x["corners"] == cli_counts[(x["input"], x["detector"])]
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
    assert all(p.poll() is not None for p in procs)


def start_scheduler(sched_file, env):
    """`dask scheduler` on 127.0.0.1 in a process group of its own, once its file is there."""
    proc = subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0",
                             "--no-dashboard", "--scheduler-file", str(sched_file)],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.time() + 60
    while not sched_file.exists() and time.time() < deadline and proc.poll() is None:
        time.sleep(0.05)
    return proc


def start_worker(sched_file, env):
    """A single-threaded `dask worker` on 127.0.0.1 without a nanny (the task runs in it)."""
    return subprocess.Popen([sys.executable, "-m", "dask", "worker", "--scheduler-file", str(sched_file),
                             "--nthreads", "1", "--no-nanny", "--no-dashboard", "--host", "127.0.0.1"],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)


def test_a_lost_scheduler_is_reported_and_finished_tasks_count(recordings, tmp_path):
    """`dask scheduler` killed (SIGKILL) in the middle of a batch, its worker frozen
    (SIGSTOP) so that no file changes while the outcome is checked: one line says so,
    exit 3, no traceback; a task is "ok" exactly when its JSON is written, else "not run"."""
    sched_file = tmp_path / "scheduler.json"
    env = env_with_package()
    procs = []
    out = tmp_path / "out"
    try:
        procs.append(start_scheduler(sched_file, env))
        procs.append(start_worker(sched_file, env))
        driver = subprocess.Popen([sys.executable, "-m", "evcorner", "batch", *recordings, "-d", ",".join(DETECTORS),
                                   "-p", "harris_window=5,7,9,11,13,15", "-o", str(out),
                                   "--scheduler-file", str(sched_file)],
                                  env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                  start_new_session=True)
        procs.append(driver)
        log = out / "results.jsonl"
        deadline = time.time() + 120
        while time.time() < deadline and driver.poll() is None and not (log.exists() and log.read_text()):
            time.sleep(0.02)
        assert driver.poll() is None, "the batch ended before the scheduler could be lost"
        os.killpg(procs[1].pid, signal.SIGSTOP)
        os.killpg(procs[0].pid, signal.SIGKILL)
        stdout, stderr = driver.communicate(timeout=120)
        assert driver.returncode == 3, stderr
        assert "Traceback" not in stderr and "CancelledError" not in stdout + stderr, stderr
        assert "lost the scheduler: " in stderr and "rerun the same command" in stderr, stderr
        tasks = batch.plan(recordings, DETECTORS, out, params={"harris_window": [5, 7, 9, 11, 13, 15]})
        final = {}
        for r in lines(log):
            final[r["task"]] = r
        assert set(final) == {t["key"] for t in tasks}
        finished = 0
        for t in tasks:
            has_json = Path(t["summary"]).exists()
            finished += has_json
            assert final[t["key"]]["status"] == ("ok" if has_json else batch.NOT_RUN), (t, final[t["key"]])
            assert has_json == Path(t["corners"]).exists()
        assert 1 <= finished < len(tasks)
        assert f"{finished} of {len(tasks)} tasks finished" in stderr
        assert stdout.count(" ok") == finished and stdout.count("NOT RUN") == len(tasks) - finished
    finally:
        if len(procs) > 1:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(procs[1].pid, signal.SIGCONT)
        for p in procs:
            stop_group(p, signal.SIGKILL)
    assert all(p.poll() is not None for p in procs)


def test_a_killed_worker_leaves_no_temporary_file(recordings, tmp_path):
    """A worker killed (SIGKILL) while it writes a corner file: its task runs again on the
    other worker, the batch ends with every task ok and no temporary file left."""
    big = tmp_path / "big.npy"
    events = evcorner.read(SAMPLE)
    span = int(events["t"][-1] - events["t"][0]) + 1000
    copies = []
    for i in range(40):  # 1.2 M events: a task lasts long enough to be caught writing
        e = events.copy()
        e["t"] += i * span
        copies.append(e)
    evcorner.write(big, np.concatenate(copies))
    sched_file = tmp_path / "scheduler.json"
    env = env_with_package()
    out = tmp_path / "out"
    procs = []
    try:
        procs.append(start_scheduler(sched_file, env))
        for _ in range(2):
            procs.append(start_worker(sched_file, env))
        from dask.distributed import Client
        with Client(scheduler_file=str(sched_file), timeout=60) as c:
            c.wait_for_workers(2, timeout=60)
        driver = subprocess.Popen([sys.executable, "-m", "evcorner", "batch", str(big), "-d", "harris",
                                   "-p", "harris_window=11,13,15", "-o", str(out), "--scheduler-file", str(sched_file)],
                                  env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                  start_new_session=True)
        procs.append(driver)
        # Kill the worker that writes the first temporary corner file seen.
        victim = None
        deadline = time.time() + 120
        while victim is None and time.time() < deadline and driver.poll() is None:
            for p in out.rglob(".*evcorner-batch-*"):
                pid = int(p.name.split("evcorner-batch-")[1].split("-")[0])
                if pid in {w.pid for w in procs[1:3]}:
                    victim = next(w for w in procs[1:3] if w.pid == pid)
                    os.killpg(victim.pid, signal.SIGKILL)
                    break
            time.sleep(0.005)
        if victim is None:
            pytest.skip("no temporary file was seen before the batch ended (too fast here)")
        stdout, stderr = driver.communicate(timeout=300)
        assert driver.returncode == 0, stderr
        assert stdout.count(" ok") == 3, stdout
        assert not list(out.rglob(".*")), "temporary files left"
    finally:
        for p in procs:
            stop_group(p, signal.SIGKILL)
