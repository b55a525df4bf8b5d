"""python3 -m evcorner batch INPUTS... -d efast,harris [-p KEY=V1,V2 ...] -o OUTDIR

Runs one Dask task per (recording, detector, parameters): on a LocalCluster of one worker
process per core (--workers N to change), or on a running cluster (--scheduler
tcp://HOST:PORT, or --scheduler-file FILE as under Slurm). Options are checked before
anything is submitted: an unknown --to, detector or parameter, or a value a detector
refuses, is a usage error. Exit status: 0 every task ok, 1 a task failed (the others
still ran; see OUTDIR/results.jsonl), 2 usage, 3 the scheduler was lost (or could not be
reached) before every task ran, 130 interrupted (Ctrl-C); rerunning the same command
resumes a batch (finished tasks are skipped).
"""

import argparse
import logging
import os
import signal
import sys
import time


def _value(text):
    low = text.lower()
    if low in ("true", "false"):
        return low == "true"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number or true/false: {text!r}") from None


def _param(text):
    key, sep, values = text.partition("=")
    if not sep or not key or not values:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE[,VALUE...], got {text!r}")
    return key.strip().replace("-", "_"), [_value(v.strip()) for v in values.split(",")]


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m evcorner", description=__doc__.split("\n\n")[1],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    b = sub.add_parser("batch", help="detectors over many recordings on Dask distributed",
                       description=__doc__.split("\n\n")[1], formatter_class=argparse.RawDescriptionHelpFormatter)
    b.add_argument("inputs", nargs="+", help="event files (any format evcorner reads) or rosbag2 folders")
    b.add_argument("-d", "--detectors", default="efast", help="comma-separated registry names (default efast)")
    b.add_argument("-p", "--param", action="append", type=_param, default=[], metavar="KEY=V[,V...]",
                   help="a detector parameter (harris_window=5,7: one task per value); each detector takes "
                        "the keys it has")
    b.add_argument("-o", "--out", required=True, help="output folder (corner files, JSON summaries, results.jsonl)")
    b.add_argument("--to", default="txt", help="corner file extension / format: txt, csv, npy, aedat4, h5 "
                                               "(or ecd-text, hdf5)")
    where = b.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a running scheduler, tcp://HOST:PORT")
    where.add_argument("--scheduler-file", help="scheduler file written by `python -m dask scheduler --scheduler-file FILE`")
    b.add_argument("--workers", type=int, default=os.cpu_count(),
                   help="LocalCluster worker processes (default: one per core, %(default)s here)")
    b.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    b.add_argument("-v", "--verbose", action="store_true",
                   help="Dask's own log messages too (connections, retries, tracebacks)")
    args = parser.parse_args(argv)

    from . import batch

    if not (args.scheduler or args.scheduler_file) and args.workers < 1:
        parser.error("--workers must be at least 1")
    try:
        tasks = batch.plan(args.inputs, [d.strip() for d in args.detectors.split(",") if d.strip()], args.out,
                           dict(args.param), args.to)
    except (ValueError, TypeError) as e:
        parser.error(str(e))
    if args.scheduler_file and not os.path.isfile(args.scheduler_file):
        parser.error(f"--scheduler-file {args.scheduler_file}: no such file (start `dask scheduler "
                     f"--scheduler-file {args.scheduler_file}` first)")
    missing = [p for p in args.inputs if not os.path.exists(p)]
    for p in missing:
        print(f"evcorner batch: {p}: no such file (its tasks will fail)", file=sys.stderr)
    return _run(args, tasks, batch)


def _say(text):
    print(f"evcorner batch: {text}", file=sys.stderr, flush=True)


def _run(args, tasks, batch):
    from dask.distributed import Client, LocalCluster

    if not args.verbose:
        # What the batch reports itself (a lost scheduler, failed tasks) in one line each,
        # not as Dask's tracebacks.
        for name in ["asyncio", *logging.root.manager.loggerDict]:
            if name in ("asyncio", "distributed") or name.startswith("distributed."):
                logging.getLogger(name).setLevel(logging.CRITICAL)
    start = time.perf_counter()
    cluster = client = None
    records = None
    try:
        try:
            if args.scheduler:
                client = Client(args.scheduler, timeout=30)
            elif args.scheduler_file:
                client = Client(scheduler_file=args.scheduler_file, timeout=30)
            else:
                # The worker processes ignore SIGINT (they inherit that): Ctrl-C reaches the
                # whole process group, and it is this process that stops them, in order.
                previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
                try:
                    cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                           dashboard_address=":0", silence_logs=logging.INFO if args.verbose
                                           else logging.CRITICAL)
                finally:
                    signal.signal(signal.SIGINT, previous)
                client = Client(cluster)
        except OSError as e:
            _say(f"cannot reach the scheduler {args.scheduler or args.scheduler_file}: {e}")
            return 3
        up_s = time.perf_counter() - start
        nworkers = len(client.scheduler_info()["workers"])
        todo = sum(1 for t in tasks if batch.done(t) is None)
        _say(f"{len(tasks)} tasks ({len(tasks) - todo} done before) on {nworkers} workers "
             f"at {client.scheduler.address} (connected in {up_s:.2f} s)")
        futures = batch.submit(client, tasks)
        records = batch.gather(tasks, futures, args.out, None if args.quiet else batch.print_progress)
    except KeyboardInterrupt:
        _close(client, cluster)
        client = cluster = None
        removed = sum(len(batch.clean(t)) for t in tasks)
        finished = sum(1 for t in tasks if batch.done(t) is not None)
        _say(f"interrupted: {finished} of {len(tasks)} tasks finished (their corner files and JSON are in "
             f"{args.out}); {removed} temporary files removed; rerun the same command to resume")
        return 130
    finally:
        _close(client, cluster)
    failed = sum(1 for r in records if r.get("status") == "failed")
    not_run = sum(1 for r in records if r.get("status") == batch.NOT_RUN)
    print(batch.table(records))
    _say(f"{len(records)} tasks, {failed} failed, {not_run} not run, {time.perf_counter() - start:.2f} s wall; "
         f"results in {os.path.join(args.out, 'results.jsonl')}")
    if not_run:
        finished = sum(1 for r in records if r.get("status") == "ok")
        _say(f"lost the scheduler: {finished} of {len(records)} tasks finished (counted above, their JSON is "
             f"written), {not_run} did not run (one still running on a worker may finish there); restart the "
             f"scheduler and workers, then rerun the same command to run what is left")
        return 3
    return 1 if failed else 0


def _close(client, cluster):
    """Closes the client and the local cluster; a scheduler already gone is no error."""
    for thing in (client, cluster):
        if thing is None:
            continue
        try:
            thing.close()
        except Exception:  # noqa: BLE001 -- closing what is lost anyway
            pass


if __name__ == "__main__":
    sys.exit(main())
