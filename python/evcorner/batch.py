"""Many recordings x detectors x parameter settings on Dask distributed.

One task per (recording, detector, parameters). A task gets PATHS (never arrays): it opens
the recording on its worker, runs the library's detection pipeline (evcorner.detect_file,
the same code as `evcorner detect`), writes its corner file and a JSON summary into
OUTDIR/<recording>/, and returns the summary. The driver appends every result, and every
failure with its input and error, to OUTDIR/results.jsonl as it arrives; a task whose
summary JSON exists is skipped, so a batch that was interrupted resumes where it stopped.

    from dask.distributed import Client, LocalCluster
    from evcorner import batch
    with Client(LocalCluster(n_workers=2, threads_per_worker=1)) as client:
        tasks = batch.plan(["a.txt", "b.aedat4"], ["efast", "harris"], "out")
        futures = batch.submit(client, tasks)        # one future per task to run
        results = batch.gather(tasks, futures, "out")

`python3 -m evcorner batch` (evcorner/__main__.py) is this plus a progress line and a table.
"""

import hashlib
import itertools
import json
import os
import socket
import sys
import time

from ._detectors import detectors as _registry


class Task(dict):
    """One unit of work (a plain dict, so that it pickles and prints simply): key, input,
    detector, params, dir, corners, summary."""


def _param_grid(detector, grid):
    """Every combination of the values in `grid` ({keyword: [values]}) that `detector` takes."""
    info = next(d for d in _registry() if d["name"] == detector)
    taken = {p["name"] for p in info["params"]}
    keys = sorted(k for k in grid if k in taken)
    return [dict(zip(keys, combo)) for combo in itertools.product(*(grid[k] for k in keys))]


def _recording_names(inputs):
    """A short, unique folder name per input: <parent>_<stem>, + a path hash on a clash."""
    names = {}
    for path in inputs:
        base = os.path.splitext(os.path.basename(path))[0]
        parent = os.path.basename(os.path.dirname(path))
        names[path] = f"{parent}_{base}" if parent else base
    counts = {}
    for n in names.values():
        counts[n] = counts.get(n, 0) + 1
    for path, n in names.items():
        if counts[n] > 1:
            names[path] = f"{n}-{hashlib.sha1(path.encode()).hexdigest()[:8]}"
    return names


def plan(inputs, detector_names, out_dir, params=None, to="txt"):
    """The tasks: every input x detector x combination of `params` ({keyword: value or
    [values]}) that the detector takes. A keyword no chosen detector takes is a ValueError.
    Inputs become absolute paths (workers must see the same file system)."""
    grid = {k: (list(v) if isinstance(v, (list, tuple)) else [v]) for k, v in (params or {}).items()}
    known = {d["name"]: d for d in _registry()}
    for name in detector_names:
        if name not in known:
            raise ValueError(f"unknown detector {name!r} (known: {', '.join(known)})")
    for key in grid:
        if not any(key in {p["name"] for p in known[n]["params"]} for n in detector_names):
            raise ValueError(f"parameter {key!r} is taken by none of {', '.join(detector_names)}")
    inputs = [os.path.abspath(os.fspath(p)) for p in inputs]
    names = _recording_names(inputs)
    out_dir = os.path.abspath(os.fspath(out_dir))
    tasks = []
    for path, name, combo in ((p, d, c) for p in inputs for d in detector_names for c in _param_grid(d, grid)):
        tag = name + "".join(f"_{k}={v}" for k, v in sorted(combo.items()))
        key = hashlib.sha1(json.dumps([path, name, sorted(combo.items())]).encode()).hexdigest()[:16]
        folder = os.path.join(out_dir, names[path])
        tasks.append(Task(key=key, input=path, recording=names[path], detector=name, params=combo,
                          tag=tag, dir=folder, corners=os.path.join(folder, f"{tag}.{to}"),
                          summary=os.path.join(folder, f"{tag}.json")))
    return tasks


def run_task(task):
    """Runs on a worker: detects, writes the corner file and then the summary JSON (atomically,
    so that its presence means the task completed), returns the summary."""
    from . import _detectors  # on the worker

    os.makedirs(task["dir"], exist_ok=True)
    start = time.perf_counter()
    summary = _detectors.detect_file(task["input"], task["corners"], task["detector"], **task["params"])
    summary.update(task=task["key"], recording=task["recording"], output=task["corners"], status="ok",
                   host=socket.gethostname(), pid=os.getpid(), task_s=time.perf_counter() - start)
    tmp = task["summary"] + f".tmp{os.getpid()}"
    with open(tmp, "w") as f:
        json.dump(summary, f)
    os.replace(tmp, task["summary"])
    return summary


