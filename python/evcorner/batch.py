"""Many recordings x detectors x parameter settings on Dask distributed.

One task per (recording, detector, parameters). A task gets PATHS (never arrays): it opens
the recording on its worker, runs the library's detection pipeline (evcorner.detect_file,
the same code as `evcorner detect`), writes its corner file and a JSON summary into
OUTDIR/<recording>/, and returns the summary. The driver appends every result, and every
failure with its input and error, to OUTDIR/results.jsonl as it arrives; a task whose
summary JSON (and corner file) exists is skipped, so a batch that was interrupted resumes
where it stopped.

Outputs are whole or absent: a task writes under hidden temporary names
(.<tag>.evcorner-batch-<pid>-<hex>...) and renames them onto the corner file and then the
summary JSON once both are complete; a failed task removes what it wrote. Temporary files
that a killed worker or an interrupted batch left are removed by clean(): submit() calls
it for every task it submits (so a resumed batch removes them), gather() for every task
whose future ended.

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
import re
import secrets
import socket
import sys
import time
from concurrent.futures import CancelledError

from . import _detectors
from ._detectors import detectors as _registry

# The corner file extensions a batch writes, by --to: an extension, or a format name of
# OUTPUT_FORMATS (the formats the library writes).
_EXTENSION_OF = {"txt": "txt", "ecd-text": "txt", "csv": "csv", "npy": "npy", "aedat4": "aedat4",
                 "h5": "h5", "hdf5": "hdf5"}

# What every temporary name of a task holds right after its tag.
_TMP_MARK = ".evcorner-batch-"

# The status of a task whose result never came: the scheduler was lost or the batch stopped.
NOT_RUN = "not run"


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


def output_extension(to):
    """The corner file extension for `to` (an extension or a format name: txt, ecd-text,
    csv, npy, aedat4, h5, hdf5); ValueError naming the choices for anything else."""
    try:
        return _EXTENSION_OF[str(to).lower().lstrip(".")]
    except KeyError:
        raise ValueError(f"unknown corner file format {to!r} (known: {', '.join(_EXTENSION_OF)})") from None


def check_parameters(detector, params):
    """Builds `detector` with `params` on a 240x180 sensor, as a task will: a ValueError
    (or TypeError) naming the detector and the parameters when the library refuses them."""
    try:
        _detectors.Detector(detector, 240, 180, dict(params))
    except (ValueError, TypeError) as e:
        what = "".join(f" {k}={v}" for k, v in sorted(params.items()))
        raise type(e)(f"{detector}{what}: {e}") from None


def plan(inputs, detector_names, out_dir, params=None, to="txt"):
    """The tasks: every input x detector x combination of `params` ({keyword: value or
    [values]}) that the detector takes. A keyword no chosen detector takes, a value the
    detector refuses (out of range, wrong type) and an unknown `to` are a ValueError before
    any task exists. Inputs become absolute paths (workers must see the same file system)."""
    grid = {k: (list(v) if isinstance(v, (list, tuple)) else [v]) for k, v in (params or {}).items()}
    ext = output_extension(to)
    known = {d["name"]: d for d in _registry()}
    for name in detector_names:
        if name not in known:
            raise ValueError(f"unknown detector {name!r} (known: {', '.join(known)})")
    for key in grid:
        if not any(key in {p["name"] for p in known[n]["params"]} for n in detector_names):
            raise ValueError(f"parameter {key!r} is taken by none of {', '.join(detector_names)}")
    combos = {name: _param_grid(name, grid) for name in detector_names}
    for name, name_combos in combos.items():
        for combo in name_combos:
            check_parameters(name, combo)
    inputs = [os.path.abspath(os.fspath(p)) for p in inputs]
    names = _recording_names(inputs)
    out_dir = os.path.abspath(os.fspath(out_dir))
    tasks = []
    for path, name, combo in ((p, d, c) for p in inputs for d in detector_names for c in combos[d]):
        tag = name + "".join(f"_{k}={v}" for k, v in sorted(combo.items()))
        folder = os.path.join(out_dir, names[path])
        # The output folder is part of the key: the same work into another folder is another task.
        key = hashlib.sha1(json.dumps([path, name, sorted(combo.items()), folder]).encode()).hexdigest()[:16]
        tasks.append(Task(key=key, input=path, recording=names[path], detector=name, params=combo,
                          tag=tag, dir=folder, corners=os.path.join(folder, f"{tag}.{ext}"),
                          summary=os.path.join(folder, f"{tag}.json")))
    return tasks


def _remove(path):
    try:
        os.remove(path)
    except FileNotFoundError:
        pass


def _failure(task, error, status="failed"):
    return {"task": task["key"], "status": status, "input": task["input"], "recording": task["recording"],
            "detector": task["detector"], "params": task["params"], "error": error}


def run_task(task):
    """Runs on a worker: detects into a temporary corner file, writes the summary JSON to a
    temporary name, then renames the corner file and then the JSON onto their names (so
    that the JSON's presence means the task completed), and returns the summary. A task
    that fails removes what it wrote (a corner file of an earlier attempt too: without its
    JSON it is no result) and returns a record with status "failed", its input and error."""
    token = f"{os.getpid()}-{secrets.token_hex(4)}"
    ext = os.path.splitext(task["corners"])[1]
    tmp_corners = os.path.join(task["dir"], f".{task['tag']}{_TMP_MARK}{token}{ext}")
    tmp_summary = os.path.join(task["dir"], f".{task['tag']}{_TMP_MARK}{token}.json")
    try:
        os.makedirs(task["dir"], exist_ok=True)
        start = time.perf_counter()
        summary = _detectors.detect_file(task["input"], tmp_corners, task["detector"], **task["params"])
        summary.update(task=task["key"], recording=task["recording"], output=task["corners"], status="ok",
                       host=socket.gethostname(), pid=os.getpid(), task_s=time.perf_counter() - start)
        with open(tmp_summary, "w") as f:
            json.dump(summary, f)
        os.replace(tmp_corners, task["corners"])
        os.replace(tmp_summary, task["summary"])
        return summary
    except Exception as e:  # noqa: BLE001 -- reported as the task's result
        for path in (tmp_corners, tmp_summary, task["corners"]):
            _remove(path)
        return _failure(task, f"{type(e).__name__}: {e}")
    except BaseException:
        for path in (tmp_corners, tmp_summary):
            _remove(path)
        raise


def _temporary_name(task):
    """A pattern of the temporary names of `task`: run_task's (and the library's hidden
    file beside one), the library's beside the corner file, and the summary's of earlier
    versions (<tag>.json.tmp<pid>)."""
    tag = re.escape(task["tag"])
    corners = re.escape(os.path.basename(task["corners"]))
    return re.compile(rf"\.{{1,2}}{tag}{re.escape(_TMP_MARK)}.*|\.{corners}\.evcorner-[A-Za-z0-9]{{6}}|{tag}\.json\.tmp\d+")


def clean(task):
    """Removes the temporary files a task left behind (a killed worker, an interrupted
    batch): only names of the task's own temporary patterns, in its folder. Returns them."""
    pattern = _temporary_name(task)
    try:
        names = os.listdir(task["dir"])
    except FileNotFoundError:
        return []
    removed = []
    for name in names:
        if pattern.fullmatch(name):
            path = os.path.join(task["dir"], name)
            try:
                os.remove(path)
                removed.append(path)
            except (FileNotFoundError, IsADirectoryError):
                pass
    return removed


