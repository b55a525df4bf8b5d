#!/usr/bin/env bash
# Writes dense 640x480 streams of 1, 10 and 60 s (or the seconds given) for the labelling
# curve of docs/evaluation.md: the Prophesee EVT2 recording
# ../shared/data/real/faery-testdata/evt2.raw (521 252 events in 95.9 ms, about 5.4 M
# events/s) repeated, each copy shifted to start 1 us after the previous one ends, cut at
# exactly S seconds after the first event. Output: OUT_PREFIX_<S>s.npy (evcorner's .npy
# layout, 16 bytes per event: 60 s is about 5 GB). Needs build/bin/evcorner and numpy.
# Usage: bench/make_dense_cuts.sh OUT_PREFIX [SECONDS...]   (default seconds: 1 10 60)
set -euo pipefail
out=${1:?usage: bench/make_dense_cuts.sh OUT_PREFIX [SECONDS...]}
shift
secs=("$@")
[ ${#secs[@]} -gt 0 ] || secs=(1 10 60)
here=$(cd "$(dirname "$0")/.." && pwd)
src="$here/../shared/data/real/faery-testdata/evt2.raw"
[ -e "$src" ] || { echo "make_dense_cuts: $src not found" >&2; exit 1; }
"$here/build/bin/evcorner" convert "$src" "$out.base.npy"
for s in "${secs[@]}"; do
  /usr/bin/python3 - "$out.base.npy" "${out}_${s}s.npy" "$s" <<'PY'
import sys
import numpy as np
base = np.load(sys.argv[1])
seconds = float(sys.argv[3])
t = base["t"].astype(np.int64)
if t.size == 0 or np.any(np.diff(t) < 0):
    sys.exit("make_dense_cuts: base recording empty or not in time order")
t0, span = int(t[0]), int(t[-1] - t[0]) + 1          # one copy lasts `span` us
limit = int(round(seconds * 1e6))                    # keep t - t0 < limit
copies = -(-limit // span)
per_copy = [int(np.searchsorted(t - t0, limit - k * span)) for k in range(copies)]
total = sum(per_copy)
out = np.lib.format.open_memmap(sys.argv[2], mode="w+", dtype=base.dtype, shape=(total,))
at = 0
for k, n in enumerate(per_copy):
    chunk = base[:n].copy()
    chunk["t"] = t[:n] + k * span
    out[at:at + n] = chunk
    at += n
out.flush()
print(f"make_dense_cuts: {sys.argv[2]}: {total} events, {copies} copies, {seconds:g} s")
PY
done
rm -f "$out.base.npy"
