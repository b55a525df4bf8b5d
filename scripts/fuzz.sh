#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang++ in build-fuzz/ and runs each for
# SECONDS_PER_TARGET seconds (default 60), seeded with the heads of the real recordings
# (../shared/data/real, when present), the bundled data/ and fuzz/seeds/. Fails on any
# crash, sanitizer report, timeout (> 10 s per input) or allocation over 2 GB, except
# inside the two libraries evcorner cannot guard (libhdf5's crashes, libmatio's memory:
# reported, not failed; below); the reproducer is left in build-fuzz/artifacts/. Prints
# the executions per target.
# FUZZ_JOBS targets (default: the number of cores) build and run at once.
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${1:-60}"
root="$PWD"
build="$root/build-fuzz"
shared="$root/../shared/data/real"

# -g1: line tables, all the reports' stacks need (full -g costs build time for nothing more).
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG" -DCMAKE_CXX_COMPILER=clang++ \
  -DEVCORNER_FUZZ=ON -DEVCORNER_BUILD_APPS=OFF -DEVCORNER_BUILD_TESTS=OFF -DEVCORNER_BUILD_BENCH=OFF >/dev/null
targets=(text csv aedat2 evt2 evt3 dat aedat4 hdf5 npy atis mat compressed)
targets+=(mcap rosbag rosbag2)  # ROS bags, read in memory
cmake --build "$build" -j "${FUZZ_JOBS:-$(nproc)}" --target "${targets[@]/#/fuzz_}" >/dev/null

# Seeds: the first 64 KiB of each matching file (inputs are capped at that length).
seed() {  # seed TARGET FILE...
  local dir="$build/corpus/$1"; shift
  mkdir -p "$dir"
  for f in "$@"; do
    [ -f "$f" ] && head -c 65536 "$f" >"$dir/seed-$(basename "$(dirname "$f")")-$(basename "$f")"
  done
  return 0
}
rm -rf "$build/corpus"
shopt -s nullglob
seed text fuzz/seeds/seed.txt data/ecd/*/events.txt "$shared"/ecd-stppp/shapes_rotation/events.txt
seed csv fuzz/seeds/seed.csv
seed npy fuzz/seeds/seed.npy
seed hdf5 fuzz/seeds/*.h5
seed aedat4 fuzz/seeds/*.aedat4 "$shared"/*/*.aedat4
seed aedat2 "$shared"/davis240c-imu-pyaedattools/*.aedat "$shared"/dvs128-walking-ouyang/neal_walking.aedat
seed evt2 "$shared"/expelliarmus/evt2_sample.raw "$shared"/faery-testdata/evt2.raw
seed evt3 "$shared"/expelliarmus/evt3_sample.raw
seed dat "$shared"/tonic-testdata/sample_ncars.dat
seed mcap fuzz/seeds/*.mcap "$shared"/ros2-event-camera-py/test_events_2/*.mcap
seed rosbag fuzz/seeds/seed.bag "$shared"/ros2-event-camera-py/ros1/*.bag
seed rosbag2 fuzz/seeds/seed.db3
seed npy fuzz/seeds/seed-*.npy
seed atis "$shared"/tonic-testdata/sample_nmnist.bin "$shared"/evlib-shiba/faces_easy_0001.bin
seed mat fuzz/seeds/*.mat "$shared"/rpg-event-lifetime/*.mat
seed compressed fuzz/seeds/seed.txt.* fuzz/seeds/seed.csv.* fuzz/seeds/seed.csv fuzz/seeds/seed.npy

mkdir -p "$build/artifacts" "$build/logs"
# run_one TARGET: fuzzes one target; its exit status lands in logs/fuzz_TARGET.status.
run_one() {
  local t=$1 log="$build/logs/fuzz_$1.log" extra=()
  # libhdf5 (Debian 12: 1.10.8) is not robust against malformed files: it leaks, and
  # overflows its own buffers while parsing object headers (H5Aexists, H5Dread), inside
  # the library where evcorner cannot guard. fuzz_hdf5 runs and reports, but does not
  # fail the run; every other target does.
  [ "$t" = hdf5 ] && extra=(-detect_leaks=0)
  # A fixed seed by default, so that a CI run can be repeated; FUZZ_SEED=0 picks one at random.
  local rc=0
  "$build/bin/fuzz_$t" "$build/corpus/$t" -max_total_time="$secs" -seed="${FUZZ_SEED:-1}" -rss_limit_mb=2048 -timeout=10 \
    -max_len=65536 -print_final_stats=1 "${extra[@]}" -artifact_prefix="$build/artifacts/$t-" >"$log" 2>&1 || rc=$?
  echo "$rc" >"$build/logs/fuzz_$t.status"
}
# Each fuzzer is one process on one core: FUZZ_JOBS of them (default: the cores) run at once.
jobs_max="${FUZZ_JOBS:-$(nproc)}"
for t in "${targets[@]}"; do
  rm -f "$build/logs/fuzz_$t.status"
  while (( $(jobs -rp | wc -l) >= jobs_max )); do wait -n || true; done
  run_one "$t" &
done
wait
failed=()
for t in "${targets[@]}"; do
  log="$build/logs/fuzz_$t.log"
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -n 1 || echo '?')
  # libmatio (Debian 12: 1.5.23) sizes allocations by counts a damaged file declares deep
  # inside its variables (cells, structs, objects), where src/io/mat_reader.cpp's walk of
  # the tags does not reach: an out-of-memory report whose allocation stack is libmatio's
  # is reported without failing the run, as libhdf5's crashes are. Any other report fails.
  libmatio_oom=false
  # (awk, not grep | grep -q: under pipefail an early exit of the second grep could fail
  # the first with SIGPIPE.)
  if [ "$t" = mat ] && awk '/ERROR: libFuzzer: out-of-memory/ { n = 30 }
                            n > 0 { n--; if (/libmatio\.so/) found = 1 }
                            END { exit !found }' "$log"; then
    libmatio_oom=true
  fi
  if [ "$(cat "$build/logs/fuzz_$t.status" 2>/dev/null)" = 0 ]; then
    echo "fuzz_$t: ok, $runs executions in ${secs} s"
  else
    if [ "$t" = hdf5 ] || $libmatio_oom; then
      echo "fuzz_$t: crash after $runs executions (informational: see above; log: $log)" >&2
    else
      echo "fuzz_$t: FAILED after $runs executions (log: $log)" >&2
      failed+=("$t")
    fi
    grep -m 5 -E 'ERROR|SUMMARY|Test unit written' "$log" >&2 || tail -5 "$log" >&2
  fi
done
if ((${#failed[@]} > 0)); then
  echo "fuzz: failures in: ${failed[*]}" >&2
  exit 1
fi