def done(task):
    """The summary of a task that completed before (its JSON and its corner file exist),
    else None."""
    try:
        with open(task["summary"]) as f:
            summary = json.load(f)
    except (FileNotFoundError, json.JSONDecodeError):
        return None
    return summary if os.path.exists(task["corners"]) else None


def submit(client, tasks):
    """Submits the tasks not done yet, after removing their temporary files of an earlier
    run (clean()); returns {task key: future}. pure=False: a task re-submitted after a
    failure runs again."""
    futures = {}
    for t in tasks:
        if done(t) is None:
            clean(t)
            futures[t["key"]] = client.submit(run_task, t, key=f"evcorner-{t['tag']}-{t['key']}", pure=False)
    return futures


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


def _lost(client):
    """Whether `client` lost its scheduler (its connection is not running)."""
    return client is not None and getattr(client, "status", "running") != "running"


def gather(tasks, futures, out_dir, progress=None):
    """Waits for `futures` (from submit) as they complete, appending each result (or
    failure: status "failed", input, detector, error) to OUTDIR/results.jsonl; tasks
    done before are taken from their JSON (and logged if the log lacks them). A future
    that ends without its result (cancelled: the scheduler was lost) counts as finished
    when the task's JSON was written all the same (`"recovered": true`), else its status
    is NOT_RUN ("not run"). Returns one record per task, in task order.
    progress(done, total, record) is told after each."""
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
            except Exception as e:  # noqa: BLE001 -- a task without its result is reported, the others go on
                r = done(t)
                if r is not None:
                    r["recovered"] = True
                elif isinstance(e, CancelledError) or _lost(getattr(fut, "client", None)):
                    r = _failure(t, "the scheduler was lost before the task's result came", NOT_RUN)
                else:
                    r = _failure(t, f"{type(e).__name__}: {e}")
            record(r)
        # A task running on its worker when the scheduler went may have finished since.
        for t in tasks:
            if records[t["key"]].get("status") == NOT_RUN and (r := done(t)) is not None:
                r["recovered"] = True
                record(r)
    # What a worker killed in the middle of a task left (the task ran again elsewhere); not
    # for tasks that may still be running on a worker the scheduler lost.
    for t in tasks:
        if records[t["key"]].get("status") != NOT_RUN:
            clean(t)
    return [records[t["key"]] for t in tasks]


