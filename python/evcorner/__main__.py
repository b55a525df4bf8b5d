"""python3 -m evcorner batch INPUTS... -d efast,harris [-p KEY=V1,V2 ...] -o OUTDIR

Runs one Dask task per (recording, detector, parameters): on a LocalCluster of one worker
process per core (--workers N to change), or on a running cluster (--scheduler
tcp://HOST:PORT, or --scheduler-file FILE as under Slurm). Exit status: 0 every task ok,
1 a task failed (the others still ran; see OUTDIR/results.jsonl), 2 usage.
"""

import argparse
import os
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
    b = sub.add_parser("batch", help="detectors over many recordings on Dask distributed")
    b.add_argument("inputs", nargs="+", help="event files (any format evcorner reads)")
    b.add_argument("-d", "--detectors", default="efast", help="comma-separated registry names (default efast)")
    b.add_argument("-p", "--param", action="append", type=_param, default=[], metavar="KEY=V[,V...]",
                   help="a detector parameter (harris_window=5,7: one task per value); each detector takes "
                        "the keys it has")
    b.add_argument("-o", "--out", required=True, help="output folder (corner files, JSON summaries, results.jsonl)")
    b.add_argument("--to", default="txt", help="corner file extension / format: txt, csv, npy, aedat4, h5")
    where = b.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a running scheduler, tcp://HOST:PORT")
    where.add_argument("--scheduler-file", help="scheduler file written by `dask scheduler --scheduler-file`")
    b.add_argument("--workers", type=int, default=os.cpu_count(),
                   help="LocalCluster worker processes (default: one per core, %(default)s here)")
    b.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    args = parser.parse_args(argv)

    from . import batch
    from dask.distributed import Client, LocalCluster

    try:
        tasks = batch.plan(args.inputs, [d.strip() for d in args.detectors.split(",") if d.strip()], args.out,
                           dict(args.param), args.to)
    except ValueError as e:
        parser.error(str(e))
    missing = [p for p in args.inputs if not os.path.exists(p)]
    for p in missing:
        print(f"evcorner batch: {p}: no such file (its tasks will fail)", file=sys.stderr)

    start = time.perf_counter()
    cluster = None
    if args.scheduler:
        client = Client(args.scheduler)
    elif args.scheduler_file:
        client = Client(scheduler_file=args.scheduler_file)
    else:
        if args.workers < 1:
            parser.error("--workers must be at least 1")
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               dashboard_address=":0")
        client = Client(cluster)
    up_s = time.perf_counter() - start
    try:
        nworkers = len(client.scheduler_info()["workers"])
        todo = sum(1 for t in tasks if batch.done(t) is None)
        print(f"evcorner batch: {len(tasks)} tasks ({len(tasks) - todo} done before) on {nworkers} workers "
              f"at {client.scheduler.address} (connected in {up_s:.2f} s)", file=sys.stderr)
        futures = batch.submit(client, tasks)
        records = batch.gather(tasks, futures, args.out, None if args.quiet else batch.print_progress)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    failed = sum(1 for r in records if r.get("status") != "ok")
    print(batch.table(records))
    print(f"{len(records)} tasks, {failed} failed, {time.perf_counter() - start:.2f} s wall; "
          f"results in {os.path.join(args.out, 'results.jsonl')}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
