#!/usr/bin/env bash
# The labelling curve of docs/evaluation.md: for each dense cut PREFIX_<S>s.npy made by
# bench/make_dense_cuts.sh, eFAST corners (evcorner detect), then evcorner label on them;
# one line per cut: events, corners, detect CPU s, label CPU s, label wall s, label peak
# RSS MB, hypotheses, label/detect CPU ratio. LABEL_ARGS (environment) goes to label, e.g.
# LABEL_ARGS="--ft-max-length 2"; EVCORNER (environment) picks the binary.
# Usage: bench/label_curve.sh PREFIX [SECONDS...]   (default seconds: 1 10 60)
set -euo pipefail
prefix=${1:?usage: bench/label_curve.sh PREFIX [SECONDS...]}
shift
secs=("$@")
[ ${#secs[@]} -gt 0 ] || secs=(1 10 60)
here=$(cd "$(dirname "$0")/.." && pwd)
ev=${EVCORNER:-$here/build/bin/evcorner}
echo "seconds events corners detect_cpu_s label_cpu_s label_wall_s label_peak_mb hypotheses label/detect"
for s in "${secs[@]}"; do
  in="${prefix}_${s}s.npy"
  corners="${prefix}_${s}s.efast.npy"
  /usr/bin/time -f "%U %S" -o "$corners.dtime" "$ev" detect "$in" --size 640x480 -d efast -o "$corners" \
    >"$corners.detect" 2>&1
  # shellcheck disable=SC2086
  /usr/bin/time -f "%U %S %e %M" -o "$corners.ltime" "$ev" label "$corners" --size 640x480 --no-progress \
    --json "$corners.json" ${LABEL_ARGS:-} >/dev/null
  /usr/bin/python3 - "$s" "$corners" <<'PY'
import json, sys
s, c = sys.argv[1], sys.argv[2]
du, ds = map(float, open(c + ".dtime").read().split()[-2:])
lu, ls, lw, lm = open(c + ".ltime").read().split()[-4:]
events = next(l.split()[1] for l in open(c + ".detect") if l.strip().startswith("events"))
j = json.load(open(c + ".json"))
d, l = du + ds, float(lu) + float(ls)
print(f"{s} {events} {j['corners']} {d:.2f} {l:.2f} {float(lw):.2f} {int(lm) / 1024:.0f} {j['hypotheses']} {l / d:.0f}")
PY
done
