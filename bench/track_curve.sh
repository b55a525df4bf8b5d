#!/usr/bin/env bash
# The tracking cost curve of docs/tracking.md ("Speed"): every registered tracker seeded at
# the first 10, 100 and 1000 ground-truth tracks of a simulated 640x480 checkerboard (37 x 28
# = 1036 corners, translating at (40, 20) px/s), HASTE's uncentered start. From a clean build:
# it simulates the scenes itself (`evcorner simulate SCENE -o ev.npy --gt-tracks gt.txt`),
# takes the seeds as the rows of the first N GT ids, and runs
#   evcorner track ev.npy --size 640x480 --tracker T --init uncentered --seeds S -o /dev/null --summary-json J
# REPEAT times per (tracker, scene, N). Every tracker runs on the short scene (SHORT_S
# seconds); the long scene (LONG_S) only for those whose short run at 1000 seeds, scaled by
# the events, predicts at most LONG_BUDGET_S seconds of tracking per run (the slow ones stay
# on the short scene: the table says which ran where).
# Prints a Markdown table: tracker, scene, seeds, started, live (running at the end),
# updates (in-range (event, track) pairs), updates per seed and event (the share of the
# seeds x events scan a one-pass tracker does), whole-run CPU s (user + sys of the process:
# reading the file included), tracking s (the pipeline's time in the tracker's calls), ns per
# event and ns per update: medians over the REPEAT runs. Cost proportional to updates shows
# as a steady ns/update while ns/event grows with the seeds.
# Environment: EVCORNER (the binary; default build/bin/evcorner, built if absent), REPEAT
# (5), SHORT_S (0.1), LONG_S (0.5), LONG_BUDGET_S (15), SEEDS ("10 100 1000"), TRACKERS
# (default: every registered tracker, as `evcorner track` names them), KEEP=1 keeps the
# temporary folder.
# Usage: bench/track_curve.sh
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
ev=${EVCORNER:-$here/build/bin/evcorner}
if [ ! -x "$ev" ]; then
  [ -f "$here/build/CMakeCache.txt" ] || cmake -S "$here" -B "$here/build" -DCMAKE_BUILD_TYPE=Release >&2
  cmake --build "$here/build" -j2 --target evcorner-cli >&2
fi
repeat=${REPEAT:-5}
short_s=${SHORT_S:-0.1}
long_s=${LONG_S:-0.5}
budget=${LONG_BUDGET_S:-15}
read -r -a seed_counts <<<"${SEEDS:-10 100 1000}"
if [ -n "${TRACKERS:-}" ]; then
  read -r -a trackers <<<"$TRACKERS"
else
  # The registry's names, from the message that lists them (tracker_names()).
  list=$("$ev" track none --tracker '?' 2>&1 | sed -n 's/.*(trackers: \(.*\)).*/\1/p' || true)
  [ -n "$list" ] || { echo "track_curve.sh: cannot list the trackers of $ev" >&2; exit 1; }
  IFS=', ' read -r -a trackers <<<"$list"
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/track_curve.XXXXXX")
[ "${KEEP:-0}" = 1 ] && echo "track_curve.sh: files in $tmp" >&2 || trap 'rm -rf "$tmp"' EXIT

# The scene (docs/simulate.md): a 36 x 27 board of 16 px squares, all 1036 grid corners on
# the sensor for the whole scene.
scene() {
  cat >"$tmp/$1.json" <<EOF
{"sensor": [640, 480], "duration_s": $2, "seed": 1,
 "objects": [{"checkerboard": {"origin": [32, 24], "square": 16, "cols": 36, "rows": 27},
              "intensity": [0.2, 0.8], "motion": {"velocity": [40, 20]}}]}
EOF
  "$ev" simulate "$tmp/$1.json" -o "$tmp/$1.npy" --gt-tracks "$tmp/$1.gt.txt" --no-progress 2>"$tmp/$1.sim"
  grep -E "^ +(events|gt tracks) " "$tmp/$1.sim" | sed "s/^/  $1: /" >&2
  for n in "${seed_counts[@]}"; do awk -v n="$n" '$1 < n' "$tmp/$1.gt.txt" >"$tmp/$1.seeds$n.txt"; done
}

# One run: tracker, scene, N, repetition.
run() {
  local base="$tmp/runs/$1.$2.$3.$4"
  /usr/bin/time -f "%U %S" -o "$base.time" "$ev" track "$tmp/$2.npy" --size 640x480 --tracker "$1" \
    --init uncentered --seeds "$tmp/$2.seeds$3.txt" -o /dev/null --summary-json "$base.json" 2>"$base.err"
}

mkdir -p "$tmp/runs"
scene short "$short_s"
scene long "$long_s"
start=$SECONDS
for t in "${trackers[@]}"; do
  for n in "${seed_counts[@]}"; do
    for ((r = 0; r < repeat; r++)); do run "$t" short "$n" "$r"; done
  done
  # Long scene: when the short run at the most seeds predicts a run within the budget.
  last=${seed_counts[${#seed_counts[@]} - 1]}
  fits=$(/usr/bin/python3 - "$tmp" "$t" "$last" "$budget" <<'PY'
import json, sys
tmp, t, n, budget = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
j = json.load(open(f"{tmp}/runs/{t}.short.{n}.0.json"))
long_events = int(open(f"{tmp}/long.sim").read().split("events")[1].split()[0])
print(1 if j["track_s"] * long_events / j["events"] <= budget else 0)
PY
)
  if [ "$fits" = 1 ]; then
    for n in "${seed_counts[@]}"; do
      for ((r = 0; r < repeat; r++)); do run "$t" long "$n" "$r"; done
    done
  fi
  echo "  $t: done ($((SECONDS - start)) s so far; long scene: $([ "$fits" = 1 ] && echo yes || echo no))" >&2
done

/usr/bin/python3 - "$tmp" "$repeat" "$short_s" "$long_s" "${seed_counts[*]}" "${trackers[@]}" <<'PY'
import glob, json, re, statistics, sys
tmp, repeat, short_s, long_s, seeds = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5].split()
trackers = sys.argv[6:]
def fmt(v, d):
    return "-" if v is None else f"{v:.{d}f}"
print(f"| tracker | scene | seeds | started | live | updates | updates / (seeds x events) | CPU s | tracking s | ns/event | ns/update |")
print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for t in trackers:
    for scene, secs in (("short", short_s), ("long", long_s)):
        for n in seeds:
            runs = sorted(glob.glob(f"{tmp}/runs/{t}.{scene}.{n}.*.json"))
            if not runs:
                continue
            js = [json.load(open(p)) for p in runs]
            cpu = [sum(map(float, open(p[:-5] + ".time").read().split()[-2:])) for p in runs]
            live = re.search(r"(\d+) running at the end", open(runs[0][:-5] + ".err").read())
            j = js[0]
            med = lambda k: statistics.median(x[k] for x in js) if all(x[k] is not None for x in js) else None
            share = j["updates"] / (int(n) * j["events"]) if j["events"] else None
            print(f"| {t} | {secs} s, {j['events']} ev | {n} | {j['tracks_started']} | {live.group(1) if live else '-'} "
                  f"| {j['updates']} | {fmt(share, 5)} | {statistics.median(cpu):.2f} | {med('track_s'):.3f} "
                  f"| {fmt(med('ns_per_event'), 1)} | {fmt(med('ns_per_update'), 1)} |")
print(f"\nmedians over {repeat} runs; CPU: {open('/proc/cpuinfo').read().split('model name')[1].split(':')[1].splitlines()[0].strip()}")
PY
