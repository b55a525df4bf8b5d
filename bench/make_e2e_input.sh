#!/usr/bin/env bash
# Writes the end-to-end benchmark input of docs/performance.md: the eight ECD cuts of
# ../shared/data/real/ecd-stppp concatenated round after round, each cut shifted to start
# 1 us after the previous one ends, until at least MIN_EVENTS events (default 10 000 000).
# Output: OUT.txt (ECD text, t in seconds with 9 decimals) and, through evcorner convert,
# OUT.npy.  Usage: bench/make_e2e_input.sh OUT_PREFIX [MIN_EVENTS]
set -euo pipefail
out=${1:?usage: bench/make_e2e_input.sh OUT_PREFIX [MIN_EVENTS]}
min=${2:-10000000}
here=$(cd "$(dirname "$0")/.." && pwd)
cuts=("$here"/../shared/data/real/ecd-stppp/*/events.txt)
[ -e "${cuts[0]}" ] || { echo "make_e2e_input: no ECD cuts under ../shared/data/real/ecd-stppp" >&2; exit 1; }
# Times are handled as integer microseconds ("49.006624000" -> 49006624).
awk -v min="$min" '
  function us(s,   a, f) { split(s, a, "."); f = substr(a[2] "000000", 1, 6); return a[1] * 1000000 + f }
  FNR == 1 { next_start = n ? last + 1 : 0; shift = next_start - us($1) }
  { t = us($1) + shift; printf "%d.%06d000 %s %s %s\n", int(t / 1000000), t % 1000000, $2, $3, $4
    last = t; n++ }
  END { if (n < min) exit 3 }
' $(for ((r = 0; r < (min + 239999) / 240000; ++r)); do printf '%s ' "${cuts[@]}"; done) >"$out.txt"
"$here/build/bin/evcorner" convert "$out.txt" "$out.npy"
wc -l "$out.txt" | awk '{print "make_e2e_input: " $1 " events"}'
