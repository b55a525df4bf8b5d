"""The measurements of docs/python.md. Not a test: speed is measured here.

    PYTHONPATH=build/python /usr/bin/python3 python/bench/measure.py build/bin/evcorner ../shared/data/real/ecd-stppp/*/events.txt

Prints one line per figure; every ratio is a median of interleaved runs in the same process
run. The machine load (uptime) is printed first and last. Detection is compared by CPU
time (detection_ratio). REPS=5 (rounds), DETECTORS=efast,harris, ONLY=detect (stop after
the detection figures).
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


def cpu_s():
    """This process's CPU time (user + system, all threads), s."""
    return time.process_time()


def detection_ratio(cli, big, events, det, reps, tmp):
    """Python vs CLI detection time on the same 10 M events, by CPU time (the machine is
    shared: wall time counts the time other processes hold the core). Interleaved, per
    round: the CLI's `bench --cpu-time` (two passes over the file as it is, each a freshly
    built detector, the thread's CPU time around detect() alone: the library's checked
    call over the whole span), then two evcorner.detect(events, det) calls in Python (the
    process's CPU time around the call, building the detector included). PIPELINE=1 adds
    the CLI's `detect` pipeline (65 536-event batches; its detect_s is wall time)."""
    js = os.path.join(tmp, "bench.json")
    cli_ns, py_ns, pipe_ns = [], [], []
    n = len(events)
    for _ in range(reps):
        subprocess.run([cli, "bench", big, "-d", det, "--repeat", "1", "--min-events", "1", "--no-latency",
                        "--cpu-time", "--json", js, "-q"], check=True, stdout=subprocess.DEVNULL)
        (row,) = json.load(open(js))["results"]
        cli_ns += [row["cold_ns_per_event"][0], row["ns_per_event"][0]]
        for _pass in range(2):
            t0 = cpu_s()
            evcorner.detect(events, det)
            py_ns.append((cpu_s() - t0) * 1e9 / n)
        line = f"  {det} round: CLI bench {cli_ns[-2]:.1f} {cli_ns[-1]:.1f}, Python detect() {py_ns[-2]:.1f} {py_ns[-1]:.1f}"
        if os.environ.get("PIPELINE") == "1":
            s = os.path.join(tmp, "s.json")
            subprocess.run([cli, "detect", big, "-d", det, "-o", os.devnull, "--summary-json", s, "-q"], check=True)
            pipe_ns.append(json.load(open(s))["detect_s"] * 1e9 / n)
            line += f", CLI detect pipeline (wall) {pipe_ns[-1]:.1f}"
        print(line + " ns/event", flush=True)
    c, p = statistics.median(cli_ns), statistics.median(py_ns)
    print(f"{det} on {n / 1e6:g} M events, CPU ns/event (medians of {len(cli_ns)} passes each, {reps} interleaved "
          f"rounds): CLI bench --cpu-time {c:.1f}, Python evcorner.detect() {p:.1f}: Python/CLI {p / c:.3f}"
          + (f"; CLI detect pipeline detect_s (wall) {statistics.median(pipe_ns):.1f}" if pipe_ns else ""),
          flush=True)

def main():
    cli, files = sys.argv[1], sys.argv[2:]
    reps = int(os.environ.get("REPS", "5"))
    detectors = os.environ.get("DETECTORS", "efast,harris").split(",")
    print("load before:", uptime())
    tmp = tempfile.mkdtemp(prefix="evcorner-measure-")
    events = replay(files, 10_000_000)
    big = os.path.join(tmp, "replay10M.npy")
    evcorner.write(big, events)

    for det in detectors:
        detection_ratio(cli, big, events, det, reps, tmp)
    if os.environ.get("ONLY") == "detect":
        print("load after:", uptime())
        return

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
