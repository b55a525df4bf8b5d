"""The measurements of docs/python.md (issue 13 item 6). Not a test: speed is measured here.

    PYTHONPATH=build/python /usr/bin/python3 python/bench/measure.py build/bin/evcorner ../shared/data/real/ecd-stppp/*/events.txt

Prints one line per figure; every ratio is a median of interleaved runs in the same process
run. The machine load (uptime) is printed first and last.
"""

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import evcorner


def uptime():
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def replay(files, n):
    """n events: the files one after another, again and again, each copy shifted in time."""
    parts = [evcorner.read(f) for f in files]
    out, total, shift = [], 0, 0
    while total < n:
        for p in parts:
            q = p.copy()
            q["t"] += shift - q["t"][0]
            shift = int(q["t"][-1]) + 1
            out.append(q)
            total += len(q)
            if total >= n:
                break
    return np.concatenate(out)[:n]


def main():
    cli, files = sys.argv[1], sys.argv[2:]
    reps = int(os.environ.get("REPS", "5"))
    print("load before:", uptime())
    tmp = tempfile.mkdtemp(prefix="evcorner-measure-")
    events = replay(files, 10_000_000)
    big = os.path.join(tmp, "replay10M.npy")
    evcorner.write(big, events)

    for det in ("efast", "harris"):
        cli_s, py_s = [], []
        for _ in range(reps):  # interleaved
            js = os.path.join(tmp, "s.json")
            subprocess.run([cli, "detect", big, "-d", det, "-o", os.devnull, "--summary-json", js, "-q"], check=True)
            cli_s.append(json.load(open(js))["detect_s"])
            t0 = time.perf_counter()
            evcorner.detect(events, det)
            py_s.append(time.perf_counter() - t0)
        c, p = statistics.median(cli_s), statistics.median(py_s)
        print(f"{det} on 10 M events: CLI detection {c:.3f} s, Python detect() {p:.3f} s "
              f"(incl. building the detector), Python/CLI {p / c:.3f} (medians of {reps})")

    det = evcorner.EFast(240, 180)
    one = events[:1].copy()
    out = np.empty(1, np.uint8)
    for label, args in (("1 event, new mask", (one,)), ("1 event, out=", (one, out)), ("0 events", (events[:0],))):
        n = 200_000
        t0 = time.perf_counter()
        for _ in range(n):
            det.process(*args)
        print(f"per-call overhead, process({label}): {(time.perf_counter() - t0) / n * 1e6:.2f} us")

    n = 1_000_000
    mv = np.zeros(n, [("x", "<u2"), ("y", "<u2"), ("p", "<i2"), ("t", "<i8")])
    tonic = np.zeros(n, [("t", "<i8"), ("x", "<i8"), ("y", "<i8"), ("p", "<i8")])
    dv = np.zeros(n, [("timestamp", "<i8"), ("x", "<i2"), ("y", "<i2"), ("polarity", "u1")])
    for a in (mv, tonic, dv):
        for k in a.dtype.names:
            src = {"timestamp": "t", "polarity": "p"}.get(k, k)
            a[k] = events[src][:n]
    for name, a in (("Metavision", mv), ("tonic", tonic), ("dv-processing", dv)):
        ts = []
        for _ in range(reps):
            t0 = time.perf_counter()
            evcorner.as_events(a)
            ts.append(time.perf_counter() - t0)
        print(f"as_events({name} dtype): {statistics.median(ts) / n * 1e9:.2f} ns/event (1 M events)")

    from dask.distributed import Client, LocalCluster
    from evcorner import batch
    for workers in (1, 2):
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0")
        client = Client(cluster)
        client.wait_for_workers(workers)
        up = time.perf_counter() - t0
        out_dir = os.path.join(tmp, f"batch{workers}")
        t1 = time.perf_counter()
        records = batch.run(client, files, ["efast", "harris"], out_dir)
        wall = time.perf_counter() - t1
        det_s = sum(r["detect_s"] for r in records)
        task_s = sum(r["task_s"] for r in records)
        # Dask's own cost per task: trivial tasks through the same client.
        k = 500
        t2 = time.perf_counter()
        client.gather(client.map(int, range(k), pure=False))
        per_task = (time.perf_counter() - t2) / k
        client.close()
        cluster.close()
        print(f"{workers} worker(s): cluster start-up {up:.2f} s; batch of {len(records)} tasks "
              f"({len(files)} files x efast,harris) {wall:.2f} s wall (sum of task times {task_s:.2f} s, "
              f"of detection {det_s:.2f} s); Dask per trivial task {per_task * 1e3:.2f} ms")
    print("load after:", uptime())


if __name__ == "__main__":
    main()