def done(task):
    """The summary of a task that completed before (its JSON exists), else None."""
    try:
        with open(task["summary"]) as f:
            return json.load(f)
    except (FileNotFoundError, json.JSONDecodeError):
        return None


def submit(client, tasks):
    """Submits the tasks not done yet; returns {task key: future}. pure=False: a task
    re-submitted after a failure runs again."""
    return {t["key"]: client.submit(run_task, t, key=f"evcorner-{t['tag']}-{t['key']}", pure=False)
            for t in tasks if done(t) is None}


def _logged_keys(path):
    keys = set()
    try:
        with open(path) as f:
            for line in f:
                try:
                    r = json.loads(line)
                except json.JSONDecodeError:
                    continue  # a line cut by a crash
                if r.get("status") == "ok":
                    keys.add(r.get("task"))
    except FileNotFoundError:
        pass
    return keys


def gather(tasks, futures, out_dir, progress=None):
    """Waits for `futures` (from submit) as they complete, appending each result (or
    failure: status "failed", input, detector, error) to OUTDIR/results.jsonl; tasks
    done before are taken from their JSON (and logged if the log lacks them). Returns one
    record per task, in task order. progress(done, total, record) is told after each."""
    from dask.distributed import as_completed

    os.makedirs(out_dir, exist_ok=True)
    log_path = os.path.join(out_dir, "results.jsonl")
    logged = _logged_keys(log_path)
    by_key = {t["key"]: t for t in tasks}
    records = {}
    with open(log_path, "a") as log:
        def record(r):
            records[r["task"]] = r
            if r.get("status") != "ok" or r["task"] not in logged:
                log.write(json.dumps(r) + "\n")
                log.flush()
            if progress:
                progress(len(records), len(tasks), r)

        for t in tasks:
            if t["key"] not in futures:
                r = done(t)
                r.setdefault("status", "ok")
                r["resumed"] = True
                record(r)
        key_of = {f.key: k for k, f in futures.items()}
        for fut in as_completed(list(futures.values())):
            t = by_key[key_of[fut.key]]
            try:
                r = fut.result()
            except Exception as e:  # noqa: BLE001 -- a failed task is reported, the others go on
                r = {"task": t["key"], "status": "failed", "input": t["input"], "detector": t["detector"],
                     "params": t["params"], "error": f"{type(e).__name__}: {e}"}
            record(r)
    return [records[t["key"]] for t in tasks]


def table(records):
    """The results as a text table."""
    head = ("recording", "detector+params", "events", "corners", "red.%", "detect_s", "status")
    rows = []
    for r in records:
        ok = r.get("status") == "ok"
        rows.append((
            str(r.get("recording", os.path.basename(str(r.get("input", ""))))),
            str(r.get("detector", "")) + "".join(f" {k}={v}" for k, v in sorted((r.get("params") or {}).items())),
            str(r.get("events", "")) if ok else "",
            str(r.get("corners", "")) if ok else "",
            f"{r['reduction_rate']:.2f}" if ok and r.get("reduction_rate") is not None else "",
            f"{r['detect_s']:.4f}" if ok else "",
            ("ok (resumed)" if r.get("resumed") else "ok") if ok else "FAILED: " + r.get("error", ""),
        ))
    widths = [max(len(h), *(len(row[i]) for row in rows)) if rows else len(h) for i, h in enumerate(head)]
    lines = ["  ".join(h.ljust(w) for h, w in zip(head, widths))]
    lines += ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in rows]
    return "\n".join(lines)


def run(client, inputs, detector_names, out_dir, params=None, to="txt", progress=None):
    """plan + submit + gather: the records, in task order."""
    tasks = plan(inputs, detector_names, out_dir, params, to)
    return gather(tasks, submit(client, tasks), out_dir, progress)


def print_progress(done_, total, r, stream=sys.stderr):
    what = f"{r.get('recording', r.get('input'))} {r.get('detector')}"
    status = "resumed" if r.get("resumed") else r.get("status")
    extra = f" {r.get('corners')} corners" if r.get("status") == "ok" else f" {r.get('error')}"
    print(f"[{done_}/{total}] {status}: {what}{extra}", file=stream, flush=True)
