"""Where a small Python/CLI gap in detection time comes from (docs/python.md, Measurements).

    PYTHONPATH=build/python /usr/bin/python3 python/bench/measure_out.py build/bin/evcorner ../shared/data/real/ecd-stppp/*/events.txt

The 10 M-event replay of measure.py; 5 interleaved rounds, each: the CLI's `bench
--cpu-time` (two passes), then twice: evcorner.detect() into a new mask, evcorner.detect()
into a reused out= mask (process CPU time), and a fresh EFast's process() alone (thread CPU
time). DETECTOR=efast by default. Not a test: speed is measured here.
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
from measure import replay, uptime


def main():
    cli, files = sys.argv[1], sys.argv[2:]
    det = os.environ.get("DETECTOR", "efast")
    cls = next(c for c in evcorner.DETECTOR_CLASSES.values() if c.registry_name == det)
    print("load before:", uptime())
    tmp = tempfile.mkdtemp(prefix="evcorner-measure-")
    events = replay(files, 10_000_000)
    big = os.path.join(tmp, "replay10M.npy")
    evcorner.write(big, events)
    n = len(events)
    out = np.zeros(n, np.uint8)
    r = {"CLI bench --cpu-time": [], "detect(), new mask": [], "detect(out=)": [], "process() alone": []}
    for _ in range(5):
        js = os.path.join(tmp, "b.json")
        subprocess.run([cli, "bench", big, "-d", det, "--repeat", "1", "--min-events", "1", "--no-latency",
                        "--cpu-time", "--json", js, "-q"], check=True, stdout=subprocess.DEVNULL)
        (row,) = json.load(open(js))["results"]
        r["CLI bench --cpu-time"] += [row["cold_ns_per_event"][0], row["ns_per_event"][0]]
        for _pass in range(2):
            t0 = time.process_time()
            evcorner.detect(events, det)
            r["detect(), new mask"].append((time.process_time() - t0) * 1e9 / n)
            t0 = time.process_time()
            evcorner.detect(events, det, out=out)
            r["detect(out=)"].append((time.process_time() - t0) * 1e9 / n)
            d = cls(240, 180)
            t0 = time.thread_time()
            d.process(events, out)
            r["process() alone"].append((time.thread_time() - t0) * 1e9 / n)
    c = statistics.median(r["CLI bench --cpu-time"])
    for k, v in r.items():
        m = statistics.median(v)
        print(f"{det} {k}: median {m:.2f} ns/event (/CLI {m / c:.3f}); passes " + " ".join(f"{x:.1f}" for x in v))
    print("load after:", uptime())


if __name__ == "__main__":
    main()