def _input_root(records):
    """The folder every input of `records` is in (the batch root)."""
    inputs = [str(r["input"]) for r in records if r.get("input")]
    if not inputs:
        return ""
    root = os.path.commonpath(inputs)
    return os.path.dirname(root) if len(set(inputs)) == 1 or root in inputs else root


def table(records):
    """The results as a text table; inputs as paths relative to the folder that holds them
    all (the first line names it), so that files of one name in different folders stay
    apart in every row, failed ones too."""
    head = ("input", "detector+params", "events", "corners", "red.%", "detect_s", "status")
    root = _input_root(records)
    rows = []
    for r in records:
        ok = r.get("status") == "ok"
        status = ("ok (recovered)" if r.get("recovered") else "ok (resumed)" if r.get("resumed") else "ok") if ok \
            else ("NOT RUN: " if r.get("status") == NOT_RUN else "FAILED: ") + str(r.get("error", ""))
        rows.append((
            os.path.relpath(str(r["input"]), root) if root and r.get("input") else str(r.get("input", "")),
            str(r.get("detector", "")) + "".join(f" {k}={v}" for k, v in sorted((r.get("params") or {}).items())),
            str(r.get("events", "")) if ok else "",
            str(r.get("corners", "")) if ok else "",
            f"{r['reduction_rate']:.2f}" if ok and r.get("reduction_rate") is not None else "",
            f"{r['detect_s']:.4f}" if ok and r.get("detect_s") is not None else "",
            status,
        ))
    widths = [max(len(h), *(len(row[i]) for row in rows)) if rows else len(h) for i, h in enumerate(head)]
    lines = [f"inputs in {root}/" if root and root != os.sep else "inputs:"]
    lines.append("  ".join(h.ljust(w) for h, w in zip(head, widths)).rstrip())
    lines += ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in rows]
    return "\n".join(lines)


def run(client, inputs, detector_names, out_dir, params=None, to="txt", progress=None):
    """plan + submit + gather: the records, in task order."""
    tasks = plan(inputs, detector_names, out_dir, params, to)
    return gather(tasks, submit(client, tasks), out_dir, progress)


def print_progress(done_, total, r, stream=sys.stderr):
    what = f"{r.get('input')} {r.get('detector')}" + "".join(f" {k}={v}" for k, v in sorted((r.get("params") or {}).items()))
    status = "resumed" if r.get("resumed") else "recovered" if r.get("recovered") else r.get("status")
    extra = f" {r.get('corners')} corners" if r.get("status") == "ok" else f" {r.get('error')}"
    print(f"[{done_}/{total}] {status}: {what}{extra}", file=stream, flush=True)
