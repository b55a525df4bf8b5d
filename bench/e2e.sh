#!/usr/bin/env bash
# End-to-end timing of `evcorner detect` (docs/performance.md): the whole process,
# reading, detecting and writing the corners, from ECD text to text and from .npy to
# .npy, on 1 and 2 threads. The cases are interleaved round after round, so that the
# noise of a shared machine hits them alike; prints the median wall time of each and
# the events per second it means.
#   Usage: bench/e2e.sh PREFIX [RUNS] [THREADS...]
#   PREFIX.txt and PREFIX.npy as bench/make_e2e_input.sh writes them; RUNS default 7;
#   THREADS default "1 2".
set -euo pipefail
prefix=${1:?usage: bench/e2e.sh PREFIX [RUNS] [THREADS...]}
runs=${2:-7}
shift $(( $# >= 2 ? 2 : 1 ))
threads=("$@")
[ ${#threads[@]} -gt 0 ] || threads=(1 2)
here=$(cd "$(dirname "$0")/.." && pwd)
exe="$here/build/bin/evcorner"
events=$(wc -l <"$prefix.txt")
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
declare -A times
for ((r = 0; r < runs; ++r)); do
    for ext in txt npy; do
        for j in "${threads[@]}"; do
            start=$(date +%s%N)
            "$exe" detect "$prefix.$ext" -o "$out/corners.$ext" -q -j "$j"
            end=$(date +%s%N)
            times[$ext-$j]+="$(( (end - start) / 1000 )) "
        done
    done
done
echo "end to end: $events events, $runs runs per case (median wall time of the whole process)"
for ext in txt npy; do
    for j in "${threads[@]}"; do
        median=$(tr ' ' '\n' <<<"${times[$ext-$j]}" | grep . | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
        awk -v e="$events" -v us="$median" -v c="$ext" -v j="$j" -v all="${times[$ext-$j]}" \
            'BEGIN { printf "%s -> %s, %d thread(s): %.3f s, %.1f M events/s   (all, us: %s)\n", c, c, j, us / 1e6, e / us, all }'
    done
done
