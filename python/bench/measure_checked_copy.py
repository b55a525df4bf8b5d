"""Python `detect` on 10 M events with two builds of the package, interleaved: the cost of
what process() checks and copies (docs/python.md, "Threads").

    /usr/bin/python3 python/bench/measure_checked_copy.py BEFORE_DIR AFTER_DIR [ROUNDS [CHUNK]]

BEFORE_DIR and AFTER_DIR each hold an `evcorner` package (e.g. a copy of build/python).
The stream is the bundled sample (data/ecd/shapes_translation) replayed, each copy
shifted past the last, to 10 M events, written once as .npy. Each round runs, in a fresh
process per package, `evcorner.detect(events, NAME)` twice per detector on the loaded
events (process CPU time around the call: building the detector, the checks, the copies,
a new mask); the figures are the medians of all passes, in ns/event. With CHUNK, each
pass is one detector fed the events CHUNK at a time (process(), as evcorner.open() chunks).
"""

import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "data" / "ecd" / "shapes_translation" / "events.txt"
DETECTORS = ("efast", "harris")
N = 10_000_000

CHILD = r"""
import sys, time
import numpy as np
import evcorner
events = np.load(sys.argv[1])
events = events.view(evcorner.EVENT_DTYPE) if events.dtype == evcorner.EVENT_DTYPE else evcorner.as_events(events)
chunk = int(sys.argv[2])
for name in sys.argv[3:]:
    for _ in range(2):
        t0 = time.process_time()
        if chunk:
            det = evcorner.Detector(name, 240, 180, {})
            mask = np.concatenate([det.process(events[a:a + chunk]) for a in range(0, len(events), chunk)])
        else:
            mask = evcorner.detect(events, name)
        dt = time.process_time() - t0
        print(name, dt * 1e9 / len(events), int(mask.sum()), flush=True)
"""


def replayed(sample_dir):
    env = dict(os.environ, PYTHONPATH=str(sample_dir))
    code = ("import sys, numpy as np, evcorner\n"
            "e = evcorner.read(sys.argv[1]); n = int(sys.argv[2])\n"
            "reps = -(-n // len(e)); span = int(e['t'][-1] - e['t'][0]) + 1\n"
            "big = np.concatenate([e] * reps)[:n]\n"
            "big['t'] += np.repeat(np.arange(reps, dtype=np.int64) * span, len(e))[:n]\n"
            "np.save(sys.argv[3], big)\n")
    path = Path(tempfile.mkdtemp()) / "replayed.npy"
    subprocess.run([sys.executable, "-c", code, str(SAMPLE), str(N), str(path)], env=env, check=True)
    return path


def main():
    before, after = Path(sys.argv[1]).resolve(), Path(sys.argv[2]).resolve()
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    chunk = int(sys.argv[4]) if len(sys.argv) > 4 else 0
    npy = replayed(after)
    passes = {(side, d): [] for side in ("before", "after") for d in DETECTORS}
    corners = {}
    for r in range(rounds):
        for side, pkg in (("before", before), ("after", after)) if r % 2 == 0 else (("after", after), ("before", before)):
            out = subprocess.run([sys.executable, "-c", CHILD, str(npy), str(chunk), *DETECTORS], env=dict(os.environ, PYTHONPATH=str(pkg)),
                                 check=True, capture_output=True, text=True).stdout
            for line in out.split("\n"):
                if line:
                    name, ns, c = line.split()
                    passes[(side, name)].append(float(ns))
                    corners.setdefault((side, name), set()).add(int(c))
    print(f"{N} events{f' in chunks of {chunk}' if chunk else ''}, {rounds} rounds x 2 passes; "
          f"load {os.getloadavg()[0]:.1f}")
    print("| detector | before ns/event | after ns/event | after/before | corners |")
    print("|---|---:|---:|---:|---:|")
    for d in DETECTORS:
        b, a = statistics.median(passes[("before", d)]), statistics.median(passes[("after", d)])
        print(f"| {d} | {b:.2f} | {a:.2f} | {a / b:.3f} | {sorted(corners[('before', d)] | corners[('after', d)])} |")
    os.unlink(npy)


if __name__ == "__main__":
    main()
