#!/usr/bin/python3
"""Rough judge of corner events against the simulator's truth (docs/nms.md), until
`evcorner eval --truth` (issue 11) gives the real tables.

usage: nms_truth.py CORNERS.txt TRUTH.csv [TOL_PX=3] [BIN_MS=10]

CORNERS.txt: `evcorner detect` text output (t [s] x y p per line). TRUTH.csv: `evcorner
simulate --truth` (t_us,object,corner,x,y,...,visible,state; every 100 us).
Each corner event is matched to the nearest visible truth corner at the truth sample
nearest its time (pixel (x, y) at (x + 0.5, y + 0.5)); within TOL_PX it is a hit.
Prints: corners, precision (hits / corners), localisation error (mean distance of hits),
recall (visible truth corners per BIN_MS bin with at least one hit / all of them) and the
smear (hits per visible truth corner per millisecond)."""
import sys
import numpy as np


def main():
    corners_path, truth_path = sys.argv[1], sys.argv[2]
    tol = float(sys.argv[3]) if len(sys.argv) > 3 else 3.0
    bin_ms = float(sys.argv[4]) if len(sys.argv) > 4 else 10.0
    c = np.loadtxt(corners_path, ndmin=2)
    truth = np.genfromtxt(truth_path, delimiter=",", names=True, dtype=None, encoding="utf-8")
    vis = truth[truth["visible"] == 1]
    tt = vis["t_us"].astype(np.int64)
    ids = vis["object"].astype(np.int64) * 100000 + vis["corner"].astype(np.int64)
    tx, ty = vis["x"].astype(float), vis["y"].astype(float)
    times = np.unique(truth["t_us"].astype(np.int64))
    step = int(times[1] - times[0]) if len(times) > 1 else 100
    starts = np.searchsorted(tt, times, side="left")
    ends = np.searchsorted(tt, times, side="right")
    where = {int(t): (int(a), int(b)) for t, a, b in zip(times, starts, ends)}
    n = len(c)
    hits, dist, hit_keys = 0, [], set()
    if n:
        t_us = np.rint(c[:, 0] * 1e6).astype(np.int64)
        k = np.clip(np.rint(t_us / step).astype(np.int64) * step, times[0], times[-1])
        px, py = c[:, 1] + 0.5, c[:, 2] + 0.5
        for i in range(n):
            a, b = where.get(int(k[i]), (0, 0))
            if a == b:
                continue
            d = np.hypot(tx[a:b] - px[i], ty[a:b] - py[i])
            j = int(np.argmin(d))
            if d[j] <= tol:
                hits += 1
                dist.append(d[j])
                hit_keys.add((int(ids[a + j]), int(t_us[i] // int(bin_ms * 1000))))
    bins = set(zip(ids.tolist(), (tt // int(bin_ms * 1000)).tolist()))
    corner_ms = len(vis) * step / 1000.0
    precision = hits / n if n else float("nan")
    loc = float(np.mean(dist)) if dist else float("nan")
    recall = len(hit_keys & bins) / len(bins) if bins else float("nan")
    smear = hits / corner_ms if corner_ms else float("nan")
    print(f"corners {n} precision {precision:.4f} loc_px {loc:.3f} recall {recall:.4f} smear_per_corner_ms {smear:.3f}")


if __name__ == "__main__":
    main()
