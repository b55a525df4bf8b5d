#!/usr/bin/env bash
# Fresh-machine test run: installs what is missing, builds everything, runs all tests.
# Tests on the real recordings run when ../shared/data exists beside the checkout.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup-debian.sh
scripts/build.sh
if [ ! -d ../shared/data ]; then
  echo "note: ../shared/data is not beside this checkout: the tests on the full set of real" \
       "recordings and golden outputs are skipped (they report 'Skipped'); the bundled sample" \
       "in data/ is still tested." >&2
fi
ctest --test-dir build --output-on-failure -j "$(nproc)"
if [ "${CI:-}" = "true" ]; then
  scripts/fuzz.sh 20
fi
